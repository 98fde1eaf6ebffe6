#pragma once
// Shared by the tests of `isowall serve --http`: a ViewServer with its HTTP front end
// on loopback ports of their own, and a plain HTTP client (one request, read to EOF, under a
// timeout).
#include <map>
#include <string>

#include "remote/http/http_front.h"
#include "tests/remote_view_util.h"

namespace isowall::test {

struct HttpReply {
    int status = 0;
    std::map<std::string, std::string> headers;  // names in lower case
    std::string body;
};

// Sends `request_head` (request line and headers, without the blank line) to 127.0.0.1:port
// and reads the reply until the server closes or `timeout_s` passes.
HttpReply http_exchange(int port, const std::string& request_head, double timeout_s = 10);
inline HttpReply http_get(int port, const std::string& path) {
    return http_exchange(port, "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1:" +
                                   std::to_string(port) + "\r\nConnection: close");
}

// A TestServer (TCP) and its HttpFrontEnd on another free port.
class WebTestServer {
  public:
    explicit WebTestServer(remote::ServerOptions o = {})
        : tcp_(std::move(o)), http_(tcp_.server(), 0) {}
    int tcp_port() const { return tcp_.port(); }
    int http_port() const { return http_.port(); }
    remote::ViewServer& view_server() { return tcp_.server(); }

  private:
    TestServer tcp_;
    remote::HttpFrontEnd http_;
};

}  // namespace isowall::test
