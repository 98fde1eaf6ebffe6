#include "remote/view_server.h"

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <list>
#include <optional>

#include "core/camera.h"
#include "core/error.h"
#include "core/newest_request.h"
#include "remote/net/socket.h"
#include "remote/request_checks.h"
#include "remote/server_refusal.h"

namespace isowall::remote {

namespace {

using Clock = std::chrono::steady_clock;

// How long an error may take to go out, and a worker to stop, before the connection is shut
// down: a send to a client that does not read waits for room in its buffers for ever.
constexpr double kErrorSendTimeoutS = 2;

constexpr const char* kDroppedText =
    "too many connections had not said their hello; the oldest was closed";

std::string seconds_text(double s) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", s);
    return buf;
}

}  // namespace

struct ViewServer::Impl {
    explicit Impl(Listener l) : listener(std::move(l)) {}
    Listener listener;
    std::mutex mutex;
    std::list<std::unique_ptr<Client>> clients;  // in the order they came
    int seated = 0;                              // clients past their hello (max_clients)
};

// One connection: this reader thread, and the worker it starts once the hello is accepted.
class ViewServer::Client {
  public:
    Client(ViewServer& server, std::unique_ptr<MessageChannel> channel)
        : server_(server), channel_(std::move(channel)), conn_(*channel_) {
        thread_ = std::thread([this] { run(); });
    }
    ~Client() {
        conn_.shutdown();
        if (thread_.joinable()) thread_.join();
    }
    bool done() const { return done_.load(); }

    // The connection has not said its hello yet (under the server's mutex).
    bool before_hello() const { return !seated_ && !yielding_ && !done_.load(); }
    // Closes a connection that has not said its hello: another needs its place.
    void drop_before_hello() {
        dropped_ = true;
        conn_.shutdown();
    }
    // Whether this client may give its seat to a newcomer, and how long it has been idle: a plain
    // client (not in a shared session) between frames. Under the server's mutex.
    std::optional<double> idle_for_yield() const {
        if (!seated_ || yielding_ || seat_ || computing_.load()) return std::nullopt;
        return idle_s();
    }
    // Gives its seat away: the reader tells the client why and closes. Under the server's mutex.
    void yield_seat(std::string why) {
        yield_why_ = std::move(why);
        seated_ = false;
        yielding_ = true;
    }

  private:
    void say(const char* fmt, const std::string& a, const std::string& b = {}) const {
        if (!server_.options_.verbose) return;
        std::printf(fmt, conn_.peer().c_str(), a.c_str(), b.c_str());
        std::fflush(stdout);
    }

    // Sends the error (if the peer still listens) and says it; the caller then closes. A client
    // that does not read has its connection shut down instead (kErrorSendTimeoutS).
    void refuse(ErrorCode code, const std::string& text) {
        say("serve: %s: error: %s%s\n", text);
        within(conn_, kErrorSendTimeoutS, [&] {
            try {
                conn_.send(make_error(code, text));
            } catch (const std::exception&) {
            }
        });
    }

    // Something moved on the connection: a message came, or one went out whole.
    void touch() { last_active_ = Clock::now().time_since_epoch().count(); }
    double idle_s() const {
        const Clock::time_point last{Clock::duration(last_active_.load())};
        return std::chrono::duration<double>(Clock::now() - last).count();
    }

    const Dataset* hello() {
        const double timeout = server_.options_.hello_timeout_s;
        std::optional<RemoteMessage> m = conn_.receive(timeout);
        if (!m) {
            refuse(ErrorCode::malformed, "no hello within " + std::to_string(timeout) + " s");
            return nullptr;
        }
        const auto* h = std::get_if<HelloMsg>(&*m);
        if (!h) {
            refuse(ErrorCode::malformed,
                   std::string("expected hello, got ") + to_string(type_of(*m)) + " message");
            return nullptr;
        }
        if (h->protocol_version != kProtocolVersion) {
            refuse(ErrorCode::unsupported_version,
                   "hello: protocol_version: " + std::to_string(h->protocol_version) +
                       " (this server speaks " + std::to_string(kProtocolVersion) + ")");
            return nullptr;
        }
        if (!server_.options_.token.empty() && !same_token(h->token, server_.options_.token)) {
            refuse(ErrorCode::bad_token, "hello: token: wrong token");
            return nullptr;
        }
        if (!known_hello_encoding(h->encoding)) {
            refuse(ErrorCode::malformed,
                   "hello: encoding: unknown group encoding " + std::to_string(h->encoding));
            return nullptr;
        }
        for (const Dataset& d : server_.datasets_)
            if (d.name == h->dataset) {
                options_ = server_.options_.session;
                apply_hello_encoding(h->encoding, options_.encoding, options_.adaptive);
                // A shared session's groups go to all its members alike: exact.
                options_.exact_after = h->takes_exact && h->role == SessionRole::none;
                if (h->role == SessionRole::none) return &d;
                std::string why;
                seat_ = server_.hub_.join(*h, conn_.peer(), why);
                if (!seat_) refuse(ErrorCode::session, why);
                return seat_ ? &d : nullptr;
            }
        refuse(ErrorCode::unknown_dataset, "hello: dataset: no dataset named " + quote(h->dataset));
        return nullptr;
    }

    void run() {
        try {
            conn_.open(server_.options_.hello_timeout_s);
            if (const Dataset* d = hello()) {
                touch();  // idle from the hello on, for choosing who yields a seat
                if (const std::string busy = server_.take_seat(*this); !busy.empty())
                    refuse(ErrorCode::internal, busy);
                else
                    serve(*d);
            }
        } catch (const WireError& e) {
            refuse(code_of(e), e.what());
        } catch (const TlsHandshakeError& e) {
            // Nothing can reach the client. The text starts with the peer, which say() adds.
            std::string_view text = e.what();
            if (text.rfind(conn_.peer() + ": ", 0) == 0)
                text.remove_prefix(conn_.peer().size() + 2);
            if (dropped_)
                say("serve: %s: closed before its hello: %s\n", kDroppedText);
            else
                say("serve: %s: error: %s\n", std::string(text));
        } catch (const PeerClosed& e) {
            // A client that stops sending inside a message may still read the reply.
            if (std::string_view(e.what()).find("inside a message") != std::string_view::npos &&
                !dropped_)
                refuse(ErrorCode::malformed, e.what());
            if (dropped_) say("serve: %s: closed before its hello: %s\n", kDroppedText);
        } catch (const std::exception& e) {
            refuse(ErrorCode::internal, e.what());
        }
        stop_worker();
        if (seat_) say("serve: %s: left session %s\n", seat_->session().name());
        seat_.reset();
        conn_.close_gracefully();
        server_.leave(*this);
        done_ = true;
    }

    void serve(const Dataset& d) {
        ReadyMsg ready;
        ready.bounds = d.volume->bounds();
        ready.value_min = d.extractor->value_min();
        ready.value_max = d.extractor->value_max();
        ready.dims = d.volume->dims();
        ready.spacing = d.volume->spacing();
        ready.axes = frame_rotation(d.volume->orientation().axes);
        // Idle from here: before the ready goes out, so a client that connects once it has
        // read its ready is idle for less time than this one (who yields a seat is decided by it).
        touch();
        conn_.send(ready);
        if (server_.options_.rate_bits_per_s > 0) conn_.set_rate(server_.options_.rate_bits_per_s);
        say("serve: %s: dataset %s%s\n", d.name);
        options_.link_cap_bytes_per_s = server_.options_.rate_bits_per_s / 8;
        session_ =
            std::make_unique<ServerSession>(*d.extractor, options_, [this](const RemoteMessage& m) {
                touch();             // the client's silence counts from the send's start
                computing_ = false;  // a send the client does not read counts as idle
                const std::size_t bytes = conn_.send(m);
                touch();
                computing_ = true;
                if (seat_ && !seat_->queue()) seat_->session().fan_out(m);
                return bytes;
            });
        session_->set_link_reader([this] { return conn_.link_progress(); });
        if (seat_ && seat_->queue()) return follow();
        if (seat_) say("serve: %s: presents session %s\n", seat_->session().name());
        worker_ = std::thread([this] { work(); });
        const double limit = server_.options_.idle_timeout_s;
        for (;;) {
            if (yielding_) {
                refuse(ErrorCode::internal, yield_why_);
                return;
            }
            tell_status();
            // The server's own work on a request is not the client's silence (a frame may
            // take longer than the limit: a large view, a slow build).
            const double idle = computing_ ? 0.0 : idle_s();
            if (idle >= limit) {
                refuse(ErrorCode::malformed, "idle for " + seconds_text(limit) +
                                                 " s (--idle-timeout): nothing received or sent");
                return;
            }
            std::optional<RemoteMessage> m = conn_.receive(std::min(0.5, limit - idle));
            if (!m) continue;
            touch();
            if (!take(*m, d)) return;
        }
    }

    // One message after the hello: false when the connection ends (a bye, or an error sent).
    bool take(const RemoteMessage& m, const Dataset& d) {
        if (std::holds_alternative<ByeMsg>(m)) return false;
        if (const auto* d = std::get_if<DecodeRateMsg>(&m)) {
            session_->client_decoded(*d);  // weighed only when the server chooses
            return true;
        }
        const auto* r = std::get_if<RequestMsg>(&m);
        if (!r) {
            refuse(ErrorCode::malformed,
                   std::string("unexpected ") + to_string(type_of(m)) + " message from a client");
            return false;
        }
        // The isovalue needs the dataset; the decoder checked the rest of the view.
        const std::string problem =
            iso_problem(r->view.iso, d.extractor->value_min(), d.extractor->value_max());
        if (!problem.empty()) {
            refuse(ErrorCode::malformed, "request: view.iso: " + problem);
            return false;
        }
        computing_ = true;  // from now until the worker has run it
        requests_.put(*r);
        return true;
    }

    void work() {
        for (;;) {
            const std::optional<RequestMsg> next = requests_.take();
            if (!next) return;
            const RequestMsg& r = *next;
            try {
                computing_ = true;
                if (seat_ && seat_->session().begin_request(r)) session_->restart_cache();
                const RequestFigures f = session_->run(r, requests_.stop_flag());
                computing_ = false;
                touch();
                if (server_.options_.verbose)
                    std::printf(
                        "serve: %s: request %llu %s: %llu groups, %llu named, %llu "
                        "triangles, %llu bytes%s\n",
                        conn_.peer().c_str(), static_cast<unsigned long long>(r.request_id),
                        f.completed ? "done" : "interrupted",
                        static_cast<unsigned long long>(f.groups),
                        static_cast<unsigned long long>(f.named),
                        static_cast<unsigned long long>(f.triangles),
                        static_cast<unsigned long long>(f.bytes), lod_note(f).c_str());
            } catch (const NetError&) {
                computing_ = false;
                conn_.shutdown();  // the reader then ends the connection
                return;
            } catch (const std::exception& e) {
                computing_ = false;
                refuse(ErrorCode::internal, e.what());
                conn_.shutdown();
                return;
            }
        }
    }

    // A worker computing stops at its next ray; one blocked in a send to a client that does not
    // read is woken by shutting the connection down.
    void stop_worker() {
        requests_.close();
        if (seat_ && seat_->queue()) seat_->queue()->close();
        if (worker_.joinable()) within(conn_, kErrorSendTimeoutS, [this] { worker_.join(); });
    }

    // A presenter's connection sends its session's status when it changed.
    void tell_status() {
        if (!seat_ || seat_->session().version() == status_seen_) return;
        status_seen_ = seat_->session().version();
        conn_.send(seat_->session().status());
    }

    // A follower (shared_session.h): the reader takes only bye; the worker catches up with the
    // latest request, then sends what the session queues for it until it leaves or is dropped.
    // A follower waits for views as long as it likes: the idle limit does not apply.
    void follow() {
        say("serve: %s: follows session %s\n", seat_->session().name());
        worker_ = std::thread([this] {
            try {
                follow_work();
            } catch (const std::exception&) {  // gone: the reader ends the connection
            }
            worker_done_ = true;
        });
        for (;;) {
            // Dropped: refuse's limit shuts down a connection whose worker is stuck in a send.
            if (const std::string why = seat_->queue()->why(); !why.empty()) {
                refuse(ErrorCode::session, why);
                return;
            }
            if (worker_done_.load()) return;
            std::optional<RemoteMessage> m = conn_.receive(0.5);
            if (!m) continue;
            if (std::holds_alternative<ByeMsg>(*m)) return;
            if (std::holds_alternative<DecodeRateMsg>(*m)) continue;  // the presenter's choice
            refuse(ErrorCode::session,
                   std::holds_alternative<RequestMsg>(*m)
                       ? "a follower asks for no views: the presenter's come by themselves"
                       : std::string("unexpected ") + to_string(type_of(*m)) +
                             " message from a follower");
            return;
        }
    }

    void follow_work() {
        FollowerQueue& queue = *seat_->queue();
        conn_.send(seat_->session().status());
        if (const std::optional<RequestMsg> r = seat_->session().latest(); r && !queue.armed()) {
            conn_.send(*r);
            session_->run(*r, queue.armed_flag());
        }
        while (const std::optional<RemoteMessage> m = queue.pop()) conn_.send(*m);
    }

    ViewServer& server_;
    std::unique_ptr<MessageChannel> channel_;
    MessageChannel& conn_;
    std::unique_ptr<SessionSeat> seat_;  // in a shared session
    std::uint64_t status_seen_ = 0;
    std::atomic<bool> worker_done_{false};
    SessionOptions options_;  // the server's, with what the hello asked for
    std::unique_ptr<ServerSession> session_;
    std::thread thread_, worker_;
    NewestRequest<RequestMsg> requests_;      // the reader puts, the worker takes
    std::atomic<Clock::rep> last_active_{0};  // see touch()
    std::atomic<bool> computing_{false};      // the worker runs a request, not in a send
    std::atomic<bool> done_{false};
    // The seat (ViewServer::take_seat), under the server's mutex; yielding_ and yield_why_ are
    // written there once, and the reader reads yield_why_ after it sees yielding_.
    bool seated_ = false;
    std::atomic<bool> yielding_{false};
    std::string yield_why_;
    std::atomic<bool> dropped_{false};  // closed before its hello (drop_before_hello)

    friend class ViewServer;
};

ViewServer::ViewServer(std::vector<Dataset> datasets, ServerOptions options)
    : datasets_(std::move(datasets)), options_(std::move(options)) {
    if (std::string p = exposure_problem(options_, "listening"); !p.empty())
        throw InputError("--listen", "address", p);
    impl_ = std::make_unique<Impl>(Listener::open(options_.address, options_.port));
}

ViewServer::~ViewServer() {
    reap(true);
}

int ViewServer::port() const {
    return impl_->listener.port();
}

void ViewServer::reap(bool all) {
    // Taken out under the lock, ended outside it: a client's thread that is still running takes
    // the lock to give its seat back (leave) before its destructor's join can return.
    std::list<std::unique_ptr<Client>> ending;
    {
        std::lock_guard lock(impl_->mutex);
        for (auto it = impl_->clients.begin(); it != impl_->clients.end();) {
            const auto next = std::next(it);
            if (all || (*it)->done()) ending.splice(ending.end(), impl_->clients, it);
            it = next;
        }
    }
    const std::size_t gone = ending.size();
    ending.clear();
    // What a client that left had the server hold goes back to the system: `isowall` keeps
    // freed memory for the next frame (keep_freed_memory, core/util.h), which would keep
    // it for as long as the server runs.
    if (gone > 0 && !all) ::malloc_trim(0);
}

void ViewServer::serve(const std::atomic<bool>& stop) {
    while (!stop.load()) {
        std::string peer;
        std::optional<Socket> s = impl_->listener.accept(0.1, &peer);
        reap(false);
        if (!s) continue;
        adopt(std::make_unique<TcpChannel>(std::move(*s), peer, options_.max_payload_bytes,
                                           options_.tls));
    }
}

void ViewServer::adopt(std::unique_ptr<MessageChannel> channel) {
    std::lock_guard lock(impl_->mutex);
    ++accepted_;
    ++open_;  // here, under the lock, not in the thread: the next adopt already counts it
    // Connections that have not said their hello hold no seat, and the oldest of them makes
    // way: half-open handshakes cannot lock out a client that has the token.
    std::size_t waiting = 0;
    Client* oldest = nullptr;
    for (const std::unique_ptr<Client>& c : impl_->clients)
        if (c->before_hello() && !c->dropped_) {
            ++waiting;
            if (!oldest) oldest = c.get();
        }
    if (oldest && waiting >= static_cast<std::size_t>(options_.max_before_hello))
        oldest->drop_before_hello();
    impl_->clients.push_back(std::make_unique<Client>(*this, std::move(channel)));
}

std::string ViewServer::take_seat(Client& c) {
    std::lock_guard lock(impl_->mutex);
    if (impl_->seated < options_.max_clients) {
        ++impl_->seated;
        c.seated_ = true;
        return "";
    }
    // Every seat is taken: the client idle the longest between frames gives its seat up.
    Client* idlest = nullptr;
    double longest = -1;
    for (const std::unique_ptr<Client>& other : impl_->clients)
        if (const std::optional<double> idle = other->idle_for_yield(); idle && *idle > longest) {
            longest = *idle;
            idlest = other.get();
        }
    const std::string count = std::to_string(options_.max_clients);
    if (!idlest)
        return "server busy: " + count +
               " clients connected, each in a frame or a shared session (--max-clients)";
    char idle[32];
    std::snprintf(idle, sizeof idle, "%.1f", longest);
    idlest->yield_seat("seat given to a newer client: all " + count +
                       " seats were taken (--max-clients) and this one was idle the longest (" +
                       idle + " s)");
    c.seated_ = true;
    return "";
}

void ViewServer::leave(Client& c) {
    std::lock_guard lock(impl_->mutex);
    if (c.seated_) --impl_->seated;
    c.seated_ = false;
    --open_;
}

std::vector<std::string> ViewServer::dataset_names() const {
    std::vector<std::string> names;
    for (const Dataset& d : datasets_) names.push_back(d.name);
    return names;
}

}  // namespace isowall::remote
