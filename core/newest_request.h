#pragma once
// A one-slot mailbox between a thread that receives requests and one that works on them, where
// the newest request wins (section 4.1: a new view interrupts the current one at once). put()
// replaces any request still waiting and raises the stop flag that the work in progress reads;
// take() hands the worker the newest request and lowers the flag. The flag is raised under the
// lock and lowered only by take(), so a put() between a take() and the next can never be missed.
// (A wall tile's inbox, tile/tile_inbox.h, is a queue instead: the jobs that follow a view must
// all be run, in order.)
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <utility>

namespace isowall {

template <class T>
class NewestRequest {
  public:
    // Called by the receiving thread.
    void put(T request) {
        std::lock_guard lock(mutex_);
        pending_ = std::move(request);
        stop_ = true;
        wake_.notify_one();
    }
    // Ends take() for good (now or once it is called) and raises the stop flag.
    void close() {
        std::lock_guard lock(mutex_);
        closed_ = true;
        stop_ = true;
        wake_.notify_one();
    }

    // Called by the working thread: blocks until there is a request (nullopt once closed).
    std::optional<T> take() {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [this] { return pending_ || closed_; });
        if (closed_) return std::nullopt;
        std::optional<T> out = std::exchange(pending_, std::nullopt);
        stop_ = false;
        return out;
    }
    // Up while a newer request waits or once closed: the request being worked on should end.
    const std::atomic<bool>& stop_flag() const { return stop_; }

  private:
    std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<T> pending_;
    bool closed_ = false;
    std::atomic<bool> stop_{false};
};

}  // namespace isowall
