#pragma once
// The thin messaging layer between the ranks of a wall run (STYLE.md: IceT's communicator,
// OSPRay's MPI_CALL). Two transports: MPI (comm/mpi_comm.cpp, the only file that includes mpi.h)
// and in-process (comm/inproc_comm.h: every rank a thread, for tests). A Comm carries bytes under
// a Tag and knows no message: the wall's typed messages, the Tag's values and send_message are
// wall_protocol/protocol.h's.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace isowall {

// A message's kind on the wire (an MPI tag). Declared here without values: wall_protocol/protocol.h
// defines them, so this layer moves any tag it is given and never looks inside the bytes.
enum class Tag : std::int32_t;

inline constexpr double kForever = std::numeric_limits<double>::infinity();

struct Envelope {
    int from = -1;
    Tag tag{};
    std::vector<std::byte> bytes;
};

// Thrown on every rank of an in-process world once any rank aborts it (the MPI transport ends the
// processes instead), so blocked threads wake up and unwind.
class CommAborted : public std::runtime_error {
  public:
    explicit CommAborted(int code) : std::runtime_error("the job was ended"), code_(code) {}
    int code() const { return code_; }

  private:
    int code_;
};

// Thread-safe: a rank's frame thread may send while its communication thread receives.
class Comm {
  public:
    virtual ~Comm() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    virtual std::string host() const = 0;
    // How many ranks of the job run on this rank's host (they share its cores).
    virtual int ranks_on_host() const = 0;
    // A name that every rank of this job shares and no other job on the host has (for what the
    // host's ranks share: comm/host_slots.h).
    virtual std::string job_id() const = 0;
    // Whether this rank has its process to itself (MPI), so that it may change the process's
    // environment; false where ranks are threads of one process (in-process transport).
    virtual bool owns_process() const = 0;
    // Hands the bytes over and returns without waiting for the peer to take them (they are
    // copied); messages to one peer arrive in the order sent.
    virtual void send(int dest, Tag tag, std::span<const std::byte> bytes) = 0;
    // The same, handing over bytes the transport may keep instead of copying (a region result is
    // hundreds of kilobytes; a fresh copy of it costs page faults as well as the copy).
    virtual void send(int dest, Tag tag, std::vector<std::byte>&& bytes) {
        send(dest, tag, std::span<const std::byte>(bytes));
    }
    // The next message from `source` (any rank when source < 0), waiting at most timeout_s
    // (0: only look, kForever: block); nullopt when none came in time.
    virtual std::optional<Envelope> receive(int source, double timeout_s) = 0;
    virtual void barrier() = 0;
    // Ends every rank of the job at once (a failing rank must not leave others waiting).
    [[noreturn]] virtual void abort(int code) = 0;
    // Whether the job goes on when a rank dies: Open MPI started with --enable-recovery (or
    // --mca orte_enable_recovery 1); otherwise mpirun ends every rank once one dies. False in
    // process.
    virtual bool survives_rank_loss() const { return false; }
    // Whether `rank`'s process has ended, as far as this rank can see: only a rank on this host
    // (its process id is known here); false for any other, which only its silence gives away.
    virtual bool peer_gone(int rank) const {
        (void)rank;
        return false;
    }
    // Ends `rank`'s process (SIGKILL) when it is on this host: a stopped rank that the job has
    // given up on, which mpirun would otherwise wait for at the end. Nothing elsewhere.
    virtual void end_peer(int rank) { (void)rank; }
    // `rank` is gone for good: sends to it in flight are cancelled and later ones dropped (a dead
    // peer never takes a large message, and MPI would wait for it at the end).
    virtual void forget(int rank) { (void)rank; }
    // Whether this rank has forgotten a peer (forget).
    virtual bool forgot_any() const { return false; }
    // Ends this process with `status` once its sends in flight are taken, without MPI_Finalize:
    // with a rank gone, Open MPI 4's finalize (a fence over every rank of the job, the dead one
    // included) may never return. Under --enable-recovery mpirun takes such an exit quietly.
    [[noreturn]] virtual void leave(int status) {
        std::fflush(nullptr);
        std::_Exit(status);
    }
    // This rank's last phase has begun (a tile released, the master finishing): from here a stop
    // of this process that lasts the end limit is ended from outside (comm/end_watch.h), since
    // no message of the wall reaches a rank that the others no longer wait for. In process:
    // nothing.
    virtual void ending() {}
};

// How long MPI_Init and MPI_Finalize may take: they wait for every rank, so a stopped rank would
// hold the others there for ever. Past the limit the process prints one line and exits (2).
struct MpiLimits {
    double startup_s = 600;
    double end_s = 120;
};

// MPI_Init (once, asking for MPI_THREAD_SERIALIZED: calls are serialised by a lock) and a
// duplicate of MPI_COMM_WORLD, so our traffic never matches anyone else's. Finalizes MPI when
// destroyed.
std::unique_ptr<Comm> make_mpi_comm(int& argc, char**& argv, const MpiLimits& limits = {});

}  // namespace isowall
