// The wall's page server (app/wall_http.h) in process, over real WebSockets on loopback, with a
// master that has not started (its state and previews as at start-up): the hello and its token,
// who steers and the refusals, every page told of every line, snapshots named by the master, the
// bound on pages, and an address off loopback refused. web/test/e2e_wall.mjs runs the page itself
// against a wall under mpirun.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/wall_http.h"
#include "comm/inproc_comm.h"
#include "core/error.h"
#include "remote/net/socket.h"
#include "tests/test_util.h"
#include "tests/ws_test_client.h"
#include "wall_spec/wall.h"

namespace isowall {
namespace {

using nlohmann::json;
using test::WsTestClient;

WallSpec two_by_two() {
    WallSpec s;
    s.columns = 2;
    s.rows = 2;
    s.tile_width_px = 320;
    s.tile_height_px = 240;
    return s;
}

struct Fixture {
    WallSpec spec = two_by_two();
    InProcWorld world{5};
    std::unique_ptr<Comm> comm = world.comm(0);
    MasterOptions mo;
    WallMaster master{mo, *comm, spec, Box3{glm::vec3(0), glm::vec3(1)}, 50, 0, 220};
};

// Messages of `type`, waiting while the source turns (as run_steering does).
json next_of(WsTestClient& c, WallHttp& http, const WallMaster& master, const std::string& type,
             std::vector<SteeringLine>* lines = nullptr) {
    for (int turn = 0; turn < 200; ++turn) {
        for (SteeringLine& l : http.take(master))
            if (lines) lines->push_back(std::move(l));
        http.show(master, FrameNote{1, false, 0.5}, true);
        while (auto m = c.receive(0.01))
            if (!m->bytes.empty() && m->bytes[0] == '{') {
                json j = json::parse(m->bytes);
                if (j["type"] == type) return j;
            }
    }
    return nullptr;
}

// The lines the source gives, turning it until there are `n` (or 10 s have passed).
std::vector<SteeringLine> lines_of(WallHttp& http, const WallMaster& master, std::size_t n) {
    std::vector<SteeringLine> lines;
    for (int turn = 0; turn < 1000 && lines.size() < n; ++turn) {
        for (SteeringLine& l : http.take(master)) lines.push_back(std::move(l));
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return lines;
}

WallHttpOptions options(std::size_t max_pages = 16) {
    WallHttpOptions o;
    o.port = 0;
    o.token = "t0k3n";
    o.out = (test::scratch_dir("wall_http") / "mosaic.png").string();
    o.wall_name = "2x2";
    o.max_pages = max_pages;
    return o;
}

TEST(WallHttp, PagesSayHelloSteerOneAtATimeAndHearEveryLine) {
    Fixture f;
    WallHttp http(f.spec, options());
    WsTestClient a(http.port()), b(http.port());
    a.send_text(R"({"hello": "t0k3n"})");
    const json wa = next_of(a, http, f.master, "welcome");
    ASSERT_FALSE(wa.is_null());
    EXPECT_EQ(wa["you"], "page 1");
    EXPECT_EQ(wa["tiles"].size(), 4u);
    b.send_text(R"({"hello": "t0k3n"})");
    EXPECT_EQ(next_of(b, http, f.master, "welcome")["you"], "page 2");
    // Each page gets the mosaic of the control window's layout.
    // The mosaic is made on the encoder's thread and handed out by the next show().
    std::optional<test::WsMessage> picture;
    for (int i = 0; i < 100 && !picture; ++i) {
        http.show(f.master, FrameNote{1, false, 0.5}, false);
        if (auto m = b.receive(0.1); m && m->bytes.rfind("IWM1", 0) == 0) picture = m;
    }
    ASSERT_TRUE(picture);
    const Image mosaic = decode_mosaic(picture->bytes);
    EXPECT_EQ(mosaic.width, wa["width"]);

    // Page 1's command is a line to run; it now steers, and page 2 is refused.
    a.send_text(R"({"run": "orbit -30 0"})");
    std::vector<SteeringLine> lines = lines_of(http, f.master, 1);
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_EQ(lines[0].text, "orbit -30 0");
    EXPECT_EQ(lines[0].who, "page 1");
    b.send_text(R"({"run": "zoom 2"})");
    const json refused = next_of(b, http, f.master, "error", &lines);
    EXPECT_NE(refused["text"].get<std::string>().find("page 1 steers"), std::string::npos);
    EXPECT_EQ(lines.size(), 1u);
    // Every page hears of a line that ran.
    http.ran(lines[0], "");
    EXPECT_EQ(next_of(b, http, f.master, "ran")["line"], "orbit -30 0");
    EXPECT_EQ(next_of(a, http, f.master, "ran")["who"], "page 1");

    // Page 2 takes over: both see it, and page 1 is refused.
    b.send_text(R"({"take": true})");
    json seen;
    for (int i = 0; i < 20 && seen["steering"] != "page 2"; ++i)
        seen = next_of(a, http, f.master, "state");
    EXPECT_EQ(seen["steering"], "page 2");
    EXPECT_EQ(seen["pages"], json::array({"page 1", "page 2"}));
    a.send_text(R"({"run": "zoom 2"})");
    EXPECT_NE(next_of(a, http, f.master, "error")["text"].get<std::string>().find("page 2 steers"),
              std::string::npos);
    // A snapshot is named by the master, and a bad line is refused to its page alone.
    lines.clear();
    b.send_text(R"({"snapshot": true})");
    b.send_text(R"({"run": "wait done"})");
    const json bad = next_of(b, http, f.master, "error", &lines);
    EXPECT_NE(bad["text"].get<std::string>().find("never stalls"), std::string::npos);
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_EQ(lines[0].text, "snapshot page-001");
    EXPECT_EQ(lines[0].who, "page 2");
}

TEST(WallHttp, AWrongTokenOrNoHelloClosesThePage) {
    Fixture f;
    WallHttp http(f.spec, options());
    WsTestClient wrong(http.port()), rude(http.port());
    wrong.send_text(R"({"hello": "guess"})");
    EXPECT_NE(
        next_of(wrong, http, f.master, "error")["text"].get<std::string>().find("wrong token"),
        std::string::npos);
    EXPECT_TRUE(wrong.wait_closed(5));
    rude.send_text(R"({"run": "quit"})");
    EXPECT_NE(next_of(rude, http, f.master, "error")["text"].get<std::string>().find("hello"),
              std::string::npos);
    EXPECT_TRUE(rude.wait_closed(5));
}

TEST(WallHttp, PagesPastTheBoundAreTurnedAway) {
    Fixture f;
    WallHttp http(f.spec, options(2));
    WsTestClient a(http.port()), b(http.port());
    for (int i = 0; i < 20; ++i) http.take(f.master);
    WsTestClient c(http.port());
    EXPECT_TRUE(c.wait_closed(5));
    EXPECT_FALSE(a.wait_closed(0.2));
}

// The page's Host rule (remote/http/web_server.h) holds on the wall too: a page that reaches it
// by a foreign name (DNS rebinding) is refused before the page's files.
TEST(WallHttp, APageReachingTheWallByAForeignNameIsRefused) {
    Fixture f;
    WallHttp http(f.spec, options());
    const auto status_for = [&](const std::string& host) {
        remote::Socket s = remote::connect_tcp("127.0.0.1", http.port(), 10);
        const std::string request =
            "GET / HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n";
        remote::send_all(s, std::as_bytes(std::span(request.data(), request.size())), "wall");
        std::string reply;
        std::array<std::byte, 4096> buf;
        std::size_t got = 0;
        try {
            while (reply.find("\r\n") == std::string::npos &&
                   remote::recv_some(s, buf, 10, got, "wall"))
                reply.append(reinterpret_cast<const char*>(buf.data()), got);
        } catch (const remote::PeerClosed&) {
        }
        return reply.substr(0, reply.find("\r\n"));
    };
    const std::string port = ":" + std::to_string(http.port());
    EXPECT_NE(status_for("evil.example" + port).find(" 403"), std::string::npos);
    EXPECT_NE(status_for("127.0.0.1" + port).find(" 200"), std::string::npos);
}

TEST(WallHttp, AnAddressOffLoopbackNeedsTlsAndAToken) {
    Fixture f;
    WallHttpOptions o = options();
    o.address = "0.0.0.0";
    try {
        WallHttp http(f.spec, o);
        ADD_FAILURE() << "listened on 0.0.0.0 without TLS";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--http-listen"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("needs TLS"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace isowall
