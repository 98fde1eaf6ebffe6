#include "remote/http/http_front.h"

#include "core/error.h"
#include "remote/http/web_routes.h"
#include "remote/view_framing.h"

namespace isowall::remote {

HttpFrontEnd::HttpFrontEnd(ViewServer& server, int port) : server_(server) {
    const ServerOptions& so = server.options();
    if (std::string p = exposure_problem(so, "serving the page"); !p.empty())
        throw InputError("--listen", "address", p);
    web::WebOptions wo;
    if (so.tls) wo.tls = so.tls->native();
    wo.address = so.address;
    wo.host_names = served_host_names(so);
    wo.port = port;
    wo.max_message_bytes = kHeaderBytes + so.max_payload_bytes;
    // The cap on a connection's queue: the back-pressure limit and the largest message a session
    // sends on top, so that only a queue grown some other way reaches it.
    wo.max_queued_bytes = wo.max_buffered_bytes + kHeaderBytes + kMaxGroupBytes + (1 << 20);
    web::WebCallbacks cb;
    RouteContext context{server.dataset_names(), so.token, web_assets()};
    cb.http = [context](const web::HttpRequest& r) { return route(r, context); };
    cb.opened = [this](web::ConnectionId id, const std::string& peer) { opened(id, peer); };
    cb.message = [this](web::ConnectionId id, std::string bytes, bool binary) {
        message(id, std::move(bytes), binary);
    };
    cb.closed = [this](web::ConnectionId id) { closed(id); };
    try {
        web_ = std::make_shared<web::WebServer>(wo, std::move(cb));
    } catch (const std::exception& e) {
        throw InputError("--http", "port", e.what());
    }
    web_->start();
}

HttpFrontEnd::~HttpFrontEnd() {
    web_->stop();  // every inbox closes (closed() runs for each), so each channel's reader ends
}

void HttpFrontEnd::opened(web::ConnectionId id, const std::string& peer) {
    auto inbox = std::make_shared<WebInbox>();
    {
        std::lock_guard lock(mutex_);
        inboxes_[id] = inbox;
    }
    server_.adopt(std::make_unique<WebChannel>(web_, id, "ws " + peer, inbox,
                                               server_.options().max_payload_bytes));
}

void HttpFrontEnd::message(web::ConnectionId id, std::string bytes, bool binary) {
    std::lock_guard lock(mutex_);
    const auto it = inboxes_.find(id);
    if (it != inboxes_.end()) it->second->push(std::move(bytes), binary);
}

void HttpFrontEnd::closed(web::ConnectionId id) {
    std::lock_guard lock(mutex_);
    const auto it = inboxes_.find(id);
    if (it == inboxes_.end()) return;
    it->second->close();
    inboxes_.erase(it);
}

}  // namespace isowall::remote
