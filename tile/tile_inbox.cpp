#include "tile/tile_inbox.h"

#include <chrono>
#include <stdexcept>
#include <utility>

namespace isowall {
namespace {

// A new view or quit ends the frame being built; jobs and results queue behind it.
bool interrupts(const Message& m) {
    return std::holds_alternative<ViewMsg>(m) || std::holds_alternative<QuitMsg>(m);
}

}  // namespace

void TileInbox::push(Message message) {
    std::lock_guard lock(mutex_);
    if (std::holds_alternative<SnapshotMsg>(message)) {
        ++snapshots_;
    } else {
        // Raised under the lock, so a pop() that lowers it cannot miss this message.
        if (interrupts(message)) {
            ++interrupts_;
            stop_ = true;
        }
        queue_.push_back(std::move(message));
    }
    changed_.notify_all();
}

void TileInbox::close(std::exception_ptr error) {
    std::lock_guard lock(mutex_);
    closed_ = true;
    if (!error_) error_ = error;
    stop_ = true;
    changed_.notify_all();
}

std::optional<Message> TileInbox::pop() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !queue_.empty() || snapshots_ > 0 || closed_; });
    if (closed_ && queue_.empty()) {
        if (error_) std::rethrow_exception(error_);
        throw std::runtime_error("the communication thread ended");
    }
    if (queue_.empty()) return std::nullopt;  // snapshot requests only
    Message m = std::move(queue_.front());
    queue_.pop_front();
    if (interrupts(m)) --interrupts_;
    stop_ = closed_ || interrupts_ > 0;
    return m;
}

bool TileInbox::wait_for(double seconds) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, std::chrono::duration<double>(seconds),
                             [&] { return !queue_.empty() || snapshots_ > 0 || closed_; });
}

int TileInbox::take_snapshots() {
    std::lock_guard lock(mutex_);
    return std::exchange(snapshots_, 0);
}

void TileInbox::wait_closed() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return closed_; });
}

void TileInbox::wait_interrupt() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return interrupts_ > 0 || closed_; });
}

}  // namespace isowall
