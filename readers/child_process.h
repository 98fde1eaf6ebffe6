#pragma once
// What a reader in a child process (isolated_read.h) and its parent share: descriptors closed with
// their owner, whole writes, a wait, and the one error a child's failure becomes.
#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>

namespace isowall::formats {

// A file descriptor closed with its owner.
class Fd {
  public:
    explicit Fd(int fd = -1) : fd_(fd) {}
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd() { reset(); }
    int get() const { return fd_; }
    void reset();
    int release() { return std::exchange(fd_, -1); }  // the caller owns it now

  private:
    int fd_;
};

// A pipe (close-on-exec); std::runtime_error naming `where` when none can be made.
struct Pipe {
    Fd read, write;
};
Pipe make_pipe(const std::string& where);

// fork(): 0 in the child, its pid in the parent; std::runtime_error naming `where` on failure.
pid_t fork_reader(const std::string& where);

// All of `n` bytes to `fd` (false on an error or a closed reader).
bool write_all(int fd, const void* data, std::size_t n);

// Everything the child writes to `fd` until it closes it (the first 4 KiB kept in `out`), or
// until `deadline` (then false).
bool read_until_closed(int fd, std::chrono::steady_clock::time_point deadline, std::string& out);

// waitpid through EINTR; the status.
int wait_for(pid_t pid);

// What a child does first: a crash ends it by its signal. Handlers the parent installed (a
// fuzzer's, which would report the parent's input as its own finding) are not the child's to run,
// nor is a sanitizer's death callback (libFuzzer's writes the input as a crash of its own).
void become_child();

// A child's whole life after become_child(): `work` runs; when it returns an empty string the
// child leaves with status 0, else with 1 after writing to `error_fd` 'E' and the line it
// returned. An InputError it throws is written as 'I' and its line (child_failed relays it as it
// is), any other exception as 'E' and its message. Never returns.
[[noreturn]] void run_child(int error_fd, const std::function<std::string()>& work);

// The error a child that did not exit 0 means: the InputError it relayed in `message` ('I' and
// its line), another error's line, or its signal or exit status, naming `where` and `decoder`.
[[noreturn]] void child_failed(const std::string& where, const std::string& decoder, int status,
                               const std::string& message);

}  // namespace isowall::formats
