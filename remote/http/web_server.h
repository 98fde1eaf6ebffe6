#pragma once
// An HTTP and WebSocket server on one port (websocketpp over standalone asio, one io thread),
// behind callbacks. This header is C++17 and includes neither websocketpp nor asio: websocketpp
// 0.8.2 does not compile as C++20, so web_server.cpp is built as C++17 in a target of its own
// (isowall_remote_web) and the C++20 side (remote/http_front.h) sees only this.
//
// With a TLS context (WebOptions::tls) every request and WebSocket goes over TLS (https, wss).
//
// Every request, plain or upgrade, must carry a Host header that names this server
// (host_allowed): a page of another site that made its own name resolve to this server's address
// (DNS rebinding) sends its own name there, and gets 403. Upgrades are accepted only on `ws_path`,
// and only when the Origin header is absent or is http://<Host header> (https:// with TLS) (a
// page of another site cannot drive the server); anything else is refused (403 for the Host or
// the Origin, 404 for the path) before the handshake completes.
// Plain HTTP requests go to the `http` callback. Every WebSocket message over `max_message_bytes`
// closes its connection (1009, message too big) without reaching `message`.
//
// What a client can make a connection hold is bounded: its sends wait while max_buffered_bytes
// wait to go out, a send that would take the queue past max_queued_bytes closes the connection
// (1008, policy violation), and pings get at most one pong at a time (RFC 6455 5.5.3: a newer
// ping replaces the one not yet answered). websocketpp answered every ping with a queued pong,
// and a ping flood grew the server by 130 MiB per million pings, for as long as it lasted.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct ssl_ctx_st;  // OpenSSL's SSL_CTX

namespace isowall::web {

using ConnectionId = std::uint64_t;

struct HttpRequest {
    std::string method;  // "GET", ...
    std::string path;    // the resource before any '?': "/datasets"
    std::string query;   // after the '?', undecoded: "token=abc"
};

struct HttpResponse {
    int status = 200;
    std::string content_type = "text/plain; charset=utf-8";
    std::string body;
};

struct WebCallbacks {
    std::function<HttpResponse(const HttpRequest&)> http;
    // A WebSocket opened (`peer` is "ADDR:PORT"), a message arrived, it closed (either side).
    // All run on the io thread; `closed` comes once for each `opened`.
    std::function<void(ConnectionId, const std::string& peer)> opened;
    std::function<void(ConnectionId, std::string bytes, bool binary)> message;
    std::function<void(ConnectionId)> closed;
};

struct WebOptions {
    std::string address = "127.0.0.1";
    int port = 0;  // 0: any free port (see WebServer::port)
    std::string ws_path = "/ws";
    std::size_t max_message_bytes = 1 << 16;
    // A send blocks while more than this many bytes wait to go out on its connection.
    std::size_t max_buffered_bytes = std::size_t{4} << 20;
    // A send that would queue more than this on its connection closes it (1008) instead; with
    // the wait above, only a message larger than the difference or a server configured with
    // max_buffered_bytes above it gets there. websocketpp writes all that is queued at once, so
    // a connection holds at most about twice this (queued and being written).
    std::size_t max_queued_bytes = std::size_t{64} << 20;
    // HTTPS and wss with this OpenSSL context (the server's certificate and key, as
    // remote::TlsContext::server made it; the server holds a reference of its own); null: plain.
    ssl_ctx_st* tls = nullptr;
    // The names a Host header may carry besides an IP address and localhost (host_allowed).
    std::vector<std::string> host_names;
};

// Whether a Host header ("wall.example.org:8080", "[::1]:80") names this server: an IP address,
// localhost or a name under .localhost (which browsers never look up), or one of `names` (case
// and a final dot aside). "" and malformed headers do not.
bool host_allowed(const std::string& host_header, const std::vector<std::string>& names);

// Whether a WebSocket upgrade with these headers may go on ("" when a header is absent): the
// page's own origin, https:// on a TLS server.
bool origin_allowed(const std::string& origin, const std::string& host, bool tls = false);

class WebServer {
  public:
    // Binds and listens at once; throws std::runtime_error ("address in use" and the like).
    WebServer(WebOptions options, WebCallbacks callbacks);
    ~WebServer();  // stop()
    WebServer(const WebServer&) = delete;
    WebServer& operator=(const WebServer&) = delete;

    int port() const;
    // Starts the io thread.
    void start();
    // Closes every connection (their `closed` callbacks run), stops the io thread and joins it;
    // later sends return false at once.
    void stop();

    // Sends one binary message; any thread. Blocks while the connection holds more than
    // max_buffered_bytes unsent, until they drain, the connection closes, the server stops or
    // `*cancel` reads true. Returns false when the message was not queued (closed, cancelled, or
    // over max_queued_bytes, which closes the connection).
    bool send(ConnectionId id, const void* bytes, std::size_t size,
              const std::atomic<bool>* cancel = nullptr);
    // What a connection has not yet sent: the bytes queued here and the socket's descriptor (whose
    // unacknowledged bytes the caller may ask the kernel for); nullopt when the connection is
    // gone. Any thread.
    struct Outgoing {
        std::size_t queued = 0;
        int fd = -1;
    };
    std::optional<Outgoing> outgoing(ConnectionId id) const;
    // Starts the closing handshake (after every message already queued); any thread.
    void close(ConnectionId id, const std::string& reason);

    struct Impl;  // the endpoint, plain or TLS (web_server.cpp)

  private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace isowall::web
