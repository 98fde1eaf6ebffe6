#pragma once
// A WebSocket client written out by hand (RFC 6455) for the tests of `serve --http` that need
// what a library client hides: a flood of pings in one send, a client that stops reading, frames
// read one at a time with their opcodes. C++20 and no websocketpp (ws_test_client.h is the
// library client). Every wait has a timeout, so a test fails instead of hanging.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "remote/net/socket.h"
#include "remote/view_protocol.h"

namespace isowall::test {

namespace ws_opcode {
inline constexpr std::uint8_t kText = 1, kBinary = 2, kClose = 8, kPing = 9, kPong = 10;
}

struct RawWsFrame {
    std::uint8_t opcode = 0;
    std::string payload;
};

class RawWs {
  public:
    // Connects to 127.0.0.1:port and upgrades /ws; throws std::runtime_error unless the server
    // answers 101 within `timeout_s`.
    explicit RawWs(int port, double timeout_s = 10);

    // One client frame (FIN set, masked as the RFC requires of a client).
    static std::vector<std::byte> frame(std::uint8_t opcode, std::span<const std::byte> payload);
    static std::vector<std::byte> frame(std::uint8_t opcode, const std::string& payload);
    // Sends bytes as they are (frames built with frame(), many in one buffer for a flood).
    void send_raw(std::span<const std::byte> bytes);
    void send_message(const remote::RemoteMessage& m);  // one protocol frame, one binary message

    // The next frame within `timeout_s`, nullopt when none completed in time. Throws
    // remote::PeerClosed once the server closed the TCP connection and no whole frame is left.
    std::optional<RawWsFrame> receive(double timeout_s);
    // The next protocol message, passing over pongs; throws std::runtime_error on a timeout, a
    // close frame or a text message.
    remote::RemoteMessage receive_message(double timeout_s);
    // Whether the server ends the connection (a close frame or EOF) within `timeout_s`; frames
    // before it are dropped. *close_code, when given, receives the close frame's code (0: none).
    bool wait_closed(double timeout_s, int* close_code = nullptr);

    remote::Socket& socket() { return socket_; }

  private:
    std::optional<RawWsFrame> parse();

    remote::Socket socket_;
    std::string buffer_;  // bytes received and not yet parsed
};

}  // namespace isowall::test
