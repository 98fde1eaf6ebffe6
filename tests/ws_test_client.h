#pragma once
// A WebSocket client for tests of `isowall serve --http` (websocketpp, like the server). C++17:
// ws_test_client.cpp is built as C++17 in isowall_test_ws, and this header includes neither
// websocketpp nor asio. Every wait has a timeout, so a test fails instead of hanging.
#include <memory>
#include <optional>
#include <string>

namespace isowall::test {

struct WsMessage {
    std::string bytes;
    bool binary = true;
};

class WsTestClient {
  public:
    // Opens ws://127.0.0.1:PORT/ws within `timeout_s`, sending `origin` as the Origin header when
    // it is not empty; throws std::runtime_error when the handshake fails or times out.
    explicit WsTestClient(int port, double timeout_s = 10, const std::string& origin = {});
    ~WsTestClient();
    WsTestClient(const WsTestClient&) = delete;
    WsTestClient& operator=(const WsTestClient&) = delete;

    void send_binary(const void* bytes, std::size_t size);
    void send_text(const std::string& text);
    // The next message within `timeout_s`; nullopt on a timeout, or once the server closed and
    // every message before the close was taken.
    std::optional<WsMessage> receive(double timeout_s);
    // Whether the connection has closed (either side) within `timeout_s`.
    bool wait_closed(double timeout_s);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace isowall::test
