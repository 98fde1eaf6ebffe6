#include "remote/http/web_channel.h"

#include "remote/net/tcp_progress.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>

#include "remote/view_framing.h"

namespace isowall::remote {
namespace {

using Clock = std::chrono::steady_clock;

double steady_now_s() {
    return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

}  // namespace

void WebInbox::push(std::string message, bool binary) {
    {
        std::lock_guard lock(mutex);
        if (overflowed) return;
        const std::size_t size = message.size() + kInboxMessageBytes;
        if (bytes + size > kMaxInboxBytes) {
            overflowed = true;
        } else {
            bytes += size;
            messages.push_back({std::move(message), binary});
        }
    }
    changed.notify_all();
}

void WebInbox::close() {
    {
        std::lock_guard lock(mutex);
        closed = true;
    }
    changed.notify_all();
}

WebChannel::WebChannel(std::shared_ptr<web::WebServer> server, web::ConnectionId id,
                       std::string peer, std::shared_ptr<WebInbox> inbox,
                       std::uint32_t max_payload_bytes)
    : server_(std::move(server)),
      id_(id),
      peer_(std::move(peer)),
      inbox_(std::move(inbox)),
      max_payload_bytes_(max_payload_bytes) {}

WebChannel::~WebChannel() {
    shutdown();
}

void WebChannel::throw_closed() const {
    throw PeerClosed(peer_ + ": the WebSocket was closed");
}

void WebChannel::set_rate(double bits_per_second) {
    std::lock_guard lock(send_mutex_);
    bucket_ = bits_per_second == 0 ? TokenBucket() : TokenBucket(bits_per_second, kPaceChunkBytes);
}

// One wait for the whole message (the bucket goes into debt for the rest): a WebSocket message
// leaves in one piece, so the link's rate holds over messages rather than within one.
void WebChannel::pace(std::size_t bytes) {
    for (;;) {
        const double now = steady_now_s();
        const double wait = bucket_.delay_s(bytes, now);
        if (wait <= 0) {
            bucket_.take(bytes, now);
            return;
        }
        std::unique_lock lock(inbox_->mutex);
        inbox_->changed.wait_for(lock, std::chrono::duration<double>(std::min(wait, 3600.0)),
                                 [this] { return shut_down_.load() || inbox_->closed; });
        if (shut_down_ || inbox_->closed) throw_closed();
    }
}

std::optional<LinkProgress> WebChannel::link_progress() const {
    const std::optional<web::WebServer::Outgoing> out = server_->outgoing(id_);
    if (!out) return std::nullopt;
    const std::optional<TcpProgress> tcp = tcp_progress(out->fd);
    if (!tcp) return std::nullopt;
    return LinkProgress{out->queued, tcp->acked, tcp->unacked, tcp->receiver_held_s,
                        tcp->same_host};
}

std::size_t WebChannel::send(const RemoteMessage& m) {
    const std::vector<std::byte> frame = encode_frame(m);
    std::lock_guard lock(send_mutex_);
    if (shut_down_) throw_closed();
    if (bucket_.limited()) pace(frame.size());
    if (!server_->send(id_, frame.data(), frame.size(), &shut_down_)) throw_closed();
    return frame.size();
}

RemoteMessage WebChannel::decode(const WebInbox::Message& message) {
    try {
        if (!message.binary)
            throw WireError("WebSocket: a text message (each message must be one binary frame)");
        const auto* data = reinterpret_cast<const std::byte*>(message.bytes.data());
        return decode_frame(std::span<const std::byte>(data, message.bytes.size()),
                            max_payload_bytes_);
    } catch (const WireError& e) {
        broken_ = e.what();
        throw;
    }
}

std::optional<RemoteMessage> WebChannel::receive(double timeout_s) {
    if (broken_) throw WireError(*broken_);
    const bool forever = !(timeout_s >= 0) || std::isinf(timeout_s);
    const auto ready = [this] {
        return !inbox_->messages.empty() || inbox_->overflowed || inbox_->closed ||
               shut_down_.load();
    };
    std::unique_lock lock(inbox_->mutex);
    if (forever)
        inbox_->changed.wait(lock, ready);
    else if (!inbox_->changed.wait_for(lock, std::chrono::duration<double>(timeout_s), ready))
        return std::nullopt;
    if (shut_down_) throw_closed();
    if (inbox_->messages.empty() && inbox_->overflowed) {
        broken_ = "WebSocket: messages waiting unread: over the limit of " +
                  std::to_string(kMaxInboxBytes) +
                  " bytes (the client sends faster than "
                  "the server reads)";
        throw WireError(*broken_);
    }
    if (inbox_->messages.empty()) throw PeerClosed(peer_ + ": the client closed the WebSocket");
    const WebInbox::Message message = std::move(inbox_->messages.front());
    inbox_->messages.pop_front();
    inbox_->bytes -= message.bytes.size() + kInboxMessageBytes;
    lock.unlock();
    return decode(message);
}

void WebChannel::shutdown() {
    {
        std::lock_guard lock(inbox_->mutex);
        if (shut_down_.exchange(true)) return;
    }
    inbox_->changed.notify_all();
    server_->close(id_, "closed by the server");
}

}  // namespace isowall::remote
