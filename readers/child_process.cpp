#include "readers/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>

#include "core/error.h"

#if defined(__SANITIZE_ADDRESS__)
#define ISOWALL_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ISOWALL_ASAN 1
#endif
#endif
#ifdef ISOWALL_ASAN
#include <sanitizer/common_interface_defs.h>
#endif

namespace isowall::formats {

void Fd::reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

Pipe make_pipe(const std::string& where) {
    int ends[2];
    if (::pipe2(ends, O_CLOEXEC) != 0)
        throw std::runtime_error(where +
                                 ": cannot make a pipe for the reader: " + std::strerror(errno));
    return {Fd(ends[0]), Fd(ends[1])};
}

pid_t fork_reader(const std::string& where) {
    const pid_t pid = ::fork();
    if (pid < 0)
        throw std::runtime_error(where + ": cannot start the reader: " + std::strerror(errno));
    return pid;
}

bool write_all(int fd, const void* data, std::size_t n) {
    const auto* p = static_cast<const char*>(data);
    while (n > 0) {
        const ssize_t w = ::write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        p += w;
        n -= std::size_t(w);
    }
    return true;
}

// Everything the child writes to `fd` until it closes it, or until `deadline` (then false).
bool read_until_closed(int fd, std::chrono::steady_clock::time_point deadline, std::string& out) {
    char buf[4096];
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) return false;
        pollfd p{fd, POLLIN, 0};
        const int r = ::poll(&p, 1, int(std::min<long long>(left.count(), 1000)));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) continue;
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return true;
        if (out.size() < 4096) out.append(buf, std::size_t(n));
    }
}

int wait_for(pid_t pid) {
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
}

void become_child() {
    for (const int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP})
        std::signal(sig, SIG_DFL);
#ifdef ISOWALL_ASAN
    __sanitizer_set_death_callback(nullptr);
#endif
}

void run_child(int error_fd, const std::function<std::string()>& work) {
    become_child();
    char kind = 'E';
    std::string line;
    try {
        line = work();
        if (line.empty()) ::_exit(0);
    } catch (const InputError& e) {
        kind = 'I';
        line = e.what();
    } catch (const std::exception& e) {
        line = e.what();
    } catch (...) {
        line = "an unknown error";
    }
    write_all(error_fd, &kind, 1);
    write_all(error_fd, line.data(), line.size());
    ::_exit(1);
}

void child_failed(const std::string& where, const std::string& decoder, int status,
                  const std::string& message) {
    if (WIFSIGNALED(status))
        throw InputError(where, "data",
                         decoder + " failed on this data and ended (signal " +
                             std::to_string(WTERMSIG(status)) + ", " +
                             ::strsignal(WTERMSIG(status)) +
                             "): the file is damaged or of a kind it cannot decode");
    if (message.size() > 1 && message[0] == 'I') throw InputError::relayed(message.substr(1));
    if (message.size() > 1) throw std::runtime_error(message.substr(1));
    throw InputError(where, "data",
                     decoder + " failed on this data (exit status " +
                         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
                         "): the file is damaged or of a kind it cannot decode");
}

}  // namespace isowall::formats
