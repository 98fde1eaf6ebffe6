// The server under every abuse of "Nothing lies, nothing hangs, round two" at once, in process
// on loopback, for kSoakSeconds: a ping flood from a client that reads its pongs and one from a
// client that does not, a request flood over TCP and one over WebSocket, clients that say hello
// and then nothing (the idle limit drops them, and they come back), and slow readers over both.
// The process's resident memory may grow by at most kMaxGrowthMiB (not judged under
// AddressSanitizer, remote_rss_util.h), every connection ends, and a well-behaved client gets,
// in the middle of it all, the same frame as on the quiet server. Its own executable, so that no
// other test's memory is counted.
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <set>
#include <thread>

#include <sys/socket.h>

#include <gtest/gtest.h>

#include "core/util.h"
#include "remote/net/connection.h"
#include "tests/remote_raw_ws.h"
#include "tests/remote_rss_util.h"
#include "tests/remote_web_util.h"

namespace isowall::test {
namespace {

using namespace remote;
using Clock = std::chrono::steady_clock;

constexpr double kSoakSeconds = 4;
constexpr double kTimeoutS = 60;
// The abusers' own buffers, a frame in flight per connection, the WebSocket queues of the clients
// that do not read (4 MiB each) and thread stacks count too: 18-37 MiB measured. With a pong
// queued for every ping, as before the fix, the same soak grew by 128 MiB.
constexpr double kMaxGrowthMiB = 80;
constexpr int kSilentClients = 4;

// The abusers' sockets, so that the end of the soak can wake a send the server no longer reads.
class LiveSockets {
  public:
    void add(Socket* s) {
        std::lock_guard lock(mutex_);
        live_.insert(s);
        if (stopped_) s->shutdown_both();
    }
    void remove(Socket* s) {
        std::lock_guard lock(mutex_);
        live_.erase(s);
    }
    void shutdown_all() {
        std::lock_guard lock(mutex_);
        stopped_ = true;
        for (Socket* s : live_) s->shutdown_both();
    }

  private:
    std::mutex mutex_;
    std::set<Socket*> live_;
    bool stopped_ = false;
};

struct Soak {
    int tcp_port = 0, http_port = 0;
    std::vector<RequestMsg> requests;  // made before the soak (a view builds the phantom)
    std::atomic<bool> stop{false};
    std::atomic<long> pings{0}, requests_sent{0}, connections{0};
    LiveSockets sockets;

    // Runs `body` on a fresh connection again and again until the stop; the server closing it
    // (the idle limit, an error) only starts the next round.
    void repeat(const std::function<void()>& body) {
        while (!stop) {
            try {
                ++connections;
                body();
            } catch (const std::exception&) {
            }
        }
    }
};

class Registered {
  public:
    Registered(Soak& s, Socket& socket) : s_(s), socket_(socket) { s_.sockets.add(&socket_); }
    ~Registered() { s_.sockets.remove(&socket_); }
    Registered(const Registered&) = delete;
    Registered& operator=(const Registered&) = delete;

  private:
    Soak& s_;
    Socket& socket_;
};

// Reads and drops whatever arrives until the stop or the end of the connection.
void drain(Soak& s, Socket& socket) {
    std::vector<std::byte> buf(64 * 1024);
    std::size_t got = 0;
    while (!s.stop) recv_some(socket, buf, 0.1, got, "server");
}

void ping_flood(Soak& s, bool reading) {
    RawWs ws(s.http_port);
    Registered reg(s, ws.socket());
    ws.send_message(phantom_hello());
    std::thread reader;
    if (reading)
        reader = std::thread([&] {
            try {
                drain(s, ws.socket());
            } catch (const std::exception&) {
            }
        });
    // A request after each 1024 pings keeps the connection from the idle limit, so one flood
    // lasts the whole soak (pings alone are not activity: websocketpp answers them, not the
    // protocol).
    std::vector<std::byte> batch;
    for (int i = 0; i < 1024; ++i) {
        const std::vector<std::byte> ping = RawWs::frame(ws_opcode::kPing, std::to_string(i));
        batch.insert(batch.end(), ping.begin(), ping.end());
    }
    RequestMsg r = s.requests.front();
    r.request_id = 1;
    const std::vector<std::byte> request = RawWs::frame(ws_opcode::kBinary, encode_frame(r));
    batch.insert(batch.end(), request.begin(), request.end());
    try {
        while (!s.stop) {
            ws.send_raw(batch);
            s.pings += 1024;
        }
    } catch (const std::exception&) {
    }
    ws.socket().shutdown_both();
    if (reader.joinable()) reader.join();
}

// A client's socket: a WebSocket through the page's port when `ws`, else plain TCP.
Socket& connect_client(Soak& s, bool ws, std::optional<RawWs>& w, std::optional<Socket>& tcp) {
    if (ws) {
        w.emplace(s.http_port);
        return w->socket();
    }
    tcp.emplace(connect_tcp("127.0.0.1", s.tcp_port, 5));
    return *tcp;
}

// Requests as fast as the socket takes them, 64 frames to a send, replies read on another
// thread. Over TCP, or over a WebSocket when `ws`.
void request_flood(Soak& s, bool ws) {
    std::optional<RawWs> w;
    std::optional<Socket> tcp;
    Socket& socket = connect_client(s, ws, w, tcp);
    Registered reg(s, socket);
    const auto frame = [&](const RemoteMessage& m) {
        return ws ? RawWs::frame(ws_opcode::kBinary, encode_frame(m)) : encode_frame(m);
    };
    send_all(socket, frame(phantom_hello()), "server");
    std::thread reader([&] {
        try {
            drain(s, socket);
        } catch (const std::exception&) {
        }
    });
    try {
        for (std::uint64_t id = 1; !s.stop;) {
            std::vector<std::byte> batch;
            for (int i = 0; i < 64; ++i, ++id) {
                RequestMsg r = s.requests[id % s.requests.size()];
                r.request_id = id;
                const std::vector<std::byte> f = frame(r);
                batch.insert(batch.end(), f.begin(), f.end());
            }
            send_all(socket, batch, "server");
            s.requests_sent += 64;
        }
    } catch (const std::exception&) {
    }
    socket.shutdown_both();
    reader.join();
}

// Hello, then nothing until the server closes the connection.
void silent(Soak& s) {
    Connection c(connect_tcp("127.0.0.1", s.tcp_port, 5), "server");
    Registered reg(s, c.socket());
    c.send(phantom_hello());
    while (!s.stop) c.receive(0.1);
}

// Asks for the largest frame there is (800x600, triangles as separate vertices) and reads it at
// 4 KiB every 10 ms through a small receive buffer.
void slow_reader(Soak& s, bool ws) {
    std::optional<RawWs> w;
    std::optional<Socket> tcp;
    Socket& socket = connect_client(s, ws, w, tcp);
    Registered reg(s, socket);
    const int small = 4096;
    ::setsockopt(socket.native_handle(), SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    RequestMsg r = s.requests.front();
    r.request_id = 1;
    r.view.width = 800;
    r.view.height = 600;
    for (const RemoteMessage& m : {RemoteMessage(phantom_hello(0)), RemoteMessage(r)})
        send_all(socket, ws ? RawWs::frame(ws_opcode::kBinary, encode_frame(m)) : encode_frame(m),
                 "server");
    std::vector<std::byte> buf(4096);
    std::size_t got = 0;
    while (!s.stop) {
        recv_some(socket, buf, 0.1, got, "server");
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
}

// A well-behaved client's frame over TCP: its end of frame, or a failure.
EndOfFrameMsg good_frame(int port, const RequestMsg& r) {
    Connection c(connect_tcp("127.0.0.1", port, 5), "server");
    c.send(phantom_hello());
    for (;;) {
        const std::optional<RemoteMessage> m = c.receive(kTimeoutS);
        if (!m) throw std::runtime_error("no message within the timeout");
        if (std::holds_alternative<ReadyMsg>(*m)) c.send(r);
        if (const auto* e = std::get_if<ErrorMsg>(&*m)) throw std::runtime_error(e->text);
        if (const auto* e = std::get_if<EndOfFrameMsg>(&*m)) return *e;
    }
}

// The largest RSS seen, sampled every 10 ms on a thread of its own.
class PeakRss {
  public:
    PeakRss() : peak_(current_rss_mib()), thread_([this] { run(); }) {}
    ~PeakRss() { stop(); }
    double stop() {
        stop_ = true;
        if (thread_.joinable()) thread_.join();
        return peak_;
    }

  private:
    void run() {
        while (!stop_) {
            peak_ = std::max(peak_.load(), current_rss_mib());
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
    }
    std::atomic<double> peak_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

TEST(RemoteSoak, AbusiveClientsLeaveTheServerSmallAndAGoodClientServed) {
    keep_freed_memory();  // as `isowall` does: what is freed stays, so RSS holds the peak
    ServerOptions o;
    o.max_clients = 64;
    o.idle_timeout_s = 1;
    WebTestServer server(o);
    Soak s;
    s.tcp_port = server.tcp_port();
    s.http_port = server.http_port();
    const Box3 bounds = make_phantom().bounds();
    for (int yaw = 0; yaw < 360; yaw += 45) {
        RequestMsg r;
        r.view = front_view(bounds, 200, 150, yaw, kPhantomSkinIso);
        s.requests.push_back(r);
    }
    RequestMsg good = s.requests[1];
    good.request_id = 1;
    const EndOfFrameMsg quiet = good_frame(s.tcp_port, good);
    const double rss0 = current_rss_mib();
    PeakRss peak;
    std::vector<std::thread> abusers;
    const auto start = [&](std::function<void()> body) {
        abusers.emplace_back([&s, body] { s.repeat(body); });
    };
    start([&] { ping_flood(s, true); });
    start([&] { ping_flood(s, false); });
    start([&] { request_flood(s, false); });
    start([&] { request_flood(s, true); });
    for (int i = 0; i < kSilentClients; ++i) start([&] { silent(s); });
    start([&] { slow_reader(s, false); });
    start([&] { slow_reader(s, true); });
    const auto began = Clock::now();
    std::this_thread::sleep_for(std::chrono::duration<double>(kSoakSeconds / 4));
    EndOfFrameMsg busy;
    EXPECT_NO_THROW(busy = good_frame(s.tcp_port, good)) << "the good client was not served";
    std::this_thread::sleep_until(began + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(kSoakSeconds)));
    s.stop = true;
    s.sockets.shutdown_all();
    for (std::thread& t : abusers) t.join();
    const double rss_peak = peak.stop();
    const auto left = Clock::now() + std::chrono::seconds(30);
    while (server.view_server().open_connections() > 0 && Clock::now() < left)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_EQ(server.view_server().open_connections(), 0) << "connections left open";
    std::printf(
        "[ measured ] soak of %.0f s: %ld pings, %ld requests, %ld connections; RSS %.1f MiB "
        "before, %.1f MiB at the peak (+%.1f), %.1f MiB after the clients left\n",
        kSoakSeconds, s.pings.load(), s.requests_sent.load(), s.connections.load(), rss0, rss_peak,
        rss_peak - rss0, current_rss_mib());
    if (kRssJudged) {
        EXPECT_LT(rss_peak - rss0, kMaxGrowthMiB);
    }
    EXPECT_GT(s.pings.load(), 0);
    EXPECT_GT(s.requests_sent.load(), 0);
    EXPECT_EQ(busy.triangles, quiet.triangles);
    EXPECT_EQ(busy.groups, quiet.groups);
    EXPECT_EQ(busy.rays, quiet.rays);
}

}  // namespace
}  // namespace isowall::test
