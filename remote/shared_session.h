#pragma once
// Shared sessions of `isowall serve`: a presenter names a session (view --present
// NAME), followers join it (view --follow NAME) and see every view the presenter asks for. The
// server extracts each view once, on the presenter's connection, and its messages go out to every
// follower through a queue of the follower's own, drained by the follower's own thread at its own
// link's pace, so a slow follower never slows the presenter or the others; a follower whose queue
// would pass max_queue_bytes is dropped with an error instead.
//
// Ids. Followers see one stream of requests whoever presents: each request and each cache
// generation the presenter's session makes is given the session's next number (from 2^40 up),
// so a new presenter, whose own ids start again from 1, never reuses a number a follower holds.
//
// Joining mid-way. A follower takes the session's messages from the next request on (a request
// already going out would reach it without its beginning). Meanwhile it catches up: its own
// connection's session casts the latest request for it alone. The presenter's next request then
// begins a new cache generation (restart_cache), so no follower is named groups it never got.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "remote/view_protocol.h"

namespace isowall::remote {

struct SessionLimits {
    std::size_t max_sessions = 16;  // sessions open on the server at once
    std::size_t max_members = 32;   // per session, its presenter included
    // Bytes of messages waiting for one follower (the queue's memory): past it, it is dropped.
    std::size_t max_queue_bytes = std::size_t{64} << 20;
};

// What a follower's thread sends, in order.
class FollowerQueue {
  public:
    explicit FollowerQueue(std::size_t max_bytes) : max_bytes_(max_bytes) {}
    // From the presenter's thread. Nothing is kept before the first RequestMsg (armed) but
    // SessionMsg; a message that would take the queue past the bound drops the follower (why()
    // says so).
    void push(const RemoteMessage& m);
    // The next message, waiting while there is none; nullopt once closed or dropped.
    std::optional<RemoteMessage> pop();
    void close();
    bool armed() const;
    // True from the first RequestMsg on: a follower's catch-up stops there.
    const std::atomic<bool>& armed_flag() const { return armed_flag_; }
    // Why the follower was dropped (empty while it was not).
    std::string why() const;
    std::size_t peak_bytes() const;

  private:
    mutable std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::pair<RemoteMessage, std::size_t>> messages_;
    std::size_t max_bytes_, bytes_ = 0, peak_ = 0;
    bool armed_ = false, closed_ = false;
    std::atomic<bool> armed_flag_{false};
    std::string why_;
};

class SessionHub;

class SharedSession {
  public:
    SharedSession(std::string name, std::string dataset, std::uint8_t encoding)
        : name_(std::move(name)), dataset_(std::move(dataset)), encoding_(encoding) {}
    const std::string& name() const { return name_; }
    const std::string& dataset() const { return dataset_; }
    std::uint8_t encoding() const { return encoding_; }

    // The presenter's thread: a request begins (renumbered for the followers, who all get it),
    // and each message of it. Returns whether the presenter's session must begin a new cache
    // generation (a follower joined since the last request).
    bool begin_request(const RequestMsg& r);
    void fan_out(const RemoteMessage& m);
    // The latest request the followers were given (for a follower's catch-up), if any.
    std::optional<RequestMsg> latest() const;
    // The SessionMsg members get now, and a number that grows with every change of it (the
    // presenter's connection sends status() when it has not seen the current one; followers get
    // it in their queue).
    SessionMsg status() const;
    std::uint64_t version() const;
    // The largest queue any follower has had so far (bytes).
    std::size_t peak_queue_bytes() const;

  private:
    friend class SessionHub;
    struct Follower {
        std::string peer;
        std::shared_ptr<FollowerQueue> queue;
    };
    void changed();                  // mutex_ held: a member joined or left
    SessionMsg status_held() const;  // mutex_ held

    const std::string name_, dataset_;
    const std::uint8_t encoding_;
    mutable std::mutex mutex_;
    std::string presenter_;  // its peer, or empty
    std::vector<Follower> followers_;
    std::size_t peak_ = 0;  // of followers that left
    std::uint64_t version_ = 0;
    bool restart_ = false;  // a follower joined: the next request begins a generation
    std::uint64_t next_id_ = std::uint64_t{1} << 40;
    std::uint64_t request_ = 0;             // the current request's session number
    std::uint64_t gen_from_ = 0, gen_ = 0;  // the presenter's current generation, and its number
    std::optional<RequestMsg> latest_;
};

// A presenter's or follower's place in a session; leaving it (destruction) tells the others.
class SessionSeat {
  public:
    SessionSeat(SessionHub& hub, std::shared_ptr<SharedSession> s, std::string peer,
                std::shared_ptr<FollowerQueue> queue)
        : hub_(hub), session_(std::move(s)), peer_(std::move(peer)), queue_(std::move(queue)) {}
    ~SessionSeat();
    SessionSeat(const SessionSeat&) = delete;
    SessionSeat& operator=(const SessionSeat&) = delete;
    SharedSession& session() const { return *session_; }
    // A follower's queue (null for the presenter).
    FollowerQueue* queue() const { return queue_.get(); }

  private:
    SessionHub& hub_;
    std::shared_ptr<SharedSession> session_;
    std::string peer_;
    std::shared_ptr<FollowerQueue> queue_;
};

class SessionHub {
  public:
    explicit SessionHub(SessionLimits limits = {}) : limits_(limits) {}
    // Takes `hello`'s place (presenter or follower) for the connection `peer`, or returns null
    // and why not in `why` (one line for an ErrorMsg): the session's presenter seat is taken,
    // there is no such session to follow, another dataset or encoding, or a limit.
    std::unique_ptr<SessionSeat> join(const HelloMsg& hello, const std::string& peer,
                                      std::string& why);
    std::size_t sessions() const;
    std::size_t peak_queue_bytes() const;  // over every session, past and present
    std::size_t dropped() const;           // followers dropped as too slow, so far
    // dropped(), and the followers whose queue overflowed and who are on their way out: a
    // presenter's send that overflows a queue counts here before its send returns.
    std::size_t overflowed() const;
    void wait_dropped(std::size_t n) const;  // returns once dropped() reaches n
    const SessionLimits& limits() const { return limits_; }

  private:
    friend class SessionSeat;
    void leave(const std::shared_ptr<SharedSession>& s, const std::string& peer,
               const FollowerQueue* queue);

    SessionLimits limits_;
    mutable std::mutex mutex_;
    std::map<std::string, std::shared_ptr<SharedSession>> sessions_;
    std::size_t peak_ = 0, dropped_ = 0;
    mutable std::condition_variable dropped_changed_;
};

}  // namespace isowall::remote
