// Class 3 of "Nothing lies, nothing hangs, round two": a WebSocket ping flood grew `serve --http`
// without bound (248 MB -> 1.23 GB in 5 s, while the client read every pong), as every ping
// queued a pong faster than they went out. Now a connection holds at most one pong waiting (a
// newer ping replaces it, as RFC 6455 5.5.3 allows) and its outgoing queue has a byte cap beyond
// which it is closed (1008). Also the idle limit over WebSocket (class 4).
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "core/util.h"
#include "tests/remote_raw_ws.h"
#include "tests/remote_rss_util.h"
#include "tests/remote_web_util.h"

namespace isowall::test {
namespace {

using namespace remote;
using Clock = std::chrono::steady_clock;

constexpr double kFloodTimeoutS = 30;
// A flood: this many pings per send, until kFloodPings or kFloodSeconds, whichever comes first.
constexpr int kPingsPerSend = 4096;
constexpr long kFloodPings = 1 << 20;
constexpr double kFloodSeconds = 3;
// What the process may grow by during a flood of a million pings: 0.2 MiB measured, 133 MiB
// before the fix (130 bytes a ping, for as long as a flood lasts).
constexpr double kMaxGrowthMiB = 48;

void expect_ready(RawWs& ws) {
    const RemoteMessage m = ws.receive_message(kFloodTimeoutS);
    ASSERT_TRUE(std::holds_alternative<ReadyMsg>(m)) << to_string(type_of(m));
}

// Asks for a small frame and reads to its end: the connection still serves.
EndOfFrameMsg one_frame(RawWs& ws) {
    RequestMsg r;
    r.request_id = 7;
    r.view = phantom_view(64, 48, 0);
    ws.send_message(r);
    for (;;) {
        const RemoteMessage m = ws.receive_message(kFloodTimeoutS);
        if (const auto* e = std::get_if<EndOfFrameMsg>(&m)) return *e;
        if (const auto* e = std::get_if<ErrorMsg>(&m)) throw std::runtime_error(e->text);
    }
}

struct Flood {
    long pings = 0;
    double peak_growth_mib = 0;
    double seconds = 0;
};

// Pings with payloads "1", "2", ... in sends of kPingsPerSend; the process's RSS over `rss0`
// sampled after each send.
Flood flood_pings(RawWs& ws, double rss0) {
    Flood f;
    const auto start = Clock::now();
    std::vector<std::byte> batch;
    while (f.pings < kFloodPings && f.seconds < kFloodSeconds) {
        batch.clear();
        for (int i = 0; i < kPingsPerSend; ++i) {
            const std::vector<std::byte> ping =
                RawWs::frame(ws_opcode::kPing, std::to_string(++f.pings));
            batch.insert(batch.end(), ping.begin(), ping.end());
        }
        ws.send_raw(batch);
        f.peak_growth_mib = std::max(f.peak_growth_mib, current_rss_mib() - rss0);
        f.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    }
    return f;
}

// Reads every frame on another thread, counting pongs, until the pong of `last` arrives.
class PongReader {
  public:
    explicit PongReader(RawWs& ws) : thread_([this, &ws] { run(ws); }) {}
    ~PongReader() {
        stop_ = true;
        thread_.join();
    }
    void expect(const std::string& last) {
        std::lock_guard lock(mutex_);
        last_ = last;
    }
    bool wait_last(double timeout_s) {
        const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
        while (!got_last_ && Clock::now() < end) std::this_thread::sleep_for(kPoll);
        return got_last_;
    }
    long pongs() const { return pongs_; }

  private:
    static constexpr auto kPoll = std::chrono::milliseconds(5);
    void run(RawWs& ws) {
        while (!stop_ && !got_last_) {
            const std::optional<RawWsFrame> f = ws.receive(0.05);
            if (!f || f->opcode != ws_opcode::kPong) continue;
            ++pongs_;
            std::lock_guard lock(mutex_);
            if (f->payload == last_) got_last_ = true;
        }
    }
    std::mutex mutex_;
    std::string last_ = "(none yet)";
    std::atomic<bool> stop_{false}, got_last_{false};
    std::atomic<long> pongs_{0};
    std::thread thread_;
};

TEST(RemoteWebFlood, APingFloodKeepsOnePongWaitingAndTheServerSmall) {
    WebTestServer server;
    RawWs ws(server.http_port());
    ws.send_message(phantom_hello());
    expect_ready(ws);
    const double rss0 = current_rss_mib();
    Flood f;
    long pongs = 0;
    {
        PongReader reader(ws);
        f = flood_pings(ws, rss0);
        reader.expect("last");
        ws.send_raw(RawWs::frame(ws_opcode::kPing, "last"));
        EXPECT_TRUE(reader.wait_last(kFloodTimeoutS)) << "the newest ping was never answered";
        pongs = reader.pongs();
    }
    std::printf(
        "[ measured ] ping flood, client reading: %ld pings in %.2f s, %ld pongs, the process "
        "grew by at most %.1f MiB\n",
        f.pings + 1, f.seconds, pongs, f.peak_growth_mib);
    if (kRssJudged) {
        EXPECT_LT(f.peak_growth_mib, kMaxGrowthMiB);
    }
    EXPECT_GE(pongs, 1);
    EXPECT_LE(pongs, f.pings + 1);
    EXPECT_GT(one_frame(ws).triangles, 0u) << "the connection no longer serves";
}

// The variant: a client that floods and never reads. Its pongs cannot go out; none pile up.
TEST(RemoteWebFlood, APingFloodFromAClientThatNeverReadsKeepsTheServerSmall) {
    WebTestServer server;
    const double rss0 = current_rss_mib();
    Flood f;
    {
        RawWs deaf(server.http_port());
        deaf.send_message(phantom_hello());
        f = flood_pings(deaf, rss0);
    }
    std::printf(
        "[ measured ] ping flood, client not reading: %ld pings in %.2f s, the process grew by "
        "at most %.1f MiB\n",
        f.pings, f.seconds, f.peak_growth_mib);
    if (kRssJudged) {
        EXPECT_LT(f.peak_growth_mib, kMaxGrowthMiB);
    }
    RawWs next(server.http_port());
    next.send_message(phantom_hello());
    expect_ready(next);
    EXPECT_GT(one_frame(next).triangles, 0u);
}

// The outgoing queue's byte cap, on the WebSocket layer alone: with back-pressure set above the
// cap, sends to a client that does not read end in a close (1008) instead of a growing queue.
TEST(RemoteWebFlood, AnOutgoingQueueOverItsCapClosesTheConnection) {
    web::WebOptions wo;
    wo.max_buffered_bytes = std::size_t{1} << 30;  // never wait: only the cap stops the queue
    wo.max_queued_bytes = std::size_t{1} << 20;
    std::atomic<web::ConnectionId> id{0};
    web::WebCallbacks cb;
    cb.http = [](const web::HttpRequest&) { return web::HttpResponse{}; };
    cb.opened = [&id](web::ConnectionId c, const std::string&) { id = c; };
    cb.message = [](web::ConnectionId, std::string, bool) {};
    cb.closed = [](web::ConnectionId) {};
    web::WebServer server(wo, cb);
    server.start();
    RawWs deaf(server.port());
    const auto end = Clock::now() + std::chrono::seconds(10);
    while (id == 0 && Clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_NE(id, 0u) << "the WebSocket did not open";
    const std::vector<char> chunk(64 * 1024, 'x');
    int sent = 0;
    while (sent < 4096 && server.send(id, chunk.data(), chunk.size())) ++sent;
    EXPECT_LT(sent, 4096) << "256 MiB queued for a client that reads nothing";
    int code = 0;
    EXPECT_TRUE(deaf.wait_closed(kFloodTimeoutS, &code));
    EXPECT_EQ(code, 1008);
    std::printf("[ measured ] %d sends of 64 KiB before the cap of 1 MiB closed the connection\n",
                sent);
}

TEST(RemoteWebFlood, AnIdleWebSocketIsClosedNamingTheLimit) {
    ServerOptions o;
    o.idle_timeout_s = 0.5;
    WebTestServer server(o);
    RawWs ws(server.http_port());
    ws.send_message(phantom_hello());
    expect_ready(ws);
    const RemoteMessage m = ws.receive_message(kFloodTimeoutS);
    const auto* e = std::get_if<ErrorMsg>(&m);
    ASSERT_TRUE(e) << "expected an error, got " << to_string(type_of(m));
    EXPECT_NE(e->text.find("--idle-timeout"), std::string::npos) << e->text;
    EXPECT_NE(e->text.find("0.5 s"), std::string::npos) << e->text;
    EXPECT_TRUE(ws.wait_closed(kFloodTimeoutS));
}

}  // namespace
}  // namespace isowall::test
