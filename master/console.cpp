#include "master/console.h"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <utility>

#include "core/error.h"

namespace isowall {
namespace {

// How long the console waits for input before the master looks after the wall again.
constexpr int kIdleSliceMs = 50;

// Lines from a file descriptor, read without blocking the master: while no whole line has come,
// `idle` runs every kIdleSliceMs.
class LineReader {
  public:
    explicit LineReader(int fd) : fd_(fd) {}

    // The next line (without its newline), or nullopt at the end of input.
    std::optional<std::string> next(const std::function<void()>& idle) {
        for (;;) {
            if (const auto nl = pending_.find('\n'); nl != std::string::npos) {
                std::string line = pending_.substr(0, nl);
                pending_.erase(0, nl + 1);
                return line;
            }
            if (ended_) {
                if (pending_.empty()) return std::nullopt;
                return std::exchange(pending_, std::string());
            }
            pollfd p{fd_, POLLIN, 0};
            const int ready = ::poll(&p, 1, kIdleSliceMs);
            if (ready < 0 && errno != EINTR) throw std::runtime_error("console: cannot poll input");
            if (ready > 0) read_some();
            idle();
        }
    }

  private:
    void read_some() {
        char buffer[4096];
        const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
        if (n > 0) pending_.append(buffer, static_cast<std::size_t>(n));
        if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN)) ended_ = true;
    }

    int fd_;
    std::string pending_;
    bool ended_ = false;
};

}  // namespace

void run_console(int fd,
                 const std::function<bool(const ScriptCommand&, const std::string& where)>& execute,
                 const std::function<void()>& idle) {
    std::printf("console: orbit, look-at, zoom, pan, iso, wait, snapshot, quit\n> ");
    std::fflush(stdout);
    LineReader reader(fd);
    int line = 0;
    while (auto text = reader.next(idle)) {
        ++line;
        if (text->find_first_not_of(" \t\r") == std::string::npos) continue;
        try {
            if (!execute(parse_command(*text, "console:" + std::to_string(line)), "console")) break;
        } catch (const InputError& e) {
            std::printf("isowall: %s\n", e.what());
        }
        std::printf("> ");
        std::fflush(stdout);
    }
}

}  // namespace isowall
