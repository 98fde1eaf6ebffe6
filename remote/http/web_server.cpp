// WebServer (web_server.h): the endpoint of web_endpoint.cpp, plain or TLS, behind one face.
// Built as C++17 with the rest of isowall_remote_web.
#include "remote/http/web_server.h"

#include <utility>

#include "remote/http/web_endpoint.h"

namespace isowall::web {

bool origin_allowed(const std::string& origin, const std::string& host, bool tls) {
    return origin.empty() || (!host.empty() && origin == (tls ? "https://" : "http://") + host);
}

WebServer::WebServer(WebOptions options, WebCallbacks callbacks)
    : impl_(make_web_endpoint(std::move(options), std::move(callbacks))) {}

WebServer::~WebServer() {
    stop();
}

int WebServer::port() const {
    return impl_->port();
}

void WebServer::start() {
    impl_->start();
}

void WebServer::stop() {
    impl_->stop();
}

bool WebServer::send(ConnectionId id, const void* bytes, std::size_t size,
                     const std::atomic<bool>* cancel) {
    return impl_->send(id, bytes, size, cancel);
}

std::optional<WebServer::Outgoing> WebServer::outgoing(ConnectionId id) const {
    return impl_->outgoing(id);
}

void WebServer::close(ConnectionId id, const std::string& reason) {
    impl_->close(id, reason);
}

}  // namespace isowall::web
