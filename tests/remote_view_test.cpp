// `isowall serve` and `isowall view` over loopback: the client's final image of a view
// equals the local one in every case, cached groups after a rotation, interrupts, and every bad
// message a server must survive.
#include <set>
#include <unordered_set>

#include <gtest/gtest.h>

#include "remote/net/connection.h"
#include "remote/net/socket.h"
#include "remote/view_client.h"
#include "remote/view_framing.h"
#include "tests/remote_view_util.h"

namespace isowall::test {
namespace {

using namespace remote;

constexpr int kW = 240, kH = 180;
constexpr double kTimeout = 60;

constexpr LodSchedule kOff = LodSchedule::off, kOn = LodSchedule::on;

struct Case {
    const char* name;
    GroupEncoding encoding;
    LodSchedule lod;
    bool cache;
    bool adaptive = false;  // the server chooses (view's default), told the client's decoding
};
const Case kCases[] = {
    {"1 base", GroupEncoding::vertices, kOff, false},
    {"2 indexed", GroupEncoding::indexed, kOff, false},
    {"3 progressive LOD", GroupEncoding::indexed, kOn, false},
    {"4 cached groups", GroupEncoding::indexed, kOn, true},
    {"5 compact+zstd", GroupEncoding::compact_zstd, kOn, true},
    {"cells, new iso", GroupEncoding::cells, kOff, false},
    {"cells + LOD + cache", GroupEncoding::cells, kOn, true},
    {"auto + LOD + cache", GroupEncoding::cells, kOn, true, true},
    {"view's defaults", GroupEncoding::cells, LodSchedule::chosen, false, true},
    {"auto + chosen LOD + cache", GroupEncoding::cells, LodSchedule::chosen, true, true}};

ClientHello hello_for(int port, GroupEncoding e, bool adaptive = false) {
    ClientHello h;
    h.port = port;
    h.encoding = e;
    h.adaptive = adaptive;
    return h;
}

TEST(RemoteView, EveryCaseEndsWithTheLocalImageOfTheViewAlsoAfterARotation) {
    TestServer server;
    const FrameView front = phantom_view(kW, kH, 0), turned = phantom_view(kW, kH, 30);
    const Image want_front = local_image(front), want_turned = local_image(turned);
    for (const Case& c : kCases) {
        auto renderer = make_renderer("osmesa");
        ViewClient client(*renderer, hello_for(server.port(), c.encoding, c.adaptive));
        client.request(front, c.lod, c.cache);
        const ClientFrameResult& a = client.wait_done(kTimeout);
        ASSERT_TRUE(a.completed) << c.name;
        EXPECT_GT(a.end.groups, 0u) << c.name;
        expect_same_image(a.final_image, want_front, std::string(c.name) + ", front");
        // The correctness curve ends at 1 and never falls below what the first sample showed.
        EXPECT_DOUBLE_EQ(a.timeline.back().correctness.c, 1.0) << c.name;
        client.request(turned, c.lod, c.cache);
        const ClientFrameResult& b = client.wait_done(kTimeout);
        expect_same_image(b.final_image, want_turned, std::string(c.name) + ", turned 30");
        if (c.cache) {
            EXPECT_GT(b.timeline.back().named, 0u) << c.name;
        }
        client.close();
    }
}

// A raw client: the messages of each request in arrival order.
struct RawClient {
    explicit RawClient(int port, GroupEncoding e = GroupEncoding::indexed)
        : conn(connect_tcp("127.0.0.1", port, 5), "server") {
        HelloMsg h;
        h.dataset = "phantom";
        h.encoding = static_cast<std::uint8_t>(e);
        conn.send(h);
        auto m = conn.receive(kTimeout);
        if (!m || !std::holds_alternative<ReadyMsg>(*m)) throw std::runtime_error("no ready");
    }
    void request(std::uint64_t id, const FrameView& v, bool lod, bool cache) {
        RequestMsg r;
        r.request_id = id;
        r.view = v;
        r.lod = lod ? LodSchedule::on : LodSchedule::off;
        r.cached_groups = cache;
        conn.send(r);
    }
    RemoteMessage next() {
        auto m = conn.receive(kTimeout);
        if (!m) throw std::runtime_error("nothing within the timeout");
        return *m;
    }
    // Every message up to and including the end of frame of `id`.
    std::vector<RemoteMessage> until_end(std::uint64_t id) {
        std::vector<RemoteMessage> out;
        for (;;) {
            out.push_back(next());
            if (const auto* e = std::get_if<EndOfFrameMsg>(&out.back()); e && e->request_id == id)
                return out;
        }
    }
    Connection conn;
};

TEST(RemoteView, CachedGroupsAreNamedFirstAfterARotationAndNoGroupIsSentTwice) {
    TestServer server;
    RawClient raw(server.port());
    std::unordered_set<GroupKey> sent;
    std::vector<GroupKey> slots;  // the cache generation's groups, by slot
    std::uint64_t gen = 0;
    std::size_t named_first = 0;
    for (std::uint64_t id = 1; id <= 3; ++id) {
        raw.request(id, phantom_view(kW, kH, 20.0 * double(id - 1)), true, true);
        const auto msgs = raw.until_end(id);
        bool group_seen = false;
        for (const RemoteMessage& m : msgs) {
            if (const auto* g = std::get_if<GroupMsg>(&m)) {
                EXPECT_TRUE(sent.insert(g->key).second) << "sent twice: " << g->key;
                if (id > 1 && g->key.level == 0) group_seen = true;
                EXPECT_EQ(g->cache_gen, 1u) << "one isovalue, one generation";
                gen = g->cache_gen;
                slots.push_back(g->key);
            } else if (const auto* v = std::get_if<VisibleMsg>(&m)) {
                for (const std::uint32_t s : v->slots) EXPECT_LT(s, slots.size()) << "gen " << gen;
                if (!group_seen && id > 1) named_first += v->slots.size();
            }
        }
        const auto& end = std::get<EndOfFrameMsg>(msgs.back());
        if (id > 1) {
            EXPECT_LT(end.groups, sent.size()) << "request " << id << " sent everything again";
        }
    }
    EXPECT_GT(named_first, 10u)
        << "the seed rays named cached groups before any new full-resolution group";
}

TEST(RemoteView, ARequestInterruptsTheFrameAndTheNextFrameHoldsOnlyItsGroups) {
    // An 8 Mbit/s link: a frame takes most of a second, so the second request comes during it.
    ServerOptions o;
    o.rate_bits_per_s = 8e6;
    TestServer server(o);
    RawClient raw(server.port());
    raw.request(1, phantom_view(kW, kH, 0), false, false);
    // Wait for the first group of request 1, then turn the view.
    for (;;)
        if (std::holds_alternative<GroupMsg>(raw.next())) break;
    raw.request(2, phantom_view(kW, kH, 90), false, false);
    const auto msgs = raw.until_end(2);
    bool second_started = false;
    for (const RemoteMessage& m : msgs) {
        if (const auto* e = std::get_if<EndOfFrameMsg>(&m)) {
            EXPECT_EQ(e->request_id, 2u) << "request 1 was not interrupted";
        }
        if (const auto* g = std::get_if<GroupMsg>(&m)) {
            if (g->request_id == 2) second_started = true;
            if (second_started) {
                EXPECT_EQ(g->request_id, 2u) << "request 1 went on after 2 began";
            }
        }
    }
    // And the client's picture of request 2 is request 2's view alone.
    auto renderer = make_renderer("osmesa");
    ViewClient client(*renderer, hello_for(server.port(), GroupEncoding::compact_zstd));
    client.request(phantom_view(kW, kH, 0), kOff, false);
    client.receive_for(0.05);
    client.request(phantom_view(kW, kH, 90), kOff, false);
    expect_same_image(client.wait_done(kTimeout).final_image, local_image(phantom_view(kW, kH, 90)),
                      "after an interrupt");
}

}  // namespace
}  // namespace isowall::test
