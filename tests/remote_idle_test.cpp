// Who holds the server's seats (--max-clients): a connection on which nothing moves for the idle
// limit (--idle-timeout) gets an error naming it and a close, as does one that stops reading what
// it asked for; when every seat is taken the client idle the longest yields to a newcomer (a
// shared session's do not); connections that never say their hello hold no seat.
#include <array>
#include <chrono>
#include <thread>

#include <sys/socket.h>

#include <gtest/gtest.h>

#include "remote/net/connection.h"
#include "tests/remote_view_util.h"

namespace isowall::test {
namespace {

using namespace remote;
using Clock = std::chrono::steady_clock;

constexpr double kTimeoutS = 30;

std::unique_ptr<Connection> said_hello(int port) {
    auto c = std::make_unique<Connection>(connect_tcp("127.0.0.1", port, 5), "server");
    c->send(phantom_hello());
    return c;
}

double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// The server's error, then its close.
ErrorMsg expect_error_then_close(Connection& c) {
    std::optional<RemoteMessage> m = c.receive(kTimeoutS);
    if (!m) throw std::runtime_error("no error within the timeout");
    const auto* e = std::get_if<ErrorMsg>(&*m);
    if (!e)
        throw std::runtime_error("expected an error, got " + std::string(to_string(type_of(*m))));
    EXPECT_THROW(c.receive(kTimeoutS), PeerClosed) << "the connection stayed open";
    return *e;
}

// Until the server takes a new client (it reaps closed ones every 100 ms): its ready.
bool gets_in(int port, double timeout_s) {
    const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
    while (Clock::now() < end) {
        Connection c(connect_tcp("127.0.0.1", port, 5), "server");
        c.send(phantom_hello());
        const std::optional<RemoteMessage> m = c.receive(kTimeoutS);
        if (m && std::holds_alternative<ReadyMsg>(*m)) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
}

TEST(RemoteIdle, EightSilentClientsAreDroppedAtTheLimit) {
    ServerOptions o;
    o.max_clients = 8;
    o.idle_timeout_s = 1;
    TestServer server(o);
    std::vector<std::unique_ptr<Connection>> silent;
    for (int i = 0; i < o.max_clients; ++i) {
        silent.push_back(said_hello(server.port()));
        const std::optional<RemoteMessage> m = silent.back()->receive(kTimeoutS);
        ASSERT_TRUE(m && std::holds_alternative<ReadyMsg>(*m)) << "client " << i;
    }
    for (auto& c : silent) {
        const ErrorMsg e = expect_error_then_close(*c);
        EXPECT_EQ(e.code, ErrorCode::malformed);
        EXPECT_NE(e.text.find("idle for 1 s"), std::string::npos) << e.text;
        EXPECT_NE(e.text.find("--idle-timeout"), std::string::npos) << e.text;
    }
    EXPECT_TRUE(gets_in(server.port(), kTimeoutS)) << "the ninth client was still refused";
}

// Every seat taken by clients between frames: a newcomer gets in at once, and the client idle the
// longest gives its seat up, told why; the next newcomer takes the seat of the next idlest.
TEST(RemoteIdle, WhenEverySeatIsTakenTheLongestIdleClientYields) {
    ServerOptions o;
    o.max_clients = 2;
    TestServer server(o);
    std::vector<std::unique_ptr<Connection>> clients;
    const auto enter = [&] {
        clients.push_back(said_hello(server.port()));
        const std::optional<RemoteMessage> m = clients.back()->receive(kTimeoutS);
        return m && std::holds_alternative<ReadyMsg>(*m);
    };
    ASSERT_TRUE(enter());
    ASSERT_TRUE(enter());
    ASSERT_TRUE(enter()) << "the third client was not let in";
    const ErrorMsg first = expect_error_then_close(*clients[0]);
    EXPECT_NE(first.text.find("--max-clients"), std::string::npos) << first.text;
    EXPECT_NE(first.text.find("idle the longest"), std::string::npos) << first.text;
    ASSERT_TRUE(enter()) << "the fourth client was not let in";
    const ErrorMsg second = expect_error_then_close(*clients[1]);
    EXPECT_NE(second.text.find("idle the longest"), std::string::npos) << second.text;
}

// A presenter of a shared session does not give its seat up: the newcomer hears the server is
// busy.
TEST(RemoteIdle, AClientInASharedSessionKeepsItsSeatAndTheNewcomerIsBusy) {
    ServerOptions o;
    o.max_clients = 1;
    TestServer server(o);
    Connection presenter(connect_tcp("127.0.0.1", server.port(), 5), "server");
    HelloMsg h = phantom_hello();
    h.role = SessionRole::presenter;
    h.session = "class";
    presenter.send(h);
    bool ready = false;
    while (!ready) {
        const std::optional<RemoteMessage> m = presenter.receive(kTimeoutS);
        ASSERT_TRUE(m) << "the presenter heard nothing";
        ASSERT_FALSE(std::holds_alternative<ErrorMsg>(*m)) << std::get<ErrorMsg>(*m).text;
        ready = std::holds_alternative<ReadyMsg>(*m);
    }
    const std::unique_ptr<Connection> newcomer = said_hello(server.port());
    const ErrorMsg e = expect_error_then_close(*newcomer);
    EXPECT_NE(e.text.find("busy"), std::string::npos) << e.text;
    EXPECT_NE(e.text.find("--max-clients"), std::string::npos) << e.text;
}

// Connections that never say their hello (half-open handshakes) hold no seat, and past
// max_before_hello the oldest of them is closed: a client with its hello gets in at once.
TEST(RemoteIdle, ConnectionsWithoutAHelloLockNoOneOut) {
    ServerOptions o;
    o.max_clients = 1;
    o.max_before_hello = 4;
    o.hello_timeout_s = 300;  // only the bound can free them in this test
    TestServer server(o);
    std::vector<Socket> mute;
    for (int i = 0; i < 8; ++i) mute.push_back(connect_tcp("127.0.0.1", server.port(), 5));
    ASSERT_TRUE(gets_in(server.port(), kTimeoutS)) << "a client with its hello was locked out";
    // The oldest four were closed to make way.
    std::array<std::byte, 16> buf{};
    std::size_t got = 0;
    for (int i = 0; i < 4; ++i)
        EXPECT_THROW(recv_some(mute[static_cast<std::size_t>(i)], buf, kTimeoutS, got, "server"),
                     PeerClosed)
            << "connection " << i;
}

// The variant: a client that asks for a large frame and never reads it. The server's sends stop
// (its socket buffers are full), nothing moves, and the limit frees its slot.
TEST(RemoteIdle, AClientThatStopsReadingIsDroppedAndTheNextGetsIn) {
    ServerOptions o;
    o.max_clients = 1;
    o.idle_timeout_s = 1;
    TestServer server(o);
    Socket s = connect_tcp("127.0.0.1", server.port(), 5);
    const int small = 4096;
    ::setsockopt(s.native_handle(), SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    Connection deaf(std::move(s), "server");
    deaf.send(phantom_hello(0));  // triangles as separate vertices: the largest frame
    const std::optional<RemoteMessage> ready = deaf.receive(kTimeoutS);
    ASSERT_TRUE(ready && std::holds_alternative<ReadyMsg>(*ready));
    RequestMsg r;
    r.request_id = 1;
    r.view = phantom_view(1600, 1200, 30);
    deaf.send(r);
    EXPECT_TRUE(gets_in(server.port(), kTimeoutS)) << "a client that stopped reading kept its slot";
}

// Activity resets the clock: a client that keeps asking for frames for longer than the limit is
// never dropped.
TEST(RemoteIdle, AClientThatKeepsAskingIsNotDropped) {
    ServerOptions o;
    o.idle_timeout_s = 2;
    TestServer server(o);
    phantom_view(64, 48, 0);  // builds the phantom for its bounds before the clock runs
    const std::unique_ptr<Connection> client = said_hello(server.port());
    Connection& c = *client;
    const std::optional<RemoteMessage> ready = c.receive(kTimeoutS);
    ASSERT_TRUE(ready && std::holds_alternative<ReadyMsg>(*ready));
    const auto start = Clock::now();
    std::uint64_t id = 0, done = 0;
    while (seconds_since(start) < 1.5 * o.idle_timeout_s) {
        RequestMsg r;
        r.request_id = ++id;
        r.view = phantom_view(64, 48, double(id));
        c.send(r);
        for (;;) {
            const std::optional<RemoteMessage> m = c.receive(kTimeoutS);
            ASSERT_TRUE(m) << "no reply within the timeout";
            ASSERT_FALSE(std::holds_alternative<ErrorMsg>(*m)) << std::get<ErrorMsg>(*m).text;
            if (std::holds_alternative<EndOfFrameMsg>(*m)) break;
        }
        ++done;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    EXPECT_GT(done, 1u);
}

// The server's own work is not the client's silence: a frame about as long as the limit
// (1600x1200, about 1 s alone, against 1 s; longer on a loaded machine and under the sanitizers)
// ends whole. The limit stays well above one send, which counts whole as idle time while the
// client drains it.
TEST(RemoteIdle, AFrameLongerThanTheLimitIsNotIdleness) {
    ServerOptions o;
    o.idle_timeout_s = 1.0;
    TestServer server(o);
    RequestMsg r;
    r.request_id = 1;
    r.view = phantom_view(1600, 1200, 0);  // before the hello: the client's own work is silence
    const std::unique_ptr<Connection> client = said_hello(server.port());
    Connection& c = *client;
    const std::optional<RemoteMessage> ready = c.receive(kTimeoutS);
    ASSERT_TRUE(ready && std::holds_alternative<ReadyMsg>(*ready));
    c.send(r);
    const auto start = Clock::now();
    for (;;) {
        const std::optional<RemoteMessage> m = c.receive(kTimeoutS);
        ASSERT_TRUE(m) << "no reply within the timeout";
        ASSERT_FALSE(std::holds_alternative<ErrorMsg>(*m)) << std::get<ErrorMsg>(*m).text;
        if (std::holds_alternative<EndOfFrameMsg>(*m)) break;
    }
    std::printf("a 1600x1200 frame in %.2f s against an idle limit of 1 s\n", seconds_since(start));
}

}  // namespace
}  // namespace isowall::test
