// `isowall serve --http`: the protocol over WebSocket. A session gives the same frame
// as over TCP; a wrong token, a text message, a frame whose header disagrees with its message
// and one that does not decode each get an ErrorMsg and a close; max_clients counts both kinds.
#include <chrono>

#include <gtest/gtest.h>

#include "remote/net/connection.h"
#include "remote/view_framing.h"
#include "tests/remote_web_util.h"
#include "tests/ws_test_client.h"

namespace isowall::test {
namespace {

using namespace remote;

constexpr double kTimeoutS = 30;

void send_frame(WsTestClient& ws, const std::vector<std::byte>& frame) {
    ws.send_binary(frame.data(), frame.size());
}
void send_message(WsTestClient& ws, const RemoteMessage& m) {
    send_frame(ws, encode_frame(m));
}

// The next message, decoded (each WebSocket message must be exactly one frame).
RemoteMessage receive_message(WsTestClient& ws) {
    std::optional<WsMessage> m = ws.receive(kTimeoutS);
    if (!m) throw std::runtime_error("no message within the timeout");
    EXPECT_TRUE(m->binary) << "the server sent a text message";
    const auto* data = reinterpret_cast<const std::byte*>(m->bytes.data());
    return decode_frame(std::span<const std::byte>(data, m->bytes.size()));
}

HelloMsg hello(const std::string& token = {}) {
    HelloMsg h;
    h.dataset = "phantom";
    h.token = token;
    h.encoding = 3;
    return h;
}

RequestMsg request() {
    RequestMsg r;
    r.request_id = 1;
    r.view = phantom_view(200, 150, 30);
    return r;
}

// Sends one request and reads up to its end_of_frame, counting the groups on the way.
template <class Send, class Receive>
EndOfFrameMsg one_frame(Send send, Receive receive, std::uint64_t& groups) {
    send(hello());
    const RemoteMessage ready = receive();
    EXPECT_TRUE(std::holds_alternative<ReadyMsg>(ready)) << to_string(type_of(ready));
    send(request());
    for (;;) {
        const RemoteMessage m = receive();
        if (std::holds_alternative<GroupMsg>(m)) ++groups;
        if (const auto* e = std::get_if<EndOfFrameMsg>(&m)) return *e;
        if (std::holds_alternative<ErrorMsg>(m))
            throw std::runtime_error("error: " + std::get<ErrorMsg>(m).text);
    }
}

ErrorMsg expect_error_then_close(WsTestClient& ws) {
    const RemoteMessage m = receive_message(ws);
    const auto* e = std::get_if<ErrorMsg>(&m);
    EXPECT_TRUE(e) << "expected an error, got " << to_string(type_of(m));
    EXPECT_TRUE(ws.wait_closed(10)) << "the server did not close the WebSocket";
    return e ? *e : ErrorMsg{};
}

TEST(RemoteWebSocket, AFrameOverWebSocketEqualsTheSameFrameOverTcp) {
    WebTestServer server;
    std::uint64_t ws_groups = 0, tcp_groups = 0;
    WsTestClient ws(server.http_port());
    const EndOfFrameMsg over_ws = one_frame([&](const RemoteMessage& m) { send_message(ws, m); },
                                            [&] { return receive_message(ws); }, ws_groups);
    Connection tcp(connect_tcp("127.0.0.1", server.tcp_port(), 5), "server");
    const EndOfFrameMsg over_tcp = one_frame([&](const RemoteMessage& m) { tcp.send(m); },
                                             [&] {
                                                 auto m = tcp.receive(kTimeoutS);
                                                 if (!m) throw std::runtime_error("timeout");
                                                 return *m;
                                             },
                                             tcp_groups);
    EXPECT_GT(over_ws.triangles, 0u);
    EXPECT_EQ(over_ws.triangles, over_tcp.triangles);
    EXPECT_EQ(over_ws.groups, over_tcp.groups);
    EXPECT_EQ(over_ws.rays, over_tcp.rays);
    EXPECT_EQ(ws_groups, over_ws.groups);
    std::printf(
        "[ measured ] one frame of the phantom (200x150, yaw 30): %llu triangles, %llu "
        "groups over WebSocket; %llu triangles, %llu groups over TCP\n",
        static_cast<unsigned long long>(over_ws.triangles),
        static_cast<unsigned long long>(over_ws.groups),
        static_cast<unsigned long long>(over_tcp.triangles),
        static_cast<unsigned long long>(over_tcp.groups));
    send_message(ws, ByeMsg{});
    EXPECT_TRUE(ws.wait_closed(10));
}

TEST(RemoteWebSocket, AWrongTokenGetsBadToken) {
    ServerOptions o;
    o.token = "sesame";
    WebTestServer server(o);
    WsTestClient ws(server.http_port());
    send_message(ws, hello("sesam"));
    EXPECT_EQ(expect_error_then_close(ws).code, ErrorCode::bad_token);
    WsTestClient good(server.http_port());
    send_message(good, hello("sesame"));
    const RemoteMessage m = receive_message(good);
    EXPECT_TRUE(std::holds_alternative<ReadyMsg>(m)) << to_string(type_of(m));
}

TEST(RemoteWebSocket, ATextMessageGetsMalformedAndAClose) {
    WebTestServer server;
    WsTestClient ws(server.http_port());
    ws.send_text("hello");
    const ErrorMsg e = expect_error_then_close(ws);
    EXPECT_EQ(e.code, ErrorCode::malformed);
    EXPECT_NE(e.text.find("text message"), std::string::npos) << e.text;
}

TEST(RemoteWebSocket, AFrameWhoseLengthDisagreesGetsAnError) {
    WebTestServer server;
    std::vector<std::byte> longer = encode_frame(hello());
    longer.push_back(std::byte{0});  // a byte after the payload the header announces
    std::vector<std::byte> shorter = encode_frame(hello());
    shorter.pop_back();
    std::vector<std::byte> garbled = encode_frame(hello());
    garbled[0] = std::byte{'X'};
    for (const auto* frame : {&longer, &shorter, &garbled}) {
        WsTestClient ws(server.http_port());
        send_frame(ws, *frame);
        EXPECT_EQ(expect_error_then_close(ws).code, ErrorCode::malformed);
    }
    // A message over a header and the payload limit is refused by the WebSocket layer itself.
    {
        WsTestClient ws(server.http_port());
        const std::vector<std::byte> huge(kHeaderBytes + ServerOptions{}.max_payload_bytes + 1);
        send_frame(ws, huge);
        EXPECT_TRUE(ws.wait_closed(10)) << "a message over the limit was taken";
    }
    // The server goes on.
    WsTestClient ws(server.http_port());
    send_message(ws, hello());
    EXPECT_TRUE(std::holds_alternative<ReadyMsg>(receive_message(ws)));
}

// On a paced link (--rate-mbps) a request interrupts the one in progress over WebSocket as over
// TCP: no group of the old request follows the new one's first, and the frame takes at least
// its bytes at the link's rate.
TEST(RemoteWebSocket, ARequestInterruptsAPacedFrame) {
    ServerOptions o;
    o.rate_bits_per_s = 8e6;
    WebTestServer server(o);
    WsTestClient ws(server.http_port());
    send_message(ws, hello());
    ASSERT_TRUE(std::holds_alternative<ReadyMsg>(receive_message(ws)));
    RequestMsg first = request();
    // The second view is made before the first request goes: phantom_view builds the phantom,
    // which under the sanitizers takes longer than the whole paced frame.
    RequestMsg second = first;
    second.request_id = 2;
    second.view = phantom_view(200, 150, 90);
    send_message(ws, first);
    RemoteMessage m = receive_message(ws);
    ASSERT_TRUE(std::holds_alternative<GroupMsg>(m)) << to_string(type_of(m));
    const auto sent = std::chrono::steady_clock::now();
    send_message(ws, second);
    bool second_began = false;
    for (;;) {
        m = receive_message(ws);
        if (const auto* g = std::get_if<GroupMsg>(&m)) {
            if (g->request_id == 2) second_began = true;
            EXPECT_FALSE(second_began && g->request_id == 1) << "a group of the old request";
        }
        if (const auto* e = std::get_if<EndOfFrameMsg>(&m)) {
            EXPECT_EQ(e->request_id, 2u) << "the interrupted frame was ended";
            const double took_s =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
            const double link_s = double(e->bytes) * 8 / o.rate_bits_per_s;
            EXPECT_GE(took_s, 0.8 * link_s - 0.05) << e->bytes << " bytes";
            std::printf(
                "[ measured ] paced WebSocket frame: %llu bytes in %.2f s (%.2f s at "
                "8 Mbit/s)\n",
                static_cast<unsigned long long>(e->bytes), took_s, link_s);
            break;
        }
    }
    EXPECT_TRUE(second_began);
}

TEST(RemoteWebSocket, MaxClientsCountsBothKinds) {
    ServerOptions o;
    o.max_clients = 1;
    WebTestServer server(o);
    Connection tcp(connect_tcp("127.0.0.1", server.tcp_port(), 5), "server");
    tcp.send(hello());
    auto ready = tcp.receive(kTimeoutS);
    ASSERT_TRUE(ready && std::holds_alternative<ReadyMsg>(*ready));
    // The TCP client, idle, gives the one seat to the WebSocket's.
    WsTestClient ws(server.http_port());
    send_message(ws, hello());
    EXPECT_TRUE(std::holds_alternative<ReadyMsg>(receive_message(ws)));
    const std::optional<RemoteMessage> m = tcp.receive(kTimeoutS);
    ASSERT_TRUE(m && std::holds_alternative<ErrorMsg>(*m));
    EXPECT_NE(std::get<ErrorMsg>(*m).text.find("--max-clients"), std::string::npos);
}

}  // namespace
}  // namespace isowall::test
