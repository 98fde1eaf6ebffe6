#pragma once
// A private X server for tests: Xvfb on a display number it picks itself (-displayfd), with one
// screen per size given, killed when the object goes. Tests skip when Xvfb is not installed.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace isowall::test {

class Xvfb {
  public:
    // screens: "WxH" each (24-bit); the display is ":N" (screen 0 by default, ":N.1" ...).
    explicit Xvfb(const std::vector<std::string>& screens) {
        if (access("/usr/bin/Xvfb", X_OK) != 0) {
            why_ = "Xvfb is not installed (Debian's xvfb; scripts/setup.sh installs it)";
            return;
        }
        int fds[2];
        if (pipe(fds) != 0) {
            why_ = "pipe failed";
            return;
        }
        std::vector<std::string> args = {"Xvfb",      "-displayfd", std::to_string(fds[1]),
                                         "-nolisten", "tcp",        "-noreset"};
        for (std::size_t i = 0; i < screens.size(); ++i) {
            args.push_back("-screen");
            args.push_back(std::to_string(i));
            args.push_back(screens[i] + "x24");
        }
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t fa;
        posix_spawn_file_actions_init(&fa);
        posix_spawn_file_actions_addclose(&fa, fds[0]);
        posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
        const int rc = posix_spawn(&pid_, "/usr/bin/Xvfb", &fa, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&fa);
        close(fds[1]);
        if (rc != 0) {
            close(fds[0]);
            pid_ = -1;
            why_ = "cannot start Xvfb";
            return;
        }
        display_ = read_display(fds[0]);
        close(fds[0]);
        if (display_.empty()) why_ = "Xvfb did not say its display within 20 s";
    }
    ~Xvfb() {
        if (pid_ <= 0) return;
        kill(pid_, SIGTERM);
        int status = 0;
        for (int i = 0; i < 100 && waitpid(pid_, &status, WNOHANG) == 0; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        kill(pid_, SIGKILL);
        waitpid(pid_, &status, WNOHANG);
    }
    Xvfb(const Xvfb&) = delete;
    Xvfb& operator=(const Xvfb&) = delete;

    bool ok() const { return !display_.empty(); }
    const std::string& why_not() const { return why_; }
    const std::string& display() const { return display_; }  // ":N"
    std::string screen(int i) const { return display_ + "." + std::to_string(i); }

  private:
    static std::string read_display(int fd) {
        std::string number;
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
        while (std::chrono::steady_clock::now() < deadline) {
            pollfd p{fd, POLLIN, 0};
            if (::poll(&p, 1, 100) <= 0) continue;
            char c;
            const ssize_t n = read(fd, &c, 1);
            if (n <= 0) break;
            if (c == '\n') return ":" + number;
            number += c;
        }
        return {};
    }

    pid_t pid_ = -1;
    std::string display_, why_;
};

}  // namespace isowall::test
