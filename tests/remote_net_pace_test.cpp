// Connection's emulated link (set_rate): on a fake clock the waits add up to exactly what the rate
// asks; on the real clock a paced send takes at least as long (speed targets live in benchmarks);
// shutdown() cuts a paced wait short.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "remote/net/connection.h"
#include "tests/remote_protocol_test_util.h"

namespace isowall::remote {
namespace {

using namespace remote_testing;

constexpr double kPaceTimeoutS = 10;

struct Pair {
    std::unique_ptr<Connection> sender, receiver;
};

Pair connected_pair() {
    Listener listener = Listener::open("127.0.0.1", 0);
    Socket client = connect_tcp("127.0.0.1", listener.port(), kPaceTimeoutS);
    std::optional<Socket> server = listener.accept(kPaceTimeoutS);
    if (!server) throw NetError("accept timed out");
    return {std::make_unique<Connection>(std::move(*server), "client"),
            std::make_unique<Connection>(std::move(client), "server")};
}

GroupMsg group_of(std::size_t bytes) {
    GroupMsg m = sample_group();
    m.encoded.assign(bytes, std::byte{5});
    return m;
}

// Receives one message on another thread while `send` runs, so the sender never blocks on a full
// socket; returns whether it arrived.
template <class Send>
bool send_while_receiving(Pair& pair, Send send) {
    bool arrived = false;
    std::thread reader([&] {
        try {
            arrived = pair.receiver->receive(kPaceTimeoutS).has_value();
        } catch (const NetError&) {  // shut down after a failed send: reported by the caller
        }
    });
    try {
        send();
    } catch (...) {
        pair.receiver->shutdown();
        reader.join();
        throw;
    }
    reader.join();
    return arrived;
}

TEST(RemoteNetPace, FakeClockWaitsExactlyWhatTheRateAsks) {
    Pair pair = connected_pair();
    double now = 0, waited = 0;
    int waits = 0;
    pair.sender->set_pacing_clock({[&] { return now; },
                                   [&](double s) {
                                       now += s;
                                       waited += s;
                                       ++waits;
                                   }});
    pair.sender->set_rate(8e6, kPaceChunkBytes);  // 1e6 bytes/s
    const GroupMsg m = group_of(256 * 1024);
    std::size_t sent = 0;
    ASSERT_TRUE(send_while_receiving(pair, [&] { sent = pair.sender->send(m); }));
    // The first chunk goes on the full bucket; every later byte waits for its token.
    const double expected_s = static_cast<double>(sent - kPaceChunkBytes) / 1e6;
    EXPECT_NEAR(waited, expected_s, 1e-9 * expected_s + 1e-12);
    EXPECT_EQ(waits, static_cast<int>((sent + kPaceChunkBytes - 1) / kPaceChunkBytes) - 1)
        << "one wait per chunk after the first";
    EXPECT_EQ(pair.sender->bytes_sent(), sent);

    // The bucket is empty now: the next message waits for all of its bytes.
    const double before = waited;
    ASSERT_TRUE(send_while_receiving(pair, [&] { pair.sender->send(ByeMsg{}); }));
    EXPECT_NEAR(waited - before, static_cast<double>(kHeaderBytes + 1) / 1e6, 1e-12);
}

TEST(RemoteNetPace, UnlimitedByDefaultAndAfterRateZero) {
    Pair pair = connected_pair();
    int waits = 0;
    pair.sender->set_pacing_clock({[] { return 0.0; }, [&](double) { ++waits; }});
    ASSERT_TRUE(send_while_receiving(pair, [&] { pair.sender->send(group_of(100000)); }));
    pair.sender->set_rate(8000);
    pair.sender->set_rate(0);
    ASSERT_TRUE(send_while_receiving(pair, [&] { pair.sender->send(group_of(100000)); }));
    EXPECT_EQ(waits, 0);
    EXPECT_THROW(pair.sender->set_rate(-1), std::invalid_argument);
}

TEST(RemoteNetPace, RealClockTakesAtLeastWhatTheRateAsks) {
    Pair pair = connected_pair();
    pair.sender->set_rate(8e6);
    std::size_t sent = 0;
    const auto start = std::chrono::steady_clock::now();
    ASSERT_TRUE(
        send_while_receiving(pair, [&] { sent = pair.sender->send(group_of(256 * 1024)); }));
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double expected_s = static_cast<double>(sent - kPaceChunkBytes) / 1e6;  // ~0.25 s
    // The pacing waited on the real clock at least as the rate asks (a busy machine can only make
    // it slower; how exactly it waits is FakeClockWaitsExactlyWhatTheRateAsks's).
    EXPECT_GT(took, 0.7 * expected_s);
}

TEST(RemoteNetPace, ShutdownCutsAPacedWaitShort) {
    Pair pair = connected_pair();
    pair.sender->set_rate(8000);  // 1000 bytes/s: 256 KiB would take over four minutes
    std::string error;
    std::thread sender([&] {
        try {
            pair.sender->send(group_of(256 * 1024));
            error = "sent";
        } catch (const PeerClosed& e) {
            error = e.what();
        }
    });
    // The first chunk arrives (the bucket's burst); the rest waits on the rate, and the shutdown
    // must end that wait with an error, not let the send finish minutes later.
    ASSERT_TRUE(pair.receiver->socket().peek(kPaceTimeoutS, "sender").has_value())
        << "nothing was sent";
    pair.sender->shutdown();
    sender.join();
    EXPECT_NE(error.find("shut down"), std::string::npos) << error;
}

}  // namespace
}  // namespace isowall::remote
