#include "core/fatal.h"

#include <unistd.h>

#include <mutex>

#include "core/error.h"

namespace isowall {
namespace {

std::mutex g_mutex;
std::function<void(const std::string&)> g_handler;

}  // namespace

void set_fatal_handler(std::function<void(const std::string& what)> handler) {
    const std::lock_guard lock(g_mutex);
    g_handler = std::move(handler);
}

void end_with_error(const std::string& what) {
    std::function<void(const std::string&)> handler;
    {
        const std::lock_guard lock(g_mutex);
        handler = g_handler;
    }
    if (handler) handler(what);
    // One write, so that lines of two threads never interleave.
    const std::string line = "isowall: error: " + clip(what, 800) + "\n";
    [[maybe_unused]] const ssize_t n = ::write(2, line.data(), line.size());
    ::_exit(1);
}

}  // namespace isowall
