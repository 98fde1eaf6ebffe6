#pragma once
// The in-process transport: every rank of a wall run is a thread of one process, so the master
// and tile logic (interrupts, snapshots, progress, a silent tile, later job migration) run in unit
// tests in seconds, deterministically, without mpirun. Messages are copied into the receiver's
// mailbox; abort() wakes every blocked rank with CommAborted, as MPI_Abort ends every process.
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "comm/comm.h"

namespace isowall {

class InProcWorld {
  public:
    explicit InProcWorld(int size);
    int size() const { return static_cast<int>(mailboxes_.size()); }
    // This process's id and the world's number in it: no two worlds share it.
    const std::string& id() const { return id_; }
    // The Comm of one rank; it refers to this world, which must outlive it.
    std::unique_ptr<Comm> comm(int rank);
    // The code of the first abort, if any rank aborted.
    std::optional<int> aborted() const;

  private:
    friend class InProcComm;
    struct Mailbox {
        std::deque<Envelope> messages;
    };
    void post(int dest, Envelope e);
    std::optional<Envelope> take(int rank, int source, double timeout_s);
    void barrier();
    [[noreturn]] void abort(int code);
    void throw_if_aborted() const;  // mutex_ held

    mutable std::mutex mutex_;
    std::condition_variable changed_;
    std::vector<Mailbox> mailboxes_;
    std::string id_;
    std::optional<int> abort_code_;
    int barrier_waiting_ = 0;
    std::uint64_t barrier_round_ = 0;
};

// Runs fn(comm) for every rank of a new world, each on its own thread, and returns each rank's
// exit code: fn's return value, or the abort code for a rank that was ended by an abort (its own
// or another's). An exception other than CommAborted escaping fn aborts the world with code 1.
std::vector<int> run_in_process(int ranks, const std::function<int(Comm&)>& fn);

}  // namespace isowall
