#pragma once
// In which order the master hands out jobs to ranks that ask for one (an emulation that
// predicts a cluster). By default a rank is served when its request arrives: on a cluster, where
// each rank has a core of its own, that is also the order of the ranks' clocks. On one machine
// with more ranks than cores, arrival follows the operating system's choice of who ran, not who
// would have been free first. In emulated-time order each rank's clock is its frame's thread CPU
// time (what it would have spent on a core of its own); the rank asking with the earliest clock
// is served first, and only once no busy rank's known clock is earlier (that rank may finish and
// ask first in emulated time). Busy ranks' clocks are known from their progress messages and
// job ends, so a wait lasts until one of them reports; nothing waits on a rank that is idle.
// Pure, without messages: the master feeds it (master/wall_master.cpp).
#include <optional>
#include <vector>

namespace isowall {

enum class Dispatch { arrival, emulated };

class DispatchOrder {
  public:
    DispatchOrder(int ranks, Dispatch order);
    // A new frame: every clock at 0, nobody asking, nobody busy.
    void begin_frame();
    // `rank`'s emulated clock is at least `seconds` (a progress message, a job's end).
    void clock(int rank, double seconds);
    // `rank` asks for work (it has no job in hand).
    void ask(int rank);
    // The next rank to serve now, taken off the asking ones; nullopt when none may be served yet.
    // In arrival order, the askers in the order they asked.
    std::optional<int> next();
    // What serving `rank` gave it: busy when it got a job (its clock then counts for the others).
    void served(int rank, bool busy);

    double clock_of(int rank) const { return clock_.at(static_cast<std::size_t>(rank)); }
    Dispatch order() const { return order_; }
    // Times next() said to wait in this frame (emulated order): how often the order mattered.
    int holds() const { return holds_; }

  private:
    Dispatch order_;
    std::vector<double> clock_;
    std::vector<bool> busy_;
    std::vector<int> asking_;  // in the order they asked
    int holds_ = 0;
};

}  // namespace isowall
