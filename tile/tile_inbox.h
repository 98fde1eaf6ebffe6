#pragma once
// A tile rank's mailbox between its two threads. The communication thread puts every message
// from the master (and every region result from a helper) here and, when a new view or quit
// arrives, raises the stop flag that the frame being built reads between rays: the frame thread
// never makes a transport call to learn that it must stop. Snapshot requests are counted rather
// than queued, so the frame thread can answer them from inside a frame (at its progress points) or
// between frames.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>

#include "wall_protocol/protocol.h"

namespace isowall {

class TileInbox {
  public:
    // Called by the communication thread.
    void push(Message message);
    // Ends the inbox: pop() rethrows `error` once the queue is empty, and the stop flag
    // rises so a frame in progress ends too.
    void close(std::exception_ptr error = nullptr);

    // Called by the frame thread. The next message in order, or nullopt when only snapshot
    // requests are waiting (answer them with take_snapshots()). Blocks while there is nothing;
    // once closed, throws the close() error (or a runtime_error when there was none). The stop
    // flag is up while a view or quit is queued: jobs popped before it end at once.
    std::optional<Message> pop();
    // Waits at most `seconds` for something pop() would return at once (a message, a snapshot
    // request, or the close); true when there is such a thing.
    bool wait_for(double seconds);
    // The number of snapshot requests waiting, which are then taken.
    int take_snapshots();
    // Blocks until close() (a rank told to stop answering, for the fault tests).
    void wait_closed();
    // Blocks until a view or quit is queued, or close() (the `late` test fault's hold).
    void wait_interrupt();

    const std::atomic<bool>& stop_flag() const { return stop_; }

  private:
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<Message> queue_;
    int snapshots_ = 0;
    int interrupts_ = 0;  // views and quits in the queue
    bool closed_ = false;
    std::exception_ptr error_;
    std::atomic<bool> stop_{false};
};

}  // namespace isowall
