#include "remote/shared_session.h"

#include <algorithm>
#include <cstdio>

#include "core/error.h"

namespace isowall::remote {
namespace {

// What a message holds in a follower's queue: its payload (the groups' bytes, mostly).
std::size_t queued_bytes(const RemoteMessage& m) {
    if (const auto* g = std::get_if<GroupMsg>(&m)) return g->encoded.size() + 64;
    if (const auto* v = std::get_if<VisibleMsg>(&m)) return v->slots.size() * 4 + 64;
    return 256;
}

std::string mib(std::size_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / (1 << 20));
    return text;
}

}  // namespace

void FollowerQueue::push(const RemoteMessage& m) {
    std::lock_guard lock(mutex_);
    if (closed_ || !why_.empty()) return;
    const bool status = std::holds_alternative<SessionMsg>(m);
    if (std::holds_alternative<RequestMsg>(m)) armed_flag_ = armed_ = true;
    if (!armed_ && !status) return;
    const std::size_t n = queued_bytes(m);
    if (bytes_ + n > max_bytes_ && !status) {
        why_ = "dropped from the session: " + mib(bytes_ + n) +
               " waiting to reach this follower (the limit is " + mib(max_bytes_) +
               "): its link is slower than the presenter's views";
        messages_.clear();
        bytes_ = 0;
        changed_.notify_all();
        return;
    }
    messages_.emplace_back(m, n);
    bytes_ += n;
    peak_ = std::max(peak_, bytes_);
    changed_.notify_all();
}

std::optional<RemoteMessage> FollowerQueue::pop() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return closed_ || !why_.empty() || !messages_.empty(); });
    if (closed_ || !why_.empty()) return std::nullopt;
    auto [m, n] = std::move(messages_.front());
    messages_.pop_front();
    bytes_ -= n;
    return std::move(m);
}

void FollowerQueue::close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    armed_flag_ = true;  // a catch-up in progress stops too
    messages_.clear();
    bytes_ = 0;
    changed_.notify_all();
}

bool FollowerQueue::armed() const {
    std::lock_guard lock(mutex_);
    return armed_;
}

std::string FollowerQueue::why() const {
    std::lock_guard lock(mutex_);
    return why_;
}

std::size_t FollowerQueue::peak_bytes() const {
    std::lock_guard lock(mutex_);
    return peak_;
}

bool SharedSession::begin_request(const RequestMsg& r) {
    std::lock_guard lock(mutex_);
    RequestMsg out = r;
    out.request_id = request_ = next_id_++;
    latest_ = out;
    for (Follower& f : followers_) f.queue->push(out);
    const bool restart = restart_;
    restart_ = false;
    return restart;
}

void SharedSession::fan_out(const RemoteMessage& m) {
    RemoteMessage out = m;
    std::lock_guard lock(mutex_);
    std::visit(
        [&](auto& msg) {
            if constexpr (requires { msg.request_id; }) msg.request_id = request_;
            if constexpr (requires { msg.cache_gen; }) {
                // A generation is the id of the request that began it: a new id, a new one.
                if (msg.cache_gen != 0 && msg.cache_gen != gen_from_) {
                    gen_from_ = msg.cache_gen;
                    gen_ = next_id_++;
                }
                if (msg.cache_gen != 0) msg.cache_gen = gen_;
            }
        },
        out);
    for (Follower& f : followers_) f.queue->push(out);
}

std::optional<RequestMsg> SharedSession::latest() const {
    std::lock_guard lock(mutex_);
    return latest_;
}

SessionMsg SharedSession::status() const {
    std::lock_guard lock(mutex_);
    return status_held();
}

SessionMsg SharedSession::status_held() const {
    return {name_, presenter_,
            static_cast<std::uint32_t>(followers_.size() + (presenter_.empty() ? 0 : 1))};
}

std::uint64_t SharedSession::version() const {
    std::lock_guard lock(mutex_);
    return version_;
}

std::size_t SharedSession::peak_queue_bytes() const {
    std::lock_guard lock(mutex_);
    std::size_t peak = peak_;
    for (const Follower& f : followers_) peak = std::max(peak, f.queue->peak_bytes());
    return peak;
}

void SharedSession::changed() {
    ++version_;
    const SessionMsg now = status_held();
    for (Follower& f : followers_) f.queue->push(now);
}

SessionSeat::~SessionSeat() {
    if (queue_) queue_->close();
    hub_.leave(session_, peer_, queue_.get());
}

std::unique_ptr<SessionSeat> SessionHub::join(const HelloMsg& h, const std::string& peer,
                                              std::string& why) {
    std::lock_guard lock(mutex_);
    auto it = sessions_.find(h.session);
    const std::string named = "session " + quote(h.session);
    if (it == sessions_.end()) {
        if (h.role == SessionRole::follower) {
            why = "hello: session: no " + named + " to follow (its presenter starts it)";
            return nullptr;
        }
        if (sessions_.size() >= limits_.max_sessions) {
            why = "hello: session: " + std::to_string(limits_.max_sessions) +
                  " sessions are open, the server's limit";
            return nullptr;
        }
        it = sessions_
                 .emplace(h.session,
                          std::make_shared<SharedSession>(h.session, h.dataset, h.encoding))
                 .first;
    }
    SharedSession& s = *it->second;
    std::lock_guard session_lock(s.mutex_);
    if (s.dataset_ != h.dataset) {
        why = "hello: dataset: " + named + " shows " + quote(s.dataset_);
        return nullptr;
    }
    if (s.encoding_ != h.encoding) {
        why = "hello: encoding: " + named + " sends groups in encoding " +
              std::to_string(s.encoding_) + " (view --encoding)";
        return nullptr;
    }
    if (s.status_held().members + 1 > limits_.max_members) {
        why = "hello: session: " + named + " has " + std::to_string(limits_.max_members) +
              " members, the server's limit";
        return nullptr;
    }
    std::shared_ptr<FollowerQueue> queue;
    if (h.role == SessionRole::presenter) {
        if (!s.presenter_.empty()) {
            why = "hello: session: " + s.presenter_ + " presents " + named + " already";
            return nullptr;
        }
        s.presenter_ = peer;
        s.gen_from_ = 0;  // the new presenter's ids start again: each gets a new number
    } else {
        queue = std::make_shared<FollowerQueue>(limits_.max_queue_bytes);
        s.followers_.push_back({peer, queue});
        s.restart_ = true;
    }
    s.changed();
    return std::make_unique<SessionSeat>(*this, it->second, peer, queue);
}

void SessionHub::leave(const std::shared_ptr<SharedSession>& s, const std::string& peer,
                       const FollowerQueue* queue) {
    std::lock_guard lock(mutex_);
    if (queue && !queue->why().empty()) {
        ++dropped_;
        dropped_changed_.notify_all();
    }
    {
        std::lock_guard session_lock(s->mutex_);
        if (queue) {
            std::erase_if(s->followers_, [&](const SharedSession::Follower& f) {
                if (f.queue.get() != queue) return false;
                s->peak_ = std::max(s->peak_, f.queue->peak_bytes());
                return true;
            });
        } else if (s->presenter_ == peer) {
            s->presenter_.clear();
        }
        peak_ = std::max(peak_, s->peak_);
        if (!s->presenter_.empty() || !s->followers_.empty()) {
            s->changed();
            return;
        }
    }
    if (auto it = sessions_.find(s->name()); it != sessions_.end() && it->second == s)
        sessions_.erase(it);
}

std::size_t SessionHub::sessions() const {
    std::lock_guard lock(mutex_);
    return sessions_.size();
}

std::size_t SessionHub::dropped() const {
    std::lock_guard lock(mutex_);
    return dropped_;
}

std::size_t SessionHub::overflowed() const {
    std::lock_guard lock(mutex_);
    std::size_t n = dropped_;
    for (const auto& [name, s] : sessions_) {
        std::lock_guard session_lock(s->mutex_);
        for (const SharedSession::Follower& f : s->followers_) n += !f.queue->why().empty();
    }
    return n;
}

void SessionHub::wait_dropped(std::size_t n) const {
    std::unique_lock lock(mutex_);
    dropped_changed_.wait(lock, [&] { return dropped_ >= n; });
}

std::size_t SessionHub::peak_queue_bytes() const {
    std::lock_guard lock(mutex_);
    std::size_t peak = peak_;
    for (const auto& [name, s] : sessions_) peak = std::max(peak, s->peak_queue_bytes());
    return peak;
}

}  // namespace isowall::remote
