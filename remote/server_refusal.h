#pragma once
// Pieces of the server's connections (view_server.cpp): a bounded wait on a channel and the
// error code a broken stream is refused with.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "remote/message_channel.h"
#include "remote/view_server.h"

namespace isowall::remote {

// Runs `f` (which must not throw) and shuts `conn` down if it has not returned within
// `timeout_s`: that ends any send or receive of `conn` that `f` waits in.
template <class F>
inline void within(MessageChannel& conn, double timeout_s, F&& f) {
    std::mutex mutex;
    std::condition_variable changed;
    bool done = false;
    std::thread watchdog([&] {
        std::unique_lock lock(mutex);
        if (!changed.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return done; }))
            conn.shutdown();
    });
    f();
    {
        std::lock_guard lock(mutex);
        done = true;
    }
    changed.notify_all();
    watchdog.join();
}

// The error code of a broken stream: the framing's and decoders' WireError texts name the field.
ErrorCode code_of(const WireError& e);

}  // namespace isowall::remote
