// WebServer (web_server.h): the endpoint of web_endpoint.cpp, plain or TLS, behind one face.
// Built as C++17 with the rest of isowall_remote_web.
#include "remote/http/web_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <algorithm>
#include <cctype>
#include <utility>

#include "remote/http/web_endpoint.h"

namespace isowall::web {

namespace {

std::string lower_without_final_dot(std::string name) {
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (!name.empty() && name.back() == '.') name.pop_back();
    return name;
}

bool is_ip_address(const std::string& text, int family) {
    unsigned char buf[sizeof(in6_addr)];
    return ::inet_pton(family, text.c_str(), buf) == 1;
}

bool ends_with(const std::string& text, const std::string& tail) {
    return text.size() >= tail.size() &&
           text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

bool host_allowed(const std::string& host_header, const std::vector<std::string>& names) {
    std::string host = host_header, port;
    if (!host.empty() && host.front() == '[') {
        const std::size_t close = host.find(']');
        if (close == std::string::npos) return false;
        port = host.substr(close + 1);
        host = host.substr(1, close - 1);
        if (!port.empty() && port.front() != ':') return false;
        if (!port.empty()) port.erase(0, 1);
        if (!is_ip_address(host, AF_INET6)) return false;
    } else if (const std::size_t colon = host.find(':'); colon != std::string::npos) {
        port = host.substr(colon + 1);
        host = host.substr(0, colon);
    }
    if (host.empty() || !std::all_of(port.begin(), port.end(),
                                     [](unsigned char c) { return std::isdigit(c) != 0; }))
        return false;
    if (is_ip_address(host, AF_INET) || is_ip_address(host, AF_INET6)) return true;
    host = lower_without_final_dot(host);
    if (host == "localhost" || ends_with(host, ".localhost")) return true;
    return std::any_of(names.begin(), names.end(), [&host](const std::string& name) {
        return !name.empty() && lower_without_final_dot(name) == host;
    });
}

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
