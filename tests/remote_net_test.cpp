// remote/net/ on loopback: a Listener on an ephemeral port, connect_tcp and Connection carry every
// message whole (also when the bytes come one at a time); timeouts, a peer that leaves (between
// or inside a message), a broken stream, shutdown() and failing connects and binds each end the
// way the header says, quickly. Every blocking call has a timeout, so no failure hangs the test.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "remote/net/connection.h"
#include "remote/net/tcp_progress.h"
#include "tests/remote_protocol_test_util.h"

namespace isowall::remote {
namespace {

using namespace remote_testing;
using Bytes = std::vector<std::byte>;
using Seconds = std::chrono::duration<double>;

constexpr double kTimeout_s = 10;  // a generous bound on anything that should take milliseconds

double seconds_since(std::chrono::steady_clock::time_point start) {
    return Seconds(std::chrono::steady_clock::now() - start).count();
}

// Two ends of one loopback connection: `client` from connect_tcp, `server` from accept.
struct Loopback {
    Listener listener = Listener::open("127.0.0.1", 0);
    Socket client;
    Socket server;
    std::string server_peer;  // the client as the server sees it

    Loopback() {
        client = connect_tcp("127.0.0.1", listener.port(), kTimeout_s);
        auto s = listener.accept(kTimeout_s, &server_peer);
        if (!s) throw NetError("accept timed out");
        server = std::move(*s);
    }
    std::unique_ptr<Connection> server_connection() {
        return std::make_unique<Connection>(std::move(server), server_peer);
    }
    std::unique_ptr<Connection> client_connection() {
        return std::make_unique<Connection>(std::move(client), "server");
    }
};

TEST(RemoteNet, ListenerTakesAnEphemeralPortAndNamesThePeer) {
    Loopback link;
    EXPECT_GT(link.listener.port(), 0);
    EXPECT_EQ(link.listener.address(), "127.0.0.1");
    EXPECT_EQ(link.server_peer.rfind("127.0.0.1:", 0), 0u) << link.server_peer;
}

TEST(RemoteNet, TcpProgressCountsWhatThePeerTook) {
    Loopback lo;
    const std::optional<TcpProgress> before = tcp_progress(lo.server.native_handle());
    ASSERT_TRUE(before.has_value());
    EXPECT_TRUE(before->same_host);  // 127.0.0.1: no link between
    const Bytes bytes(100000, std::byte{7});
    send_all(lo.server, bytes, "client");
    // The peer's host acknowledges what its socket took, read or not (its buffer holds 100 KB).
    std::optional<TcpProgress> after;
    const auto start = std::chrono::steady_clock::now();
    do {
        after = tcp_progress(lo.server.native_handle());
        ASSERT_TRUE(after.has_value());
    } while (after->acked < before->acked + bytes.size() && seconds_since(start) < kTimeout_s);
    EXPECT_EQ(after->acked, before->acked + bytes.size());
    EXPECT_EQ(after->unacked, 0u);
    EXPECT_FALSE(tcp_progress(-1).has_value());
}

TEST(RemoteNet, ConnectsByName) {
    Listener l = Listener::open("127.0.0.1", 0);
    // "localhost" may name ::1 first, where nothing listens: connect_tcp tries each address.
    Socket s = connect_tcp("localhost", l.port(), kTimeout_s);
    EXPECT_TRUE(s.valid());
    EXPECT_TRUE(l.accept(kTimeout_s));
}

TEST(RemoteNet, EveryMessageRoundTripsBothWays) {
    Loopback link;
    auto server = link.server_connection();
    auto client = link.client_connection();
    std::uint64_t frame_bytes = 0;
    for (const RemoteMessage& m : samples()) {
        SCOPED_TRACE(to_string(type_of(m)));
        const std::size_t sent = client->send(m);
        EXPECT_EQ(sent, encode_frame(m).size());
        frame_bytes += sent;
        const auto got = server->receive(kTimeout_s);
        ASSERT_TRUE(got);
        EXPECT_EQ(*got, m);
        server->send(*got);
        const auto back = client->receive(kTimeout_s);
        ASSERT_TRUE(back);
        EXPECT_EQ(*back, m);
    }
    EXPECT_EQ(client->bytes_sent(), frame_bytes);
    EXPECT_EQ(server->bytes_received(), frame_bytes);
    EXPECT_EQ(server->bytes_sent(), frame_bytes);
    EXPECT_EQ(client->bytes_received(), frame_bytes);
}

TEST(RemoteNet, BytesOneAtATimeStillMakeWholeMessages) {
    Loopback link;
    auto server = link.server_connection();
    for (const RemoteMessage& m : {RemoteMessage(sample_hello()), RemoteMessage(sample_group())}) {
        const Bytes frame = encode_frame(m);
        for (std::size_t i = 0; i + 1 < frame.size(); ++i) {
            send_all(link.client, std::span(frame).subspan(i, 1), "test client");
            ASSERT_FALSE(server->receive(0)) << "a message before its byte " << i + 1;
        }
        send_all(link.client, std::span(frame).last(1), "test client");
        const auto got = server->receive(kTimeout_s);
        ASSERT_TRUE(got) << to_string(type_of(m));
        EXPECT_EQ(*got, m);
    }
}

TEST(RemoteNet, ALargeMessageInSmallChunksFromAnotherThread) {
    Loopback link;
    auto server = link.server_connection();
    GroupMsg big = sample_group();
    big.encoded.assign(300 * 1024, std::byte{7});
    big.encoded[12345] = std::byte{1};
    const Bytes frame = encode_frame(big);
    std::thread sender([&] {
        try {
            for (std::size_t i = 0; i < frame.size(); i += 1000)
                send_all(link.client,
                         std::span(frame).subspan(i, std::min<std::size_t>(1000, frame.size() - i)),
                         "test client");
        } catch (const NetError&) {  // the receiver gave up: its failure is reported below
        }
    });
    const auto got = server->receive(kTimeout_s);
    if (!got) link.client.shutdown_both();  // so that the sender cannot block forever
    sender.join();
    ASSERT_TRUE(got);
    EXPECT_EQ(*got, RemoteMessage(big));
}

TEST(RemoteNet, ReceiveTimesOutQuickly) {
    Loopback link;
    auto server = link.server_connection();
    const auto start = std::chrono::steady_clock::now();
    EXPECT_FALSE(server->receive(0.05));
    const double took = seconds_since(start);
    EXPECT_GE(took, 0.04);
    EXPECT_LT(took, 2.0);
    EXPECT_FALSE(server->receive(0));
}

TEST(RemoteNet, PeerClosingBetweenMessagesIsPeerClosed) {
    Loopback link;
    auto server = link.server_connection();
    send_all(link.client, encode_frame(ByeMsg{}), "test client");
    link.client.close();
    ASSERT_TRUE(server->receive(kTimeout_s));
    try {
        server->receive(kTimeout_s);
        ADD_FAILURE() << "no PeerClosed";
    } catch (const PeerClosed& e) {
        EXPECT_NE(std::string(e.what()).find(link.server_peer), std::string::npos) << e.what();
    }
}

TEST(RemoteNet, PeerClosingInsideAMessageSaysTheStreamWasCutShort) {
    Loopback link;
    auto server = link.server_connection();
    const Bytes frame = encode_frame(sample_hello());
    send_all(link.client, std::span(frame).first(frame.size() - 3), "test client");
    link.client.close();
    try {
        server->receive(kTimeout_s);
        ADD_FAILURE() << "no PeerClosed";
    } catch (const PeerClosed& e) {
        EXPECT_NE(std::string(e.what()).find("cut short inside a message"), std::string::npos)
            << e.what();
    }
}

TEST(RemoteNet, BadMagicBreaksTheStream) {
    Loopback link;
    auto server = link.server_connection();
    Bytes frame = encode_frame(ByeMsg{});
    frame[0] = std::byte{'X'};
    send_all(link.client, frame, "test client");
    EXPECT_THROW(server->receive(kTimeout_s), WireError);
    EXPECT_THROW(server->receive(0), WireError) << "a broken stream stays broken";
}

TEST(RemoteNet, ShutdownWakesABlockedReceive) {
    Loopback link;
    auto server = link.server_connection();
    std::string error;
    const auto start = std::chrono::steady_clock::now();
    std::thread reader([&] {
        try {
            server->receive(kTimeout_s);
            error = "returned";
        } catch (const PeerClosed& e) {
            error = e.what();
        }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    server->shutdown();
    reader.join();
    EXPECT_LT(seconds_since(start), kTimeout_s / 2) << "woken, not timed out";
    EXPECT_NE(error.find("shut down"), std::string::npos) << error;
    EXPECT_THROW(server->send(ByeMsg{}), PeerClosed);
}

TEST(RemoteNet, ConnectToAClosedPortNamesIt) {
    int port = 0;
    {
        Listener gone = Listener::open("127.0.0.1", 0);
        port = gone.port();
    }
    const auto start = std::chrono::steady_clock::now();
    try {
        connect_tcp("127.0.0.1", port, kTimeout_s);
        ADD_FAILURE() << "connected to a closed port";
    } catch (const NetError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind("127.0.0.1:" + std::to_string(port) + ": connect: ", 0), 0u) << what;
    }
    EXPECT_LT(seconds_since(start), kTimeout_s / 2);
}

TEST(RemoteNet, ListeningOnAPortInUseNamesIt) {
    Listener first = Listener::open("127.0.0.1", 0);
    try {
        Listener::open("127.0.0.1", first.port());
        ADD_FAILURE() << "bound a port in use";
    } catch (const NetError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind("127.0.0.1:" + std::to_string(first.port()) + ": bind: ", 0), 0u)
            << what;
        EXPECT_NE(what.find("in use"), std::string::npos) << what;
    }
}

TEST(RemoteNet, AcceptTimesOutAndBadAddressesAreNetErrors) {
    Listener l = Listener::open("127.0.0.1", 0);
    EXPECT_FALSE(l.accept(0.02));
    EXPECT_THROW(Listener::open("not an address", 0), NetError);
    EXPECT_THROW(connect_tcp("127.0.0.1", 0, kTimeout_s), NetError);
    EXPECT_THROW(connect_tcp("127.0.0.1", 65536, kTimeout_s), NetError);
    EXPECT_THROW(Listener::open("127.0.0.1", -1), NetError);
}

TEST(RemoteNet, ConcurrentSendersNeverInterleaveFrames) {
    Loopback link;
    auto server = link.server_connection();
    auto client = link.client_connection();
    constexpr int kEach = 200;
    GroupMsg big = sample_group();
    big.encoded.assign(20000, std::byte{3});
    const auto send_many = [&](const RemoteMessage& m) {
        try {
            for (int i = 0; i < kEach; ++i) client->send(m);
        } catch (const NetError&) {  // shut down below after a failure: reported there
        }
    };
    std::thread a(send_many, RemoteMessage(big));
    std::thread b(send_many, RemoteMessage(sample_error()));
    int groups = 0, errors = 0;
    try {
        for (int i = 0; i < 2 * kEach; ++i) {
            const auto m = server->receive(kTimeout_s);
            if (!m) break;
            if (*m == RemoteMessage(big)) ++groups;
            if (*m == RemoteMessage(sample_error())) ++errors;
        }
    } catch (const std::exception& e) {
        ADD_FAILURE() << e.what();
    }
    client->shutdown();  // a sender left blocked by a failure above wakes
    a.join();
    b.join();
    EXPECT_EQ(groups, kEach);
    EXPECT_EQ(errors, kEach);
}

// A receive that runs out of time leaves its read pending on the net thread: what arrives after
// it goes to the next receive, whole and in order. A peek shows bytes without taking them.
TEST(RemoteNet, ATimedOutReceiveLosesNoByteAndAPeekTakesNone) {
    Loopback link;
    std::array<std::byte, 16> buf{};
    std::size_t got = 99;
    EXPECT_FALSE(recv_some(link.server, buf, 0, got, "client"));
    EXPECT_EQ(got, 0u);
    const Bytes first = {std::byte{1}, std::byte{2}, std::byte{3}};
    send_all(link.client, first, "server");
    const std::optional<Bytes> peeked = link.server.peek(kTimeout_s, "client");
    ASSERT_TRUE(peeked.has_value());
    ASSERT_FALSE(peeked->empty());
    EXPECT_EQ(peeked->front(), std::byte{1});
    const Bytes second = {std::byte{4}, std::byte{5}};
    send_all(link.client, second, "server");
    Bytes all;
    while (all.size() < first.size() + second.size()) {
        ASSERT_TRUE(recv_some(link.server, std::span(buf).first(2), kTimeout_s, got, "client"));
        all.insert(all.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(got));
    }
    EXPECT_EQ(all, (Bytes{std::byte{1}, std::byte{2}, std::byte{3}, std::byte{4}, std::byte{5}}));
}

// A send the peer never reads fills the sockets' buffers and waits; a shutdown from another
// thread ends it with PeerClosed, and so every later send.
TEST(RemoteNet, ShutdownWakesASendThePeerNeverReads) {
    Loopback link;
    const std::optional<TcpProgress> before = tcp_progress(link.client.native_handle());
    ASSERT_TRUE(before.has_value());
    const Bytes huge(64u << 20, std::byte{9});  // far more than loopback's buffers hold
    std::string error;
    std::thread sender([&] {
        try {
            send_all(link.client, huge, "server");
            error = "returned";
        } catch (const PeerClosed& e) {
            error = e.what();
        }
    });
    // The send has begun: the kernel holds some of its bytes (acknowledged or not).
    for (;;) {
        const std::optional<TcpProgress> now = tcp_progress(link.client.native_handle());
        ASSERT_TRUE(now.has_value());
        if (now->acked + now->unacked > before->acked + before->unacked) break;
        std::this_thread::yield();
    }
    link.client.shutdown_both();
    sender.join();
    EXPECT_NE(error, "returned");
    EXPECT_NE(error.find("shut down"), std::string::npos) << error;
    EXPECT_THROW(send_all(link.client, Bytes(1), "server"), PeerClosed);
}

}  // namespace
}  // namespace isowall::remote
