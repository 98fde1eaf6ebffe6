#include <mpi.h>

#include <unistd.h>

#include <cstdio>
#include <stdexcept>

#include "comm/comm.h"

namespace isowall {
namespace {

// Every MPI call is checked: a failed call becomes an exception naming the call.
#define ISOWALL_MPI_CALL(call)                                                        \
    do {                                                                              \
        if (int rc_ = (call); rc_ != MPI_SUCCESS)                                     \
            throw std::runtime_error(std::string("MPI: ") + #call + " failed (" +     \
                                     std::to_string(rc_) + ")");                     \
    } while (0)

class MpiComm final : public Comm {
public:
    MpiComm(int& argc, char**& argv) {
        int initialized = 0;
        MPI_Initialized(&initialized);
        if (!initialized) ISOWALL_MPI_CALL(MPI_Init(&argc, &argv));
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
        MPI_Get_processor_name(name, &len);
        return std::string(name, static_cast<std::size_t>(len));
    }
    void send(int dest, Tag tag, std::span<const std::byte> bytes) override {
        ISOWALL_MPI_CALL(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, dest,
                                  static_cast<int>(tag), comm_));
    }
    std::vector<std::byte> recv(int source, Tag tag) override {
        MPI_Status status;
        ISOWALL_MPI_CALL(MPI_Probe(source, static_cast<int>(tag), comm_, &status));
        int count = 0;
        ISOWALL_MPI_CALL(MPI_Get_count(&status, MPI_BYTE, &count));
        std::vector<std::byte> bytes(static_cast<std::size_t>(count));
        ISOWALL_MPI_CALL(MPI_Recv(bytes.data(), count, MPI_BYTE, source, static_cast<int>(tag), comm_,
                                  MPI_STATUS_IGNORE));
        return bytes;
    }
    std::optional<Tag> probe(int source) override {
        int flag = 0;
        MPI_Status status;
        ISOWALL_MPI_CALL(MPI_Iprobe(source < 0 ? MPI_ANY_SOURCE : source, MPI_ANY_TAG, comm_, &flag, &status));
        if (!flag) return std::nullopt;
        return static_cast<Tag>(status.MPI_TAG);
    }
    std::pair<Tag, std::vector<std::byte>> recv_any(int source, int* from) override {
        MPI_Status status;
        ISOWALL_MPI_CALL(MPI_Probe(source < 0 ? MPI_ANY_SOURCE : source, MPI_ANY_TAG, comm_, &status));
        int count = 0;
        ISOWALL_MPI_CALL(MPI_Get_count(&status, MPI_BYTE, &count));
        std::vector<std::byte> bytes(static_cast<std::size_t>(count));
        ISOWALL_MPI_CALL(MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG,
                                  comm_, MPI_STATUS_IGNORE));
        if (from) *from = status.MPI_SOURCE;
        return {static_cast<Tag>(status.MPI_TAG), std::move(bytes)};
    }
    void barrier() override { ISOWALL_MPI_CALL(MPI_Barrier(comm_)); }
    [[noreturn]] void abort(int code) override {
        std::fflush(stdout);
        std::fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, code);
        _exit(code);
    }

private:
    MPI_Comm comm_ = MPI_COMM_NULL;
    int rank_ = 0;
    int size_ = 1;
};

}  // namespace

std::unique_ptr<Comm> make_mpi_comm(int& argc, char**& argv) {
    return std::make_unique<MpiComm>(argc, argv);
}

}  // namespace isowall
