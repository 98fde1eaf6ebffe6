#pragma once
// A rank stopped (SIGSTOP, a debugger) in its last phase, once the other ranks have passed
// MPI_Finalize, keeps mpirun waiting for it for ever: no message reaches it any more, and a
// stopped process runs no watchdog of its own. So each rank forks a small watcher before MPI
// starts (a fork before MPI_Init is safe; the watcher never touches MPI) and arms it when its
// last phase begins. Armed, the watcher looks at its rank every 100 ms; a rank that stays
// stopped for the end limit is named on stderr and killed (SIGKILL ends a stopped process), so
// mpirun sees the rank end and ends the job. The watcher leaves when its rank exits (the arming
// pipe closes), and dies with it (PR_SET_PDEATHSIG).
#include <string>

namespace isowall {

class EndWatch {
  public:
    // Forks the watcher of this process; `line` is what it prints before the kill. Without a
    // watcher (fork failed) arm() does nothing: the run itself is unchanged.
    EndWatch(double limit_s, const std::string& line);
    EndWatch(const EndWatch&) = delete;
    EndWatch& operator=(const EndWatch&) = delete;
    ~EndWatch();

    // This rank's last phase has begun. Idempotent.
    void arm();

  private:
    int arm_fd_ = -1;
    bool armed_ = false;
};

// Whether /proc/PID/stat says the process is stopped (T or t).
bool process_stopped(int pid);

}  // namespace isowall
