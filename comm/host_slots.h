#pragma once
// At most N of one host's tile ranks compute at once: a counting semaphore that the host's ranks
// share (a POSIX named semaphore, named after the job), which a rank holds while it runs a job
// and gives back when the job ends. With more ranks on a host than cores (a wall emulated on one
// machine), the ranks that compute at once are then as many as the cores, so a rank's thread CPU
// for a job is closer to what it would be on a core of its own than when every rank competes for
// the cores' caches at once (`wall --emulate-cores`).
#include <atomic>
#include <string>

#include <semaphore.h>

namespace isowall {

class HostSlots {
  public:
    // Opens the job's semaphore on this host, created with `slots` if it is the first to;
    // `job` tells jobs apart (Comm::job_id). Throws std::runtime_error naming the call.
    HostSlots(const std::string& job, int slots);
    ~HostSlots();
    HostSlots(const HostSlots&) = delete;
    HostSlots& operator=(const HostSlots&) = delete;

    // Takes a slot, waiting while every slot is held; gives up (false) once `stop` rises.
    bool acquire(const std::atomic<bool>& stop);
    void release();
    // The slots free now (for tests).
    int free_slots() const;
    // Removes the name (each rank may; the semaphore lives on while a rank has it open). Clean-up
    // at a rank's end: false when it could not (already gone is no failure).
    bool unlink() noexcept;

  private:
    std::string name_;
    sem_t* sem_ = nullptr;
};

// Holds one slot of `slots` (none when it is null) from construction until destruction.
class SlotHold {
  public:
    SlotHold(HostSlots* slots, const std::atomic<bool>& stop)
        : slots_(slots), held_(slots && slots->acquire(stop)) {}
    ~SlotHold() {
        if (held_) slots_->release();
    }
    SlotHold(const SlotHold&) = delete;
    SlotHold& operator=(const SlotHold&) = delete;
    // Whether the work may go on: a slot is held, or there are no slots to hold.
    bool ok() const { return !slots_ || held_; }

  private:
    HostSlots* slots_;
    bool held_;
};

}  // namespace isowall
