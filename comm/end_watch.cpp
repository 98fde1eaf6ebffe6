#include "comm/end_watch.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <ctime>

namespace isowall {
namespace {

double now_s() {
    timespec t{};
    ::clock_gettime(CLOCK_MONOTONIC, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The watcher's whole life, after the fork: only system calls and the buffers made before it
// (another thread of the parent may have held the allocator's lock at the fork).
[[noreturn]] void watch(int arm_fd, int parent, double limit_s, const char* line,
                        std::size_t line_len) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(0);
    ::prctl(PR_SET_NAME, "isowall-watch", 0, 0, 0);
    bool armed = false;
    double stopped_since = -1;
    for (;;) {
        pollfd p{arm_fd, POLLIN, 0};
        if (::poll(&p, 1, 100) > 0) {
            char b = 0;
            if (::read(arm_fd, &b, 1) <= 0) ::_exit(0);  // the rank has exited
            armed = true;
        }
        if (!armed) continue;
        if (!process_stopped(parent)) {
            stopped_since = -1;
            continue;
        }
        if (stopped_since < 0) stopped_since = now_s();
        if (now_s() - stopped_since >= limit_s) {
            (void)!::write(STDERR_FILENO, line, line_len);
            ::kill(parent, SIGKILL);
            ::_exit(0);
        }
    }
}

}  // namespace

bool process_stopped(int pid) {
    char path[64];
    std::snprintf(path, sizeof path, "/proc/%d/stat", pid);
    const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    char buf[512];
    const ssize_t n = ::read(fd, buf, sizeof buf - 1);
    ::close(fd);
    if (n <= 0) return false;
    buf[n] = '\0';
    // "PID (COMM) S ...": the name may hold ") "; the state follows the last one.
    const char* close = nullptr;
    for (const char* p = std::strstr(buf, ") "); p; p = std::strstr(p + 1, ") ")) close = p;
    return close && (close[2] == 'T' || close[2] == 't');
}

EndWatch::EndWatch(double limit_s, const std::string& line) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) return;
    std::fflush(stdout);
    std::fflush(stderr);
    const int parent = ::getpid();
    const pid_t child = ::fork();
    if (child == 0) {
        ::close(fds[1]);
        watch(fds[0], parent, limit_s, line.c_str(), line.size());
    }
    ::close(fds[0]);
    if (child < 0) {
        ::close(fds[1]);
        return;
    }
    arm_fd_ = fds[1];
}

// The arming pipe stays open until the process exits: its closing is how the watcher learns
// that the rank has gone, and the teardown after MPI (destructors, exit) is part of the last
// phase a stop can hit.
EndWatch::~EndWatch() = default;

void EndWatch::arm() {
    if (armed_ || arm_fd_ < 0) return;
    armed_ = true;
    const char b = 1;
    (void)!::write(arm_fd_, &b, 1);
}

}  // namespace isowall
