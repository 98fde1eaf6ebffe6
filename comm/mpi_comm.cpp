#include <mpi.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <list>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "comm/comm.h"
#include "comm/end_watch.h"

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
// A receive sleeps longer the longer nothing has come (an eighth of the quiet time, up to this):
// each poll costs a lock, an MPI_Iprobe and a wake-up, and a rank that waits a whole frame for
// its next job polled 5,000 times a second at kPollSleep (the communication thread took
// a third of a tile rank's CPU). While messages flow, the sleep stays at kPollSleep.
constexpr auto kPollSleepMax = std::chrono::microseconds(2000);
// How long a rank that ends waits for its last sends to be taken.
constexpr auto kFinalSendWait = std::chrono::seconds(10);

// MPI_Init and MPI_Finalize wait for every rank of the job, and a rank that is stopped or cut off
// would keep the others there for ever, where no message of ours can reach them. A watchdog
// thread ends this process with one line if the call has not returned in time; mpirun then ends
// the job. The master's limit is the shortest, so when it is alive its line is the one printed.
class Watchdog {
  public:
    Watchdog(double limit_s, std::string line) : line_(std::move(line)) {
        thread_ = std::thread([this, limit_s] {
            std::unique_lock lock(mutex_);
            const auto limit = std::chrono::duration<double>(limit_s);
            if (!cv_.wait_for(lock, limit, [this] { return disarmed_; })) {
                std::fflush(stdout);
                std::fputs(line_.c_str(), stderr);
                std::fflush(stderr);
                _exit(2);
            }
        });
    }
    ~Watchdog() {
        {
            std::lock_guard lock(mutex_);
            disarmed_ = true;
        }
        cv_.notify_all();
        thread_.join();
    }

  private:
    std::string line_;
    std::mutex mutex_;
    std::condition_variable cv_;
    bool disarmed_ = false;
    std::thread thread_;
};

// This process's rank and host before MPI can say (from the launcher's environment).
std::string who_before_init() {
    const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
    if (!rank) rank = std::getenv("PMIX_RANK");
    char host[256] = "?";
    ::gethostname(host, sizeof(host) - 1);
    return std::string("rank ") + (rank ? rank : "?") + " (host " + host + ")";
}

// Tiles wait a little longer than the master, and each a second longer than the one before (up
// to 8 s), so that one rank names the stall, the master when it can, before mpirun ends the rest.
double watchdog_limit(double limit_s, int rank) {
    return rank == 0 ? limit_s : limit_s + 2 + 1.0 * std::min(rank - 1, 8);
}

int rank_before_init() {
    const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
    if (!rank) rank = std::getenv("PMIX_RANK");
    return rank ? std::atoi(rank) : 1;
}

class MpiComm final : public Comm {
  public:
    MpiComm(int& argc, char**& argv, const MpiLimits& limits)
        : limits_(limits),
          // Forked first: before MPI and before the start-up watchdog's thread.
          end_watch_(limits.end_s, "isowall: error: " + who_before_init() + " stayed stopped for " +
                                       seconds(limits.end_s) +
                                       " in its last phase (--timeout): it is ended, so that the "
                                       "job ends\n") {
        Watchdog watchdog(watchdog_limit(limits.startup_s, rank_before_init()),
                          "isowall: error: " + who_before_init() +
                              ": MPI start-up did not finish within " + seconds(limits.startup_s) +
                              " (--startup-timeout): a rank of this job has stopped or cannot be "
                              "reached\n");
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
        MPI_Comm node = MPI_COMM_NULL;
        ISOWALL_MPI_CALL(MPI_Comm_split_type(comm_, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node));
        ISOWALL_MPI_CALL(MPI_Comm_size(node, &on_host_));
        // Every rank of this host and its process id, so a rank that dies here is seen at once
        // (peer_gone), without waiting for its silence.
        const int mine[2] = {rank_, static_cast<int>(::getpid())};
        std::vector<int> all(2 * static_cast<std::size_t>(on_host_));
        ISOWALL_MPI_CALL(MPI_Allgather(mine, 2, MPI_INT, all.data(), 2, MPI_INT, node));
        for (std::size_t i = 0; i + 1 < all.size(); i += 2) host_pids_[all[i]] = all[i + 1];
        MPI_Comm_free(&node);
        // The job's name: rank 0's process id and start time, the same on every rank.
        std::uint64_t id[2] = {static_cast<std::uint64_t>(::getpid()),
                               static_cast<std::uint64_t>(
                                   std::chrono::steady_clock::now().time_since_epoch().count())};
        ISOWALL_MPI_CALL(MPI_Bcast(id, 2, MPI_UINT64_T, 0, comm_));
        job_id_ = std::to_string(id[0]) + "-" + std::to_string(id[1]);
    }
    ~MpiComm() override {
        end_watch_.arm();
        // 2 s past the end watch's limit: a rank stopped in its last phase is named by its own
        // watcher (comm/end_watch.h), which knows who; this line is for ranks cut off.
        Watchdog watchdog(watchdog_limit(limits_.end_s, rank_) + 2,
                          "isowall: error: rank " + std::to_string(rank_) + " (host " + host() +
                              "): MPI did not end within " + seconds(limits_.end_s) +
                              " (--timeout): a rank of this job has stopped or cannot be "
                              "reached\n");
        wait_for_sends();
        MPI_Comm_free(&comm_);
        MPI_Finalize();
    }
    void ending() override { end_watch_.arm(); }
    int rank() const override { return rank_; }
    int size() const override { return size_; }
    int ranks_on_host() const override { return on_host_; }
    std::string job_id() const override { return job_id_; }
    bool owns_process() const override { return true; }
    bool survives_rank_loss() const override { return survives_rank_loss_; }
    bool peer_gone(int rank) const override {
        const auto it = host_pids_.find(rank);
        if (it == host_pids_.end() || rank == rank_) return false;
        if (::kill(it->second, 0) != 0) return errno == ESRCH;
        // Killed but not yet reaped by its launcher: a zombie.
        std::ifstream stat("/proc/" + std::to_string(it->second) + "/stat");
        std::string pid, name, state;
        return stat >> pid >> name >> state && state == "Z";
    }
    void end_peer(int rank) override {
        const auto it = host_pids_.find(rank);
        if (it != host_pids_.end() && rank != rank_) ::kill(it->second, SIGKILL);
    }
    bool forgot_any() const override {
        std::lock_guard lock(mutex_);
        return !forgotten_.empty();
    }
    [[noreturn]] void leave(int status) override {
        end_watch_.arm();
        wait_for_sends();
        std::fflush(nullptr);
        std::_Exit(status);
    }
    void forget(int rank) override {
        std::lock_guard lock(mutex_);
        forgotten_.insert(rank);
        for (auto it = pending_.begin(); it != pending_.end();) {
            if (it->dest != rank) {
                ++it;
                continue;
            }
            MPI_Cancel(&it->request);
            MPI_Request_free(&it->request);
            it = pending_.erase(it);
        }
    }
    std::string host() const override {
        char name[MPI_MAX_PROCESSOR_NAME];
        int len = 0;
        std::lock_guard lock(mutex_);
        MPI_Get_processor_name(name, &len);
        return std::string(name, static_cast<std::size_t>(len));
    }

    // The caller never waits for the peer: the bytes are copied and sent with MPI_Isend, and
    // every later call (either thread's) tests the sends in flight. So two ranks that send each
    // other large messages cannot deadlock, and a frame thread does not spend its CPU polling
    // for a peer that is scheduled late (with 25 ranks on 2 cores, tens of milliseconds).
    // Messages to one peer still arrive in order (MPI does not let them overtake).
    void send(int dest, Tag tag, std::span<const std::byte> bytes) override {
        send(dest, tag, std::vector<std::byte>(bytes.begin(), bytes.end()));
    }
    void send(int dest, Tag tag, std::vector<std::byte>&& bytes) override {
        std::lock_guard lock(mutex_);
        if (forgotten_.count(dest)) return;
        PendingSend& p = pending_.emplace_back();
        p.dest = dest;
        p.bytes = std::move(bytes);
        ISOWALL_MPI_CALL(MPI_Isend(p.bytes.data(), static_cast<int>(p.bytes.size()), MPI_BYTE, dest,
                                   static_cast<int>(tag), comm_, &p.request));
        progress_sends();
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
                if (flag) {
                    last_message_ = std::chrono::steady_clock::now();
                    return take(status);
                }
                progress_sends();
            }
            const auto now = std::chrono::steady_clock::now();
            const double waited = std::chrono::duration<double>(now - start).count();
            if (waited >= timeout_s) return std::nullopt;
            const auto quiet =
                std::chrono::duration_cast<std::chrono::microseconds>(now - last_message_.load());
            std::this_thread::sleep_for(std::clamp(quiet / 8, kPollSleep, kPollSleepMax));
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
                progress_sends();
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
    // Sends still in flight complete before MPI ends; a peer that is gone cannot take them, so
    // the wait is bounded (the master releases tiles only once every result is in).
    void wait_for_sends() {
        const auto start = std::chrono::steady_clock::now();
        while (true) {
            {
                std::lock_guard lock(mutex_);
                progress_sends();
                if (pending_.empty()) break;
            }
            if (std::chrono::steady_clock::now() - start > kFinalSendWait) break;
            std::this_thread::sleep_for(kPollSleep);
        }
    }

    static std::string seconds(double s) {
        char text[32];
        std::snprintf(text, sizeof(text), "%g s", s);
        return text;
    }

    struct PendingSend {
        MPI_Request request = MPI_REQUEST_NULL;
        int dest = -1;
        std::vector<std::byte> bytes;
    };

    // Drops the sends that have completed (mutex_ held).
    void progress_sends() {
        for (auto it = pending_.begin(); it != pending_.end();) {
            int done = 0;
            ISOWALL_MPI_CALL(MPI_Test(&it->request, &done, MPI_STATUS_IGNORE));
            it = done ? pending_.erase(it) : std::next(it);
        }
    }

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

    MpiLimits limits_;
    mutable std::mutex mutex_;
    // When this rank last received a message (receive's sleep grows with the quiet since).
    std::atomic<std::chrono::steady_clock::time_point> last_message_{
        std::chrono::steady_clock::now()};
    std::list<PendingSend> pending_;
    MPI_Comm comm_ = MPI_COMM_NULL;
    int rank_ = 0;
    int size_ = 1;
    int on_host_ = 1;  // ranks sharing this host (MPI_COMM_TYPE_SHARED)
    std::string job_id_;
    // mpirun --enable-recovery (or --mca orte_enable_recovery 1), which it passes to every rank.
    const bool survives_rank_loss_ = [] {
        const char* v = std::getenv("OMPI_MCA_orte_enable_recovery");
        const std::string s = v ? v : "";
        return s == "1" || s == "true" || s == "yes" || s == "on";
    }();
    std::map<int, int> host_pids_;  // rank -> process id, for the ranks on this host
    std::set<int> forgotten_;       // ranks gone for good (forget)
    EndWatch end_watch_;
};

}  // namespace

std::unique_ptr<Comm> make_mpi_comm(int& argc, char**& argv, const MpiLimits& limits) {
    return std::make_unique<MpiComm>(argc, argv, limits);
}

}  // namespace isowall
