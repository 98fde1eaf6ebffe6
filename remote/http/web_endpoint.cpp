// websocketpp behind web_server.h, plain or TLS. Built as C++17 (websocketpp 0.8.2 is not C++20
// code).
#include "remote/http/web_endpoint.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>

#include <openssl/ssl.h>
#include <websocketpp/config/asio.hpp>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace isowall::web {
namespace {

using Handle = websocketpp::connection_hdl;
namespace status = websocketpp::http::status_code;

// How often a send blocked by back-pressure looks at the connection's buffer again.
constexpr auto kDrainPoll = std::chrono::milliseconds(2);
// How long stop() lets the connections' closing handshakes run before it stops the io thread.
constexpr auto kCloseGrace = std::chrono::seconds(1);
// How soon a pong waiting for the one before it looks again, in milliseconds: at first, and at
// most (the wait doubles while a client does not read its pongs).
constexpr long kPongPollMs = 2, kPongPollMaxMs = 256;

void split_resource(const std::string& resource, std::string& path, std::string& query) {
    const std::size_t q = resource.find('?');
    path = resource.substr(0, q);
    query = q == std::string::npos ? std::string() : resource.substr(q + 1);
}

// A server's pong frame, prepared: FIN and opcode 0xA, then the length in one byte (a ping's
// payload is at most 125 bytes, which websocketpp checks) and the payload, unmasked. Prepared
// here rather than by websocketpp's pong() so that its owner can see when it has been written:
// websocketpp holds a reference until then.
template <class Config>
typename websocketpp::server<Config>::message_ptr pong_frame(std::string payload) {
    using Message = typename Config::message_type;
    payload.resize(std::min<std::size_t>(payload.size(), 125));
    auto m = std::make_shared<Message>(typename Message::con_msg_man_ptr(),
                                       websocketpp::frame::opcode::pong, 0);
    m->set_header(std::string{static_cast<char>(0x8A), static_cast<char>(payload.size())});
    m->set_payload(payload);
    m->set_prepared(true);
    return m;
}

template <class ConnectionPtr>
void refuse(const ConnectionPtr& con, status::value code, const std::string& text) {
    con->set_status(code);
    con->replace_header("Content-Type", "text/plain; charset=utf-8");
    con->replace_header("Cache-Control", "no-store");
    con->set_body(text + "\n");
}

}  // namespace

namespace {

template <class Config>
struct Server final : WebServer::Impl {
    using Endpoint = websocketpp::server<Config>;
    using MessagePtr = typename Endpoint::message_ptr;
    using ConnectionPtr = typename Endpoint::connection_ptr;
    static constexpr bool kTls = !std::is_same_v<Config, websocketpp::config::asio>;

    Server(WebOptions o, WebCallbacks cb);
    ~Server() override { stop(); }
    int port() const override;
    void start() override;
    void stop() override;
    bool send(ConnectionId id, const void* bytes, std::size_t size,
              const std::atomic<bool>* cancel) override;
    std::optional<WebServer::Outgoing> outgoing(ConnectionId id) override;
    void close(ConnectionId id, const std::string& reason) override;

    WebOptions options;
    WebCallbacks callbacks;
    mutable Endpoint endpoint;  // mutable: websocketpp's get_local_endpoint is not const
    std::thread thread;
    std::mutex mutex;
    std::condition_variable changed;  // a connection closed, or the server stopped
    std::map<Handle, ConnectionId, std::owner_less<Handle>> ids;
    std::map<ConnectionId, Handle> handles;
    ConnectionId next_id = 1;
    bool stopped = false;

    // At most one pong per connection in websocketpp's hands (queued or being written), and the
    // newest ping's payload not answered yet; io thread only.
    struct PongSlot {
        MessagePtr out;        // the last pong sent; still held by websocketpp until written
        std::string next;      // the payload of the newest ping not answered yet
        bool waiting = false;  // `next` waits for `out` to be written
        bool timer = false;    // a timer will look again
        long poll_ms = kPongPollMs;
    };
    std::map<ConnectionId, PongSlot> pongs;

    void install_handlers();
    bool validate(Handle h);
    void serve_http(Handle h);
    void on_open(Handle h);
    void on_end(Handle h);
    bool find(ConnectionId id, Handle& h);
    ConnectionId id_of(Handle h);
    bool on_ping(Handle h, std::string payload);
    void send_pong(ConnectionId id);
    bool over_cap(const ConnectionPtr& con, std::size_t more);
};

template <class Config>
void Server<Config>::install_handlers() {
    endpoint.set_validate_handler([this](Handle h) { return validate(h); });
    endpoint.set_http_handler([this](Handle h) { serve_http(h); });
    endpoint.set_open_handler([this](Handle h) { on_open(h); });
    endpoint.set_close_handler([this](Handle h) { on_end(h); });
    endpoint.set_fail_handler([this](Handle h) { on_end(h); });
    endpoint.set_ping_handler([this](Handle h, std::string p) { return on_ping(h, std::move(p)); });
    endpoint.set_message_handler([this](Handle h, MessagePtr m) {
        const ConnectionId id = id_of(h);
        if (id == 0) return;
        const bool binary = m->get_opcode() == websocketpp::frame::opcode::binary;
        callbacks.message(id, std::move(m->get_raw_payload()), binary);
    });
}

namespace {

// The Host check's refusal: one line a user can act on.
std::string foreign_host(const std::string& host) {
    return "Host " + (host.empty() ? std::string("(none)") : host) +
           " does not name this server (a page of another site reaching it through a name of its "
           "own?): open it by an address, localhost or a name it serves, or add the name with "
           "--allow-host NAME";
}

}  // namespace

template <class Config>
bool Server<Config>::validate(Handle h) {
    const ConnectionPtr con = endpoint.get_con_from_hdl(h);
    if (const std::string host = con->get_request_header("Host");
        !host_allowed(host, options.host_names)) {
        refuse(con, status::forbidden, foreign_host(host));
        return false;
    }
    std::string path, query;
    split_resource(con->get_resource(), path, query);
    if (path != options.ws_path) {
        refuse(con, status::not_found,
               "no WebSocket at " + path + " (it is at " + options.ws_path + ")");
        return false;
    }
    if (!origin_allowed(con->get_request_header("Origin"), con->get_request_header("Host"), kTls)) {
        refuse(con, status::forbidden,
               kTls ? "Origin must be https://<Host>" : "Origin must be http://<Host>");
        return false;
    }
    return true;
}

template <class Config>
void Server<Config>::serve_http(Handle h) {
    const ConnectionPtr con = endpoint.get_con_from_hdl(h);
    if (const std::string host = con->get_request_header("Host");
        !host_allowed(host, options.host_names)) {
        refuse(con, status::forbidden, foreign_host(host));
        return;
    }
    HttpRequest request;
    request.method = con->get_request().get_method();
    split_resource(con->get_resource(), request.path, request.query);
    HttpResponse response;
    try {
        response = callbacks.http(request);
    } catch (const std::exception& e) {
        response = {500, "text/plain; charset=utf-8", std::string("internal error: ") + e.what()};
    }
    con->set_status(static_cast<status::value>(response.status));
    con->replace_header("Content-Type", response.content_type);
    con->replace_header("Cache-Control", "no-store");
    con->set_body(std::move(response.body));
}

template <class Config>
void Server<Config>::on_open(Handle h) {
    ConnectionId id = 0;
    {
        std::lock_guard lock(mutex);
        id = next_id++;
        ids[h] = id;
        handles[id] = h;
    }
    callbacks.opened(id, endpoint.get_con_from_hdl(h)->get_remote_endpoint());
}

// Close and fail both end a connection; only one that opened has an id (and a `closed`).
template <class Config>
void Server<Config>::on_end(Handle h) {
    ConnectionId id = 0;
    {
        std::lock_guard lock(mutex);
        const auto it = ids.find(h);
        if (it == ids.end()) return;
        id = it->second;
        handles.erase(id);
        ids.erase(it);
    }
    pongs.erase(id);
    changed.notify_all();
    callbacks.closed(id);
}

template <class Config>
ConnectionId Server<Config>::id_of(Handle h) {
    std::lock_guard lock(mutex);
    const auto it = ids.find(h);
    return it == ids.end() ? 0 : it->second;
}

// Never websocketpp's own pong (it would queue one for every ping): the newest payload waits in
// the connection's slot until the pong before it has been written.
template <class Config>
bool Server<Config>::on_ping(Handle h, std::string payload) {
    const ConnectionId id = id_of(h);
    if (id == 0) return false;
    PongSlot& slot = pongs[id];
    slot.next = std::move(payload);
    slot.waiting = true;
    send_pong(id);
    return false;
}

template <class Config>
void Server<Config>::send_pong(ConnectionId id) {
    const auto it = pongs.find(id);
    Handle h;
    if (it == pongs.end() || !it->second.waiting || !find(id, h)) return;
    PongSlot& slot = it->second;
    if (slot.out && slot.out.use_count() > 1) {  // websocketpp still holds the last one
        if (!slot.timer) {
            slot.timer = true;
            const long ms = std::exchange(slot.poll_ms, std::min(2 * slot.poll_ms, kPongPollMaxMs));
            endpoint.set_timer(ms, [this, id](const websocketpp::lib::error_code& ec) {
                const auto again = pongs.find(id);
                if (again == pongs.end()) return;
                again->second.timer = false;
                if (!ec) send_pong(id);
            });
        }
        return;
    }
    websocketpp::lib::error_code ec;
    const ConnectionPtr con = endpoint.get_con_from_hdl(h, ec);
    if (ec) return;
    slot.out = pong_frame<Config>(std::move(slot.next));
    slot.waiting = false;
    slot.poll_ms = kPongPollMs;
    if (!over_cap(con, slot.out->get_payload().size()))
        con->send(slot.out);  // an error only when the connection is closing: no pong is due
}

// Whether `more` bytes would take the connection's queue past max_queued_bytes; if so, closes it.
template <class Config>
bool Server<Config>::over_cap(const ConnectionPtr& con, std::size_t more) {
    if (con->get_buffered_amount() + more <= options.max_queued_bytes) return false;
    websocketpp::lib::error_code ec;
    con->close(websocketpp::close::status::policy_violation,
               "over " + std::to_string(options.max_queued_bytes) +
                   " bytes queued: the client does not read",
               ec);
    return true;
}

template <class Config>
bool Server<Config>::find(ConnectionId id, Handle& h) {
    std::lock_guard lock(mutex);
    const auto it = handles.find(id);
    if (stopped || it == handles.end()) return false;
    h = it->second;
    return true;
}

template <class Config>
Server<Config>::Server(WebOptions o, WebCallbacks cb)
    : options(std::move(o)), callbacks(std::move(cb)) {
    Endpoint& e = endpoint;
    e.clear_access_channels(websocketpp::log::alevel::all);
    e.clear_error_channels(websocketpp::log::elevel::all);
    e.init_asio();
    e.set_reuse_addr(true);
    e.set_max_message_size(options.max_message_bytes);
    e.set_max_http_body_size(options.max_message_bytes);  // only GET is served
    if constexpr (kTls) {
        // The caller's context (its certificate and key, checked when it was made), shared:
        // asio's context frees the reference it is given.
        SSL_CTX_up_ref(options.tls);
        auto context = std::make_shared<websocketpp::lib::asio::ssl::context>(options.tls);
        e.set_tls_init_handler([context](Handle) { return context; });
    }
    install_handlers();
    websocketpp::lib::error_code ec;
    e.listen(options.address, std::to_string(options.port), ec);
    if (!ec) e.start_accept(ec);
    if (ec)
        throw std::runtime_error("cannot listen on " + options.address + ":" +
                                 std::to_string(options.port) + ": " + ec.message());
}

template <class Config>
int Server<Config>::port() const {
    websocketpp::lib::asio::error_code ec;
    const auto local = endpoint.get_local_endpoint(ec);
    return ec ? -1 : local.port();
}

template <class Config>
void Server<Config>::start() {
    thread = std::thread([this] { endpoint.run(); });
}

template <class Config>
void Server<Config>::stop() {
    {
        std::lock_guard lock(mutex);
        if (stopped) return;
        stopped = true;
    }
    changed.notify_all();
    if (thread.joinable()) {
        websocketpp::lib::asio::post(endpoint.get_io_service(), [this] {
            websocketpp::lib::error_code ec;
            endpoint.stop_listening(ec);
            std::map<ConnectionId, Handle> open;
            {
                std::lock_guard lock(mutex);  // not held while closing: a handler may run
                open = handles;
            }
            for (const auto& entry : open)
                endpoint.close(entry.second, websocketpp::close::status::going_away, "server stops",
                               ec);
        });
        std::unique_lock lock(mutex);
        changed.wait_for(lock, kCloseGrace, [this] { return handles.empty(); });
        lock.unlock();
        endpoint.stop();
        thread.join();
    }
    std::map<ConnectionId, Handle> left;
    {
        std::lock_guard lock(mutex);
        left.swap(handles);
        ids.clear();
    }
    for (const auto& entry : left) callbacks.closed(entry.first);
}

template <class Config>
bool Server<Config>::send(ConnectionId id, const void* bytes, std::size_t size,
                          const std::atomic<bool>* cancel) {
    Handle h;
    if (!find(id, h)) return false;
    websocketpp::lib::error_code ec;
    const ConnectionPtr con = endpoint.get_con_from_hdl(h, ec);
    if (ec) return false;
    {
        // Back-pressure: a slow reader holds at most max_buffered_bytes (plus one message) here.
        // get_buffered_amount() reads a size_t that the io thread updates; websocketpp takes no
        // lock for it either, and a stale value only delays the next look by kDrainPoll.
        std::unique_lock lock(mutex);
        while (con->get_buffered_amount() > options.max_buffered_bytes) {
            if (stopped || !handles.count(id) || (cancel && cancel->load())) return false;
            changed.wait_for(lock, kDrainPoll);
        }
    }
    if (over_cap(con, size)) return false;
    return !con->send(bytes, size, websocketpp::frame::opcode::binary);
}

template <class Config>
std::optional<WebServer::Outgoing> Server<Config>::outgoing(ConnectionId id) {
    Handle h;
    if (!find(id, h)) return std::nullopt;
    websocketpp::lib::error_code ec;
    const ConnectionPtr con = endpoint.get_con_from_hdl(h, ec);
    if (ec) return std::nullopt;
    // The descriptor is only read: the io thread owns the socket. get_buffered_amount() as in
    // send() above.
    return WebServer::Outgoing{con->get_buffered_amount(),
                               static_cast<int>(con->get_raw_socket().native_handle())};
}

template <class Config>
void Server<Config>::close(ConnectionId id, const std::string& reason) {
    Handle h;
    if (!find(id, h)) return;
    websocketpp::lib::error_code ec;
    endpoint.close(h, websocketpp::close::status::normal, reason, ec);
}

}  // namespace

std::unique_ptr<WebServer::Impl> make_web_endpoint(WebOptions options, WebCallbacks callbacks) {
    if (options.tls)
        return std::make_unique<Server<websocketpp::config::asio_tls>>(std::move(options),
                                                                       std::move(callbacks));
    return std::make_unique<Server<websocketpp::config::asio>>(std::move(options),
                                                               std::move(callbacks));
}

}  // namespace isowall::web
