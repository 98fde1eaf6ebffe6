// Shared sessions of `isowall serve` (remote/shared_session.h), in process over loopback: a
// presenter and followers, one of whom joins after the first view and catches up; each follower's
// final image equals the presenter's after each of three views; a follower that stops reading is
// dropped while the others finish, and the memory its queue took stays under the bound (printed).
// Then the queue and the renumbering alone, and the refusals a hello can get.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>

#include "core/util.h"
#include "remote/net/socket.h"
#include "remote/view_client.h"
#include "tests/remote_rss_util.h"
#include "tests/remote_view_util.h"

namespace isowall::remote {
namespace {

constexpr double kTimeoutS = 120;
constexpr std::size_t kQueueBound = 256 << 10;

ClientHello session_hello(int port, SessionRole role, const std::string& name = "class") {
    ClientHello h;
    h.port = port;
    h.role = role;
    h.session = name;
    return h;
}

// A follower on its own thread (its own renderer): the view and final image of every frame it
// completes, until one of `last` (a catch-up cut short by the presenter's next view never
// completes, so the frames are not counted).
struct Follower {
    Follower(int port, const FrameView& last) {
        thread = std::thread([this, port, last] {
            try {
                auto renderer = make_renderer("osmesa");
                ViewClient c(*renderer, session_hello(port, SessionRole::follower));
                mark_joined();
                for (bool more = true; more;) {
                    const ClientFrameResult* r = c.next_frame(kTimeoutS);
                    if (!r) throw std::runtime_error("no frame within the limit");
                    views.push_back(c.frames().request().view);
                    images.push_back(r->final_image);
                    more = !same_view(views.back(), last);
                }
                if (c.session()) presenter = c.session()->presenter;
                c.close();
            } catch (const std::exception& e) {
                error = e.what();
            }
            mark_joined();
        });
    }
    void mark_joined() {
        {
            std::lock_guard lock(joined_mutex);
            joined = true;
        }
        joined_changed.notify_all();
    }
    // Returns once the follower is in the session (its ready came), or has failed.
    void wait_joined() {
        std::unique_lock lock(joined_mutex);
        joined_changed.wait(lock, [&] { return joined; });
    }
    std::thread thread;
    std::mutex joined_mutex;
    std::condition_variable joined_changed;
    bool joined = false;
    static bool same_view(const FrameView& a, const FrameView& b) {
        return a.iso == b.iso && a.camera.eye == b.camera.eye && a.width == b.width;
    }
    std::vector<FrameView> views;
    std::vector<Image> images;
    std::string presenter, error;
};

// A follower that says hello and never reads, with a small receive buffer: the server's send to
// it soon blocks and its queue grows.
int stalled_follower(int port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    const int small = 4096;
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    HelloMsg h = test::phantom_hello();
    h.role = SessionRole::follower;
    h.session = "class";
    const std::vector<std::byte> frame = encode_frame(h);
    EXPECT_EQ(::send(fd, frame.data(), frame.size(), 0), static_cast<ssize_t>(frame.size()));
    // The server's answer begins: its hello was taken (a peek: the buffer stays as full).
    char first = 0;
    EXPECT_EQ(::recv(fd, &first, 1, MSG_PEEK), 1) << "no answer to the stalled follower's hello";
    return fd;
}

TEST(RemoteSession, FollowersSeeEveryViewAndASlowOneIsDropped) {
    ServerOptions o;
    o.sessions.max_queue_bytes = kQueueBound;
    test::TestServer server(o);
    const double rss_start = current_rss_mib();  // the process's: server and clients
    auto renderer = make_renderer("osmesa");
    ViewClient presenter(*renderer, session_hello(server.port(), SessionRole::presenter));
    const FrameView views[] = {test::phantom_view(640, 480, 0), test::phantom_view(640, 480, 35),
                               test::phantom_view(640, 480, 35, 120)};
    Follower early(server.port(), views[2]);
    early.wait_joined();
    const int stalled = stalled_follower(server.port());
    std::vector<Image> shown;
    std::unique_ptr<Follower> late;
    for (const FrameView& v : views) {
        presenter.request(v, LodSchedule::on, /*cached_groups=*/true);
        shown.push_back(presenter.wait_done(kTimeoutS).final_image);
        if (!late) {  // joins after the first view: catches up with it, then follows
            late = std::make_unique<Follower>(server.port(), views[2]);
            late->wait_joined();
        }
    }
    early.thread.join();
    late->thread.join();
    ASSERT_EQ(early.error, "");
    ASSERT_EQ(late->error, "");
    // The early follower completes all three views; the late one its catch-up of the first
    // (unless the second came first) and the other two. Each frame equals the presenter's.
    EXPECT_EQ(early.images.size(), 3u);
    EXPECT_GE(late->images.size(), 2u);
    for (const Follower* f : {&early, late.get()})
        for (std::size_t i = 0; i < f->images.size(); ++i) {
            std::size_t k = 0;
            while (k < 3 && !Follower::same_view(f->views[i], views[k])) ++k;
            ASSERT_LT(k, 3u) << "a frame of a view the presenter never asked for";
            const auto c = test::compare_images(f->images[i], shown[k]);
            std::printf("%s follower, view %zu: %s\n", f == &early ? "early" : "late", k + 1,
                        testing::PrintToString(c).c_str());
            EXPECT_GT(c.covered_both, 1000u);
            EXPECT_GE(c.mask_iou, 0.999);
            EXPECT_GE(c.equal_share, 0.999);
        }
    EXPECT_FALSE(early.presenter.empty());
    // The stalled follower is dropped once its queue would pass the bound: more views, each
    // sent whole (no cache), until it is (its connection closes within the error's 2 s).
    int more = 0;
    for (; more < 12 && server.server().sessions().overflowed() == 0; ++more) {
        presenter.request(test::phantom_view(640, 480, 10.0 * more, 60 + more), LodSchedule::off,
                          false);
        presenter.wait_done(kTimeoutS);
    }
    ASSERT_GT(server.server().sessions().overflowed(), 0u) << "no queue overflowed in 12 views";
    server.server().sessions().wait_dropped(1);  // its connection ends within the error's 2 s
    std::printf("the stalled follower was dropped after %d more view(s)\n", more);
    const std::size_t peak = server.server().sessions().peak_queue_bytes();
    std::printf("session: followers' queues peaked at %zu KiB (bound %zu KiB), %zu dropped\n",
                peak >> 10, kQueueBound >> 10, server.server().sessions().dropped());
    EXPECT_EQ(server.server().sessions().dropped(), 1u);
    EXPECT_LE(peak, kQueueBound);
    // The process holds the server and every client; what it grew by, for the note (judged by
    // the queue's bound above; RSS under ASan holds its quarantine).
    std::printf("process RSS %.1f MiB at the start, %.1f MiB now, peak %.1f MiB%s\n", rss_start,
                current_rss_mib(), peak_rss_mib(), test::kRssJudged ? "" : " (ASan)");
    presenter.close();
    ::close(stalled);
}

// The hellos of a presenter and a follower of session "s".
std::pair<HelloMsg, HelloMsg> session_hellos() {
    HelloMsg p = test::phantom_hello();
    p.role = SessionRole::presenter;
    p.session.assign(1, 's');  // GCC 12 warns falsely (-Wrestrict) on assigning "s" here
    HelloMsg f = p;
    f.role = SessionRole::follower;
    return {p, f};
}

TEST(RemoteSession, TheQueueKeepsNothingBeforeARequestAndDropsPastItsBound) {
    FollowerQueue q(10000);
    GroupMsg g;
    g.encoded.resize(4000);
    q.push(g);  // before any request: a group whose beginning it never saw
    EXPECT_FALSE(q.armed());
    q.push(SessionMsg{"s", "p", 2});  // status always goes
    q.push(RequestMsg{});
    EXPECT_TRUE(q.armed());
    q.push(g);
    EXPECT_TRUE(std::holds_alternative<SessionMsg>(*q.pop()));
    EXPECT_TRUE(std::holds_alternative<RequestMsg>(*q.pop()));
    EXPECT_TRUE(std::holds_alternative<GroupMsg>(*q.pop()));
    q.push(g);
    q.push(g);
    q.push(g);  // 3 x 4064 bytes: past the bound
    EXPECT_NE(q.why().find("dropped from the session"), std::string::npos) << q.why();
    EXPECT_FALSE(q.pop());
    EXPECT_LE(q.peak_bytes(), 10000u);
}

// Followers see one stream of ids whoever presents: a second presenter's request 1 and its
// generation get new numbers, never one a follower holds.
TEST(RemoteSession, RequestsAndGenerationsAreRenumberedForFollowers) {
    SessionHub hub;
    const auto [p, f] = session_hellos();
    std::string why;
    auto first = hub.join(p, "a:1", why);
    auto follower = hub.join(f, "b:2", why);
    ASSERT_TRUE(first && follower) << why;
    SharedSession& s = first->session();
    std::vector<std::uint64_t> ids;
    auto run = [&](std::uint64_t request, std::uint64_t gen) {
        RequestMsg r;
        r.request_id = request;
        s.begin_request(r);
        GroupMsg g;
        g.request_id = request;
        g.cache_gen = gen;
        s.fan_out(g);
    };
    run(1, 1);
    run(2, 1);  // keeps the generation
    first.reset();
    auto second = hub.join(p, "c:3", why);
    ASSERT_TRUE(second) << why;
    run(1, 1);  // the new presenter's first request and generation
    std::vector<std::uint64_t> requests, gens;
    while (follower->queue()->armed() && requests.size() + gens.size() < 6) {
        const auto m = follower->queue()->pop();
        if (const auto* r = std::get_if<RequestMsg>(&*m)) requests.push_back(r->request_id);
        if (const auto* g = std::get_if<GroupMsg>(&*m)) gens.push_back(g->cache_gen);
    }
    ASSERT_EQ(requests.size(), 3u);
    EXPECT_LT(requests[0], requests[1]);
    EXPECT_LT(requests[1], requests[2]);
    EXPECT_EQ(gens[0], gens[1]);  // one generation, kept
    EXPECT_NE(gens[2], gens[0]);  // the new presenter's is another
    EXPECT_GE(requests[0], std::uint64_t{1} << 40);
}

TEST(RemoteSession, HellosThatCannotJoinAreRefusedSayingWhy) {
    SessionLimits limits;
    limits.max_sessions = 1;
    limits.max_members = 2;
    SessionHub hub(limits);
    const auto [p, f] = session_hellos();
    std::string why;
    HelloMsg nobody = f;
    nobody.session = "t";
    EXPECT_FALSE(hub.join(nobody, "x:1", why));
    EXPECT_NE(why.find("no session \"t\" to follow"), std::string::npos) << why;
    auto seat = hub.join(p, "a:1", why);
    ASSERT_TRUE(seat);
    EXPECT_FALSE(hub.join(p, "b:2", why));
    EXPECT_NE(why.find("a:1 presents session \"s\" already"), std::string::npos) << why;
    HelloMsg other = p;
    other.session = "u";
    EXPECT_FALSE(hub.join(other, "c:3", why));
    EXPECT_NE(why.find("1 sessions are open"), std::string::npos) << why;
    HelloMsg raw = f;
    raw.encoding = 0;
    EXPECT_FALSE(hub.join(raw, "d:4", why));
    EXPECT_NE(why.find("encoding"), std::string::npos) << why;
    auto one = hub.join(f, "e:5", why);
    ASSERT_TRUE(one) << why;
    EXPECT_FALSE(hub.join(f, "f:6", why));
    EXPECT_NE(why.find("2 members"), std::string::npos) << why;
    EXPECT_EQ(seat->session().status().members, 2u);
}

}  // namespace
}  // namespace isowall::remote
