#include "remote/net/connection.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>

namespace isowall::remote {
namespace {

using Clock = std::chrono::steady_clock;

// One recv takes at most this much: a large group arrives in several calls, never one
// allocation sized by the peer (the parser grows its payload as the bytes come).
constexpr std::size_t kRecvBufferBytes = 64 * 1024;

double steady_now_s() {
    return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

}  // namespace

Connection::Connection(Socket s, std::string peer, std::uint32_t max_payload_bytes)
    : socket_(std::move(s)),
      peer_(std::move(peer)),
      parser_(max_payload_bytes),
      recv_buffer_(kRecvBufferBytes) {
    clock_.now_s = steady_now_s;
    clock_.wait_s = [this](double seconds) {
        std::unique_lock lock(wake_mutex_);
        wake_.wait_for(lock, std::chrono::duration<double>(std::min(seconds, 3600.0)),
                       [this] { return shut_down_.load(); });
    };
}

void Connection::throw_shut_down() const {
    throw PeerClosed(peer_ + ": the connection was shut down");
}

void Connection::set_rate(double bits_per_second, std::size_t burst_bytes) {
    std::lock_guard lock(send_mutex_);
    bucket_ = bits_per_second == 0 ? TokenBucket() : TokenBucket(bits_per_second, burst_bytes);
}

void Connection::set_pacing_clock(PacingClock clock) {
    std::lock_guard lock(send_mutex_);
    clock_ = std::move(clock);
}

void Connection::pace(std::size_t bytes) {
    for (;;) {
        const double now = clock_.now_s();
        const double wait = bucket_.delay_s(bytes, now);
        if (wait <= 0) {
            bucket_.take(bytes, now);
            return;
        }
        clock_.wait_s(wait);
        if (shut_down_) throw_shut_down();
    }
}

std::size_t Connection::send(const RemoteMessage& m) {
    const std::vector<std::byte> frame = encode_frame(m);
    std::lock_guard lock(send_mutex_);
    if (shut_down_) throw_shut_down();
    std::span<const std::byte> rest(frame);
    while (!rest.empty()) {
        // Paced sends go in chunks, each waiting for its tokens, so that a large group trickles
        // out at the link's rate instead of in one burst followed by a long silence.
        const std::size_t n =
            bucket_.limited() ? std::min(rest.size(), kPaceChunkBytes) : rest.size();
        if (bucket_.limited()) pace(n);
        try {
            send_all(socket_, rest.first(n), peer_);
        } catch (const NetError&) {
            if (shut_down_) throw_shut_down();
            throw;
        }
        bytes_sent_ += n;
        rest = rest.subspan(n);
    }
    return frame.size();
}

std::optional<RemoteMessage> Connection::receive(double timeout_s) {
    if (broken_) throw WireError(*broken_);
    const bool forever = !(timeout_s >= 0) || std::isinf(timeout_s);
    const double deadline_s = forever ? 0 : steady_now_s() + timeout_s;
    for (;;) {
        if (recv_begin_ < recv_end_) {
            std::span<const std::byte> input(recv_buffer_.data() + recv_begin_,
                                             recv_end_ - recv_begin_);
            std::optional<RemoteMessage> m;
            try {
                m = parser_.next(input);
            } catch (const WireError& e) {
                broken_ = e.what();
                throw;
            }
            recv_begin_ = recv_end_ - input.size();
            if (m) return m;
        }
        if (shut_down_) throw_shut_down();
        const double left_s = forever ? -1 : std::max(0.0, deadline_s - steady_now_s());
        std::size_t got = 0;
        try {
            if (!recv_some(socket_, recv_buffer_, left_s, got, peer_)) return std::nullopt;
        } catch (const PeerClosed&) {
            if (shut_down_) throw_shut_down();
            if (parser_.pending_bytes() > 0)
                throw PeerClosed(peer_ + ": the stream was cut short inside a message (" +
                                 std::to_string(parser_.pending_bytes()) +
                                 " bytes of it received)");
            throw;
        }
        recv_begin_ = 0;
        recv_end_ = got;
        bytes_received_ += got;
    }
}

void Connection::shutdown() {
    {
        std::lock_guard lock(wake_mutex_);
        shut_down_ = true;
    }
    wake_.notify_all();
    socket_.shutdown_both();
}

}  // namespace isowall::remote
