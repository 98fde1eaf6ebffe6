#pragma once
// SIGINT, SIGTERM and SIGHUP caught so that a command can end cleanly (serve closes its
// connections, import removes the store it was writing) and then end by that same signal, as an
// uncaught one would (exit status 128 + signal to a shell).
#include <atomic>

namespace isowall {

// Installs the handlers; from then on a stop signal sets stop_requested() instead of ending the
// process.
void catch_stop_signals();
// True once one of the signals arrived.
const std::atomic<bool>& stop_requested();
// The signal that arrived, or 0.
int stop_signal();
// When a signal arrived: its default action restored and the signal raised again, which ends the
// process. Returns when none arrived.
void end_by_stop_signal();

}  // namespace isowall
