#include "app/stop_signals.h"

#include <csignal>

namespace isowall {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};

extern "C" void on_stop_signal(int sig) {
    g_signal.store(sig);
    g_stop.store(true);
}

}  // namespace

void catch_stop_signals() {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_stop_signal);
}

const std::atomic<bool>& stop_requested() {
    return g_stop;
}

int stop_signal() {
    return g_signal.load();
}

void end_by_stop_signal() {
    if (const int sig = g_signal.load(); sig != 0) {
        std::signal(sig, SIG_DFL);
        std::raise(sig);
    }
}

}  // namespace isowall
