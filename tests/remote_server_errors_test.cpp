// A server that is sent nonsense answers with an error naming it, closes that connection, never
// allocates what a header claims, and serves the next client.
#include <cmath>
#include <cstring>
#include <utility>

#include <sys/socket.h>

#include <gtest/gtest.h>

#include "core/error.h"
#include "remote/net/connection.h"
#include "remote/net/socket.h"
#include "remote/view_framing.h"
#include "tests/remote_view_util.h"

namespace isowall::test {
namespace {

using namespace remote;

std::vector<std::byte> frame_of(const RemoteMessage& m) {
    return encode_frame(m);
}

// Sends `bytes` (then, when `half_close`, ends the sending side) and returns the server's error.
ErrorMsg error_after(int port, const std::vector<std::byte>& bytes, bool half_close = false) {
    Socket s = connect_tcp("127.0.0.1", port, 5);
    send_all(s, bytes, "server");
    if (half_close) ::shutdown(s.native_handle(), SHUT_WR);
    Connection conn(std::move(s), "server");
    std::optional<RemoteMessage> m = conn.receive(20);
    if (!m) throw std::runtime_error("no answer within 20 s");
    const auto* e = std::get_if<ErrorMsg>(&*m);
    if (!e)
        throw std::runtime_error(std::string("expected an error, got ") + to_string(type_of(*m)));
    // Then the server closes the connection.
    EXPECT_THROW(
        {
            for (int i = 0; i < 100; ++i) conn.receive(0.2);
        },
        PeerClosed);
    return *e;
}

void expect_serves_next(int port) {
    Connection conn(connect_tcp("127.0.0.1", port, 5), "server");
    HelloMsg h;
    h.dataset = "phantom";
    conn.send(h);
    auto m = conn.receive(20);
    ASSERT_TRUE(m && std::holds_alternative<ReadyMsg>(*m)) << "the next client was not served";
}

HelloMsg good_hello(const std::string& token = {}) {
    HelloMsg h;
    h.dataset = "phantom";
    h.token = token;
    return h;
}

TEST(RemoteServerErrors, EachBadInputGetsAnErrorAndAClosedConnectionAndTheServerGoesOn) {
    ServerOptions o;
    o.token = "sesame";
    TestServer server(o);
    const int port = server.port();

    std::vector<std::byte> bad_magic = frame_of(good_hello("sesame"));
    bad_magic[0] = std::byte{'X'};
    EXPECT_EQ(error_after(port, bad_magic).code, ErrorCode::malformed);

    std::vector<std::byte> wrong_version = frame_of(good_hello("sesame"));
    wrong_version[4] = std::byte{9};
    EXPECT_EQ(error_after(port, wrong_version).code, ErrorCode::unsupported_version);

    // A header claiming 3 GiB: refused from the header alone, nothing allocated for it.
    std::vector<std::byte> oversized = frame_of(good_hello("sesame"));
    oversized[8] = oversized[9] = oversized[10] = std::byte{0};
    oversized[11] = std::byte{0xC0};
    EXPECT_EQ(error_after(port, oversized).code, ErrorCode::too_large);

    // A payload whose fields end early (its length agrees with the bytes sent).
    std::vector<std::byte> short_payload = frame_of(good_hello("sesame"));
    short_payload.erase(short_payload.end() - 3, short_payload.end());
    const std::uint32_t len = std::uint32_t(short_payload.size() - kHeaderBytes);
    std::memcpy(short_payload.data() + 8, &len, 4);
    const ErrorMsg e = error_after(port, short_payload);
    EXPECT_EQ(e.code, ErrorCode::malformed);
    EXPECT_NE(e.text.find("hello"), std::string::npos) << e.text;

    // Cut short inside a message, then the client stops sending.
    std::vector<std::byte> cut = frame_of(good_hello("sesame"));
    cut.erase(cut.end() - 2, cut.end());
    EXPECT_EQ(error_after(port, cut, true).code, ErrorCode::malformed);

    EXPECT_EQ(error_after(port, frame_of(good_hello("wrong"))).code, ErrorCode::bad_token);
    EXPECT_EQ(error_after(port, frame_of(good_hello())).code, ErrorCode::bad_token);

    HelloMsg unknown = good_hello("sesame");
    unknown.dataset = "nosuch";
    EXPECT_EQ(error_after(port, frame_of(unknown)).code, ErrorCode::unknown_dataset);

    // A message a client may not send first, and one it may not send later.
    EXPECT_EQ(error_after(port, frame_of(ReadyMsg{})).code, ErrorCode::malformed);
    std::vector<std::byte> later = frame_of(good_hello("sesame"));
    const auto group = frame_of(GroupMsg{});
    later.insert(later.end(), group.begin(), group.end());
    {
        Socket s = connect_tcp("127.0.0.1", port, 5);
        send_all(s, later, "server");
        Connection conn(std::move(s), "server");
        auto ready = conn.receive(20);
        ASSERT_TRUE(ready && std::holds_alternative<ReadyMsg>(*ready));
        auto err = conn.receive(20);
        ASSERT_TRUE(err && std::holds_alternative<ErrorMsg>(*err));
        EXPECT_EQ(std::get<ErrorMsg>(*err).code, ErrorCode::malformed);
    }

    Connection good(connect_tcp("127.0.0.1", port, 5), "server");
    good.send(good_hello("sesame"));
    auto m = good.receive(20);
    ASSERT_TRUE(m && std::holds_alternative<ReadyMsg>(*m)) << "the next client was not served";
}

// Class 7 of "Nothing lies, nothing hangs, round two": a request the server cannot draw got an
// empty frame and no error. Now it gets an error naming the field (before any group), the
// connection closes as after any error, and the server draws the next client's request.
ErrorMsg error_for_request(int port, const RequestMsg& r, ReadyMsg* ready = nullptr) {
    Connection conn(connect_tcp("127.0.0.1", port, 5), "server");
    conn.send(good_hello());
    const std::optional<RemoteMessage> m = conn.receive(20);
    if (!m || !std::holds_alternative<ReadyMsg>(*m)) throw std::runtime_error("no ready");
    if (ready) *ready = std::get<ReadyMsg>(*m);
    conn.send(r);
    const std::optional<RemoteMessage> reply = conn.receive(20);
    if (!reply) throw std::runtime_error("no answer within 20 s");
    const auto* e = std::get_if<ErrorMsg>(&*reply);
    if (!e)
        throw std::runtime_error(std::string("expected an error, got ") +
                                 to_string(type_of(*reply)));
    EXPECT_THROW(conn.receive(20), PeerClosed) << "the connection stayed open";
    return *e;
}

RequestMsg drawable_request(double iso = kPhantomSkinIso) {
    RequestMsg r;
    r.request_id = 1;
    r.view = phantom_view(64, 48, 0, iso);
    return r;
}

void expect_draws_next(int port) {
    Connection conn(connect_tcp("127.0.0.1", port, 5), "server");
    conn.send(good_hello());
    auto m = conn.receive(20);
    ASSERT_TRUE(m && std::holds_alternative<ReadyMsg>(*m));
    conn.send(drawable_request());
    for (;;) {
        m = conn.receive(20);
        ASSERT_TRUE(m) << "no end of frame within 20 s";
        ASSERT_FALSE(std::holds_alternative<ErrorMsg>(*m)) << std::get<ErrorMsg>(*m).text;
        if (const auto* e = std::get_if<EndOfFrameMsg>(&*m)) {
            EXPECT_GT(e->triangles, 0u);
            return;
        }
    }
}

TEST(RemoteServerErrors, AnIsovalueOutsideTheVolumesRangeGetsAnErrorNamingIt) {
    TestServer server;
    ReadyMsg ready;
    ErrorMsg e = error_for_request(server.port(), drawable_request(1e6), &ready);
    EXPECT_EQ(e.code, ErrorCode::malformed);
    EXPECT_NE(e.text.find("view.iso"), std::string::npos) << e.text;
    EXPECT_NE(e.text.find("1e+06"), std::string::npos) << e.text;
    // Just outside either end of the range ready announced.
    for (const double iso :
         {std::nextafter(ready.value_max, 1e300), std::nextafter(ready.value_min, -1e300)}) {
        e = error_for_request(server.port(), drawable_request(iso));
        EXPECT_NE(e.text.find("view.iso"), std::string::npos) << iso << ": " << e.text;
    }
    expect_draws_next(server.port());
}

TEST(RemoteServerErrors, AnUndrawableFrustumGetsAnErrorNamingTheField) {
    TestServer server;
    const struct {
        const char* field;
        void (*spoil)(Frustum&);
    } cases[] = {
        {"view.frustum.left", [](Frustum& f) { f.left = -1e38f; }},
        {"view.frustum.far_z", [](Frustum& f) { f.far_z = 1e38f; }},
        {"view.frustum.right", [](Frustum& f) { f.right = f.left; }},
        {"view.frustum.top", [](Frustum& f) { std::swap(f.top, f.bottom); }},
        {"view.frustum.near_z", [](Frustum& f) { f.near_z = 0; }},
        {"view.frustum.far_z", [](Frustum& f) { f.far_z = f.near_z; }},
    };
    for (const auto& c : cases) {
        RequestMsg r = drawable_request();
        c.spoil(r.view.frustum);
        const ErrorMsg e = error_for_request(server.port(), r);
        EXPECT_EQ(e.code, ErrorCode::malformed) << c.field;
        EXPECT_NE(e.text.find(c.field), std::string::npos) << c.field << ": " << e.text;
    }
    expect_draws_next(server.port());
}

TEST(RemoteServerErrors, AnAddressOtherThanLoopbackNeedsAToken) {
    ServerOptions o;
    o.address = "0.0.0.0";
    o.port = 0;
    std::vector<Dataset> ds;
    ds.push_back(phantom_dataset());
    EXPECT_THROW(ViewServer(std::move(ds), o), InputError);
}

TEST(RemoteServerErrors, WithoutATokenALoopbackServerServes) {
    TestServer server;
    expect_serves_next(server.port());
}

}  // namespace
}  // namespace isowall::test
