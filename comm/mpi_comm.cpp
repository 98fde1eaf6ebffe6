#include <mpi.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "comm/comm.h"

namespace isowall {
namespace {

// Every MPI call is checked: a failed call becomes an exception naming the call.
#define ISOWALL_MPI_CALL(call)                                                    \
    do {                                                                          \
        if (int rc_ = (call); rc_ != MPI_SUCCESS)                                 \
            throw std::runtime_error(std::string("MPI: ") + #call + " failed (" + \
                                     std::to_string(rc_) + ")");                  \
    } while (0)

// Waiting polls with a short sleep instead of blocking in MPI_Probe: Open MPI spins inside a
// blocking call, and with 25 ranks on 2 cores a spinning idle rank steals the busy ranks' core.
constexpr auto kPollSleep = std::chrono::microseconds(200);

class MpiComm final : public Comm {
  public:
    MpiComm(int& argc, char**& argv) {
        int initialized = 0;
        MPI_Initialized(&initialized);
        if (!initialized) {
            // SERIALIZED is enough: every call below holds mutex_, and no call blocks while
            // holding it (sends are MPI_Isend + MPI_Test, receives MPI_Iprobe first).
            int provided = 0;
            ISOWALL_MPI_CALL(MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided));
            if (provided < MPI_THREAD_SERIALIZED)
                throw std::runtime_error(
                    "MPI: this MPI library does not support MPI_THREAD_SERIALIZED");
        }
        ISOWALL_MPI_CALL(MPI_Comm_dup(MPI_COMM_WORLD, &comm_));
        ISOWALL_MPI_CALL(MPI_Comm_rank(comm_, &rank_));
        ISOWALL_MPI_CALL(MPI_Comm_size(comm_, &size_));
    }
    ~MpiComm() override {
        MPI_Comm_free(&comm_);
        MPI_Finalize();
    }
    int rank() const override { return rank_; }
    int size() const override { return size_; }
    std::string host() const override {
        char name[MPI_MAX_PROCESSOR_NAME];
        int len = 0;
        std::lock_guard lock(mutex_);
        MPI_Get_processor_name(name, &len);
        return std::string(name, static_cast<std::size_t>(len));
    }

    // Two ranks that send each other large messages at once must not deadlock: the lock is
    // released between tests, so this rank's receiving thread can still take the peer's message.
    void send(int dest, Tag tag, std::span<const std::byte> bytes) override {
        MPI_Request request;
        {
            std::lock_guard lock(mutex_);
            ISOWALL_MPI_CALL(MPI_Isend(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, dest,
                                       static_cast<int>(tag), comm_, &request));
        }
        for (;;) {
            int done = 0;
            {
                std::lock_guard lock(mutex_);
                ISOWALL_MPI_CALL(MPI_Test(&request, &done, MPI_STATUS_IGNORE));
            }
            if (done) return;
            std::this_thread::sleep_for(kPollSleep);
        }
    }

    std::optional<Envelope> receive(int source, double timeout_s) override {
        const auto start = std::chrono::steady_clock::now();
        for (;;) {
            {
                std::lock_guard lock(mutex_);
                int flag = 0;
                MPI_Status status;
                ISOWALL_MPI_CALL(MPI_Iprobe(source < 0 ? MPI_ANY_SOURCE : source, MPI_ANY_TAG,
                                            comm_, &flag, &status));
                if (flag) return take(status);
            }
            const double waited =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (waited >= timeout_s) return std::nullopt;
            std::this_thread::sleep_for(kPollSleep);
        }
    }

    void barrier() override {
        MPI_Request request;
        {
            std::lock_guard lock(mutex_);
            ISOWALL_MPI_CALL(MPI_Ibarrier(comm_, &request));
        }
        for (int done = 0; !done;) {
            {
                std::lock_guard lock(mutex_);
                ISOWALL_MPI_CALL(MPI_Test(&request, &done, MPI_STATUS_IGNORE));
            }
            if (!done) std::this_thread::sleep_for(kPollSleep);
        }
    }

    [[noreturn]] void abort(int code) override {
        std::fflush(stdout);
        std::fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, code);
        _exit(code);
    }

  private:
    // Receives the message `status` describes (mutex_ held).
    Envelope take(const MPI_Status& status) {
        int count = 0;
        ISOWALL_MPI_CALL(MPI_Get_count(&status, MPI_BYTE, &count));
        Envelope e;
        e.from = status.MPI_SOURCE;
        e.tag = static_cast<Tag>(status.MPI_TAG);
        e.bytes.resize(static_cast<std::size_t>(count));
        ISOWALL_MPI_CALL(MPI_Recv(e.bytes.data(), count, MPI_BYTE, status.MPI_SOURCE,
                                  status.MPI_TAG, comm_, MPI_STATUS_IGNORE));
        return e;
    }

    mutable std::mutex mutex_;
    MPI_Comm comm_ = MPI_COMM_NULL;
    int rank_ = 0;
    int size_ = 1;
};

}  // namespace

std::unique_ptr<Comm> make_mpi_comm(int& argc, char**& argv) {
    return std::make_unique<MpiComm>(argc, argv);
}

}  // namespace isowall
