#pragma once
// The endpoint behind WebServer (web_server.h), plain or TLS: websocketpp's asio or asio_tls
// config, one template (web_endpoint.cpp). C++17, like web_server.h; includes neither library.
#include <atomic>
#include <cstddef>
#include <memory>
#include <string>

#include "remote/http/web_server.h"

namespace isowall::web {

// What WebServer does, whichever endpoint (plain or TLS) does it.
struct WebServer::Impl {
    virtual ~Impl() = default;
    virtual int port() const = 0;
    virtual void start() = 0;
    virtual void stop() = 0;
    virtual bool send(ConnectionId id, const void* bytes, std::size_t size,
                      const std::atomic<bool>* cancel) = 0;
    virtual std::optional<WebServer::Outgoing> outgoing(ConnectionId id) = 0;
    virtual void close(ConnectionId id, const std::string& reason) = 0;
};

// Listens at once (throws std::runtime_error when it cannot), over TLS when options.tls is set.
std::unique_ptr<WebServer::Impl> make_web_endpoint(WebOptions options, WebCallbacks callbacks);

}  // namespace isowall::web
