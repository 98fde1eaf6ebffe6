#pragma once
// Small helpers for programs: wall-clock stopwatch, peak memory, option value parsing.
#include <chrono>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include <glm/vec2.hpp>

namespace isowall {

class Stopwatch {
  public:
    Stopwatch() : start_(std::chrono::steady_clock::now()) {}
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    void restart() { start_ = std::chrono::steady_clock::now(); }

  private:
    std::chrono::steady_clock::time_point start_;
};

// Tells the C library to keep freed memory for reuse instead of handing it back to the kernel:
// a frame's meshes, the renderer's buffers and its queued triangles are freed at the end of one
// frame and needed again in the next, and pages given back are faulted in again, zeroed, one by
// one (on this machine a 2048^3 frame on two threads took 20,000 such faults and half its time to
// C = 99%; with this, 1,000-3,500). Programs that draw frame after frame call it first in main().
// Freed memory up to kKeepFreedBytes stays in the process.
inline constexpr std::size_t kKeepFreedBytes = std::size_t(1) << 30;
void keep_freed_memory();

// The cores this process may run on (its CPU affinity mask; mpirun's binding may narrow it).
int cores_allowed();

// How many times the calling thread gave up its core of its own accord (blocked in a call: a
// socket write that waits for room, a sleep, a lock), as getrusage(RUSAGE_THREAD) counts them.
// A call during which this did not change never waited, however long it took: on a loaded
// machine a thread is also taken off its core by the scheduler, which this does not count.
long voluntary_switches();

// Peak resident set size of this process, in MiB (getrusage).
double peak_rss_mib();
// Current resident set size of this process, in MiB (/proc/self/statm).
double current_rss_mib();

// "1600x1200" -> (1600, 1200); nullopt unless two positive integers <= 32768.
std::optional<glm::ivec2> parse_size(std::string_view s);

}  // namespace isowall
