#pragma once
// `isowall serve --http PORT`: the page and the protocol over WebSocket, beside a
// ViewServer's TCP listener at the same address. HTTP requests go to web_routes.h; each
// WebSocket on /ws becomes a WebChannel the ViewServer serves like a TCP connection (its hello,
// token, worker and interrupts; max_clients counts both kinds).
#include <map>
#include <memory>
#include <mutex>

#include "remote/http/web_channel.h"
#include "remote/http/web_server.h"
#include "remote/view_server.h"

namespace isowall::remote {

class HttpFrontEnd {
  public:
    // Listens at once on the server's --listen address and `port` (0: any free port) and starts
    // the io thread, over TLS when the server has a context (https and wss). Throws InputError
    // naming --http when it cannot listen (a port in use), or --listen when the address is not
    // loopback and the server has no token or no TLS.
    HttpFrontEnd(ViewServer& server, int port);
    // Stops the io thread and ends every WebSocket; destroy it before the ViewServer.
    ~HttpFrontEnd();
    HttpFrontEnd(const HttpFrontEnd&) = delete;
    HttpFrontEnd& operator=(const HttpFrontEnd&) = delete;

    int port() const { return web_->port(); }

  private:
    void opened(web::ConnectionId id, const std::string& peer);
    void message(web::ConnectionId id, std::string bytes, bool binary);
    void closed(web::ConnectionId id);

    ViewServer& server_;
    std::shared_ptr<web::WebServer> web_;  // shared with the channels, which may outlive this
    std::mutex mutex_;
    std::map<web::ConnectionId, std::shared_ptr<WebInbox>> inboxes_;
};

}  // namespace isowall::remote
