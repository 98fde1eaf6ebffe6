// websocketpp behind web_server.h. Built as C++17 (websocketpp 0.8.2 is not C++20 code).
#include "remote/web/web_server.h"

#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace isowall::web {
namespace {

using Endpoint = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;
namespace status = websocketpp::http::status_code;

// How often a send blocked by back-pressure looks at the connection's buffer again.
constexpr auto kDrainPoll = std::chrono::milliseconds(2);
// How long stop() lets the connections' closing handshakes run before it stops the io thread.
constexpr auto kCloseGrace = std::chrono::seconds(1);

void split_resource(const std::string& resource, std::string& path, std::string& query) {
    const std::size_t q = resource.find('?');
    path = resource.substr(0, q);
    query = q == std::string::npos ? std::string() : resource.substr(q + 1);
}

void refuse(const Endpoint::connection_ptr& con, status::value code, const std::string& text) {
    con->set_status(code);
    con->replace_header("Content-Type", "text/plain; charset=utf-8");
    con->replace_header("Cache-Control", "no-store");
    con->set_body(text + "\n");
}

}  // namespace

bool origin_allowed(const std::string& origin, const std::string& host) {
    return origin.empty() || (!host.empty() && origin == "http://" + host);
}

struct WebServer::Impl {
    WebOptions options;
    WebCallbacks callbacks;
    Endpoint endpoint;
    std::thread thread;
    std::mutex mutex;
    std::condition_variable changed;  // a connection closed, or the server stopped
    std::map<Handle, ConnectionId, std::owner_less<Handle>> ids;
    std::map<ConnectionId, Handle> handles;
    ConnectionId next_id = 1;
    bool stopped = false;

    void install_handlers();
    bool validate(Handle h);
    void serve_http(Handle h);
    void on_open(Handle h);
    void on_end(Handle h);
    bool find(ConnectionId id, Handle& h);
};

void WebServer::Impl::install_handlers() {
    endpoint.set_validate_handler([this](Handle h) { return validate(h); });
    endpoint.set_http_handler([this](Handle h) { serve_http(h); });
    endpoint.set_open_handler([this](Handle h) { on_open(h); });
    endpoint.set_close_handler([this](Handle h) { on_end(h); });
    endpoint.set_fail_handler([this](Handle h) { on_end(h); });
    endpoint.set_message_handler([this](Handle h, Endpoint::message_ptr m) {
        ConnectionId id = 0;
        {
            std::lock_guard lock(mutex);
            const auto it = ids.find(h);
            if (it == ids.end()) return;
            id = it->second;
        }
        const bool binary = m->get_opcode() == websocketpp::frame::opcode::binary;
        callbacks.message(id, std::move(m->get_raw_payload()), binary);
    });
}

bool WebServer::Impl::validate(Handle h) {
    const Endpoint::connection_ptr con = endpoint.get_con_from_hdl(h);
    std::string path, query;
    split_resource(con->get_resource(), path, query);
    if (path != options.ws_path) {
        refuse(con, status::not_found,
               "no WebSocket at " + path + " (it is at " + options.ws_path + ")");
        return false;
    }
    if (!origin_allowed(con->get_request_header("Origin"), con->get_request_header("Host"))) {
        refuse(con, status::forbidden, "Origin must be http://<Host>");
        return false;
    }
    return true;
}

void WebServer::Impl::serve_http(Handle h) {
    const Endpoint::connection_ptr con = endpoint.get_con_from_hdl(h);
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

void WebServer::Impl::on_open(Handle h) {
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
void WebServer::Impl::on_end(Handle h) {
    ConnectionId id = 0;
    {
        std::lock_guard lock(mutex);
        const auto it = ids.find(h);
        if (it == ids.end()) return;
        id = it->second;
        handles.erase(id);
        ids.erase(it);
    }
    changed.notify_all();
    callbacks.closed(id);
}

bool WebServer::Impl::find(ConnectionId id, Handle& h) {
    std::lock_guard lock(mutex);
    const auto it = handles.find(id);
    if (stopped || it == handles.end()) return false;
    h = it->second;
    return true;
}

WebServer::WebServer(WebOptions options, WebCallbacks callbacks) : impl_(std::make_unique<Impl>()) {
    impl_->options = std::move(options);
    impl_->callbacks = std::move(callbacks);
    Endpoint& e = impl_->endpoint;
    e.clear_access_channels(websocketpp::log::alevel::all);
    e.clear_error_channels(websocketpp::log::elevel::all);
    e.init_asio();
    e.set_reuse_addr(true);
    e.set_max_message_size(impl_->options.max_message_bytes);
    e.set_max_http_body_size(impl_->options.max_message_bytes);  // only GET is served
    impl_->install_handlers();
    websocketpp::lib::error_code ec;
    e.listen(impl_->options.address, std::to_string(impl_->options.port), ec);
    if (!ec) e.start_accept(ec);
    if (ec)
        throw std::runtime_error("cannot listen on " + impl_->options.address + ":" +
                                 std::to_string(impl_->options.port) + ": " + ec.message());
}

WebServer::~WebServer() {
    stop();
}

int WebServer::port() const {
    websocketpp::lib::asio::error_code ec;
    const auto local = impl_->endpoint.get_local_endpoint(ec);
    return ec ? -1 : local.port();
}

void WebServer::start() {
    impl_->thread = std::thread([this] { impl_->endpoint.run(); });
}

void WebServer::stop() {
    Impl& im = *impl_;
    {
        std::lock_guard lock(im.mutex);
        if (im.stopped) return;
        im.stopped = true;
    }
    im.changed.notify_all();
    if (im.thread.joinable()) {
        websocketpp::lib::asio::post(im.endpoint.get_io_service(), [&im] {
            websocketpp::lib::error_code ec;
            im.endpoint.stop_listening(ec);
            std::map<ConnectionId, Handle> open;
            {
                std::lock_guard lock(im.mutex);  // not held while closing: a handler may run
                open = im.handles;
            }
            for (const auto& entry : open)
                im.endpoint.close(entry.second, websocketpp::close::status::going_away,
                                  "server stops", ec);
        });
        std::unique_lock lock(im.mutex);
        im.changed.wait_for(lock, kCloseGrace, [&im] { return im.handles.empty(); });
        lock.unlock();
        im.endpoint.stop();
        im.thread.join();
    }
    std::map<ConnectionId, Handle> left;
    {
        std::lock_guard lock(im.mutex);
        left.swap(im.handles);
        im.ids.clear();
    }
    for (const auto& entry : left) im.callbacks.closed(entry.first);
}

bool WebServer::send(ConnectionId id, const void* bytes, std::size_t size,
                     const std::atomic<bool>* cancel) {
    Handle h;
    if (!impl_->find(id, h)) return false;
    websocketpp::lib::error_code ec;
    const Endpoint::connection_ptr con = impl_->endpoint.get_con_from_hdl(h, ec);
    if (ec) return false;
    {
        // Back-pressure: a slow reader holds at most max_buffered_bytes (plus one message) here.
        // get_buffered_amount() reads a size_t that the io thread updates; websocketpp takes no
        // lock for it either, and a stale value only delays the next look by kDrainPoll.
        std::unique_lock lock(impl_->mutex);
        while (con->get_buffered_amount() > impl_->options.max_buffered_bytes) {
            if (impl_->stopped || !impl_->handles.count(id) || (cancel && cancel->load()))
                return false;
            impl_->changed.wait_for(lock, kDrainPoll);
        }
    }
    return !con->send(bytes, size, websocketpp::frame::opcode::binary);
}

void WebServer::close(ConnectionId id, const std::string& reason) {
    Handle h;
    if (!impl_->find(id, h)) return;
    websocketpp::lib::error_code ec;
    impl_->endpoint.close(h, websocketpp::close::status::normal, reason, ec);
}

}  // namespace isowall::web
