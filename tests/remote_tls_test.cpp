// Remote viewing over TLS, in process on loopback: the image over TLS equals the local
// one; a plain client on a TLS port, a TLS client on a plain port, an untrusted certificate and
// one for another host each fail with one line that says so; bad certificate files name the file
// and the option; framed connections over TLS carry large messages and wake on shutdown.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "core/error.h"
#include "remote/net/connection.h"
#include "remote/net/tls.h"
#include "remote/view_client.h"
#include "tests/remote_protocol_test_util.h"
#include "tests/remote_view_util.h"
#include "tests/tls_test_util.h"

namespace isowall::test {
namespace {

using namespace remote;

constexpr int kTlsW = 200, kTlsH = 150;

// A certificate for localhost and 127.0.0.1, made once per process. CTest runs each test in a
// process of its own, two at once: a folder shared by all of them let one process remake the
// certificate between another's server loading it and its client trusting it.
const TestCert& server_cert() {
    static const TestCert c = make_test_cert(
        scratch_dir("tls_server_cert_" + std::to_string(::getpid())), "isowall-test");
    return c;
}

std::shared_ptr<const TlsContext> server_tls() {
    return std::make_shared<const TlsContext>(
        TlsContext::server(server_cert().cert, server_cert().key));
}

ServerOptions tls_options() {
    ServerOptions o;
    o.tls = server_tls();
    return o;
}

ClientHello tls_hello(int port, const std::string& ca, const std::string& host = "127.0.0.1") {
    ClientHello h;
    h.host = host;
    h.port = port;
    h.connect_timeout_s = 20;
    h.tls = std::make_shared<const TlsContext>(TlsContext::client(ca));
    return h;
}

// The text of what `f` throws as E ("" when it throws nothing).
template <class E, class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const E& e) {
        return e.what();
    }
    return "";
}

void expect_words(const std::string& text, std::initializer_list<const char*> words) {
    EXPECT_FALSE(text.empty()) << "no error";
    EXPECT_EQ(text.find('\n'), std::string::npos) << text;
    for (const char* w : words) EXPECT_NE(text.find(w), std::string::npos) << w << " in: " << text;
}

TEST(RemoteTls, TheViewOverTlsEndsWithTheLocalImage) {
    TestServer server(tls_options());
    const FrameView view = phantom_view(kTlsW, kTlsH, 20);
    auto renderer = make_renderer("osmesa");
    ViewClient client(*renderer, tls_hello(server.port(), server_cert().cert));
    client.request(view, remote::LodSchedule::on, true);
    const ClientFrameResult& r = client.wait_done(60);
    ASSERT_TRUE(r.completed);
    expect_same_image(r.final_image, local_image(view), "over TLS");
    // Every byte travelled inside TLS records, so the client got more than the frame's bytes.
    EXPECT_GT(client.bytes_received(), 0u);
    client.close();
}

TEST(RemoteTls, APlainClientOnATlsPortHearsInPlainTextThatThePortSpeaksTls) {
    TestServer server(tls_options());
    auto renderer = make_renderer("osmesa");
    ClientHello h;
    h.port = server.port();
    const std::string e = error_of<RemoteError>([&] { ViewClient c(*renderer, h); });
    expect_words(e, {"TLS", "--tls"});
}

TEST(RemoteTls, ATlsClientOnAPlainPortSaysTheServerDoesNotAnswerInTls) {
    TestServer server;
    auto renderer = make_renderer("osmesa");
    const std::string e = error_of<TlsHandshakeError>(
        [&] { ViewClient c(*renderer, tls_hello(server.port(), server_cert().cert)); });
    expect_words(e, {"127.0.0.1", "TLS", "plain port"});
}

TEST(RemoteTls, ACertificateTheClientDoesNotTrustOrForAnotherHostIsRefused) {
    TestServer server(tls_options());
    auto renderer = make_renderer("osmesa");
    // Trusting another self-signed certificate only.
    const TestCert other = make_test_cert(scratch_dir("tls_other_ca"), "other");
    const std::string untrusted = error_of<TlsHandshakeError>(
        [&] { ViewClient c(*renderer, tls_hello(server.port(), other.cert)); });
    expect_words(untrusted, {"not trusted", "--tls-ca"});
    // The system's authorities do not know a self-signed certificate either.
    const std::string system =
        error_of<TlsHandshakeError>([&] { ViewClient c(*renderer, tls_hello(server.port(), "")); });
    expect_words(system, {"not trusted"});
    // Trusted, but it names localhost and 127.0.0.1 only.
    const TestCert named = make_test_cert(scratch_dir("tls_named"), "named", "DNS:localhost");
    TestServer named_server([&] {
        ServerOptions o;
        o.tls = std::make_shared<const TlsContext>(TlsContext::server(named.cert, named.key));
        return o;
    }());
    const std::string host = error_of<TlsHandshakeError>(
        [&] { ViewClient c(*renderer, tls_hello(named_server.port(), named.cert)); });
    expect_words(host, {"does not name 127.0.0.1"});
    // ... and by that name it is accepted.
    ViewClient ok(*renderer, tls_hello(named_server.port(), named.cert, "localhost"));
    ok.close();
}

// The one seat is taken by an idle client: it gives the seat to the newcomer and hears why, in
// TLS.
TEST(RemoteTls, AClientThatYieldsItsSeatHearsWhyOverTls) {
    ServerOptions o = tls_options();
    o.max_clients = 1;
    TestServer server(o);
    auto renderer = make_renderer("osmesa");
    ViewClient first(*renderer, tls_hello(server.port(), server_cert().cert));
    ViewClient second(*renderer, tls_hello(server.port(), server_cert().cert));
    const std::string e = error_of<RemoteError>([&] { first.next_frame(60); });
    expect_words(e, {"--max-clients", "idle the longest"});
    second.close();
}

// A client that starts a handshake and stalls holds its slot only until the hello's limit (5 s
// in TestServer), and never the accept loop: another client is served meanwhile.
TEST(RemoteTls, AStalledHandshakeEndsAtTheHelloLimitAndBlocksNoOne) {
    TestServer server(tls_options());
    Socket stalled = connect_tcp("127.0.0.1", server.port(), 5);
    const std::byte start[] = {std::byte{22}, std::byte{3}, std::byte{1}};
    send_all(stalled, start, "stalled");
    auto renderer = make_renderer("osmesa");
    ViewClient other(*renderer, tls_hello(server.port(), server_cert().cert));
    other.close();
    std::array<std::byte, 64> buf{};
    std::size_t got = 0;
    const auto t0 = std::chrono::steady_clock::now();
    bool closed = false;
    try {
        while (recv_some(stalled, buf, 30, got, "stalled")) {
        }
    } catch (const PeerClosed&) {
        closed = true;
    }
    const double waited =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_TRUE(closed) << "the server did not close the stalled connection within 30 s";
    EXPECT_LT(waited, 20) << "the stalled handshake was held past the hello's limit";
}

// The names a certificate carries are names its page may be reached by (the Host rule), beside
// the listen name, this machine's name and --allow-host.
TEST(RemoteTls, TheCertificatesNamesAreNamesThePageMayBeReachedBy) {
    const TestCert named =
        make_test_cert(scratch_dir("tls_page_names"), "page", "DNS:wall.test,DNS:node7.test");
    ServerOptions o;
    o.address = "wall-listen.test";
    o.allowed_hosts = {"proxy.test"};
    o.tls = std::make_shared<const TlsContext>(TlsContext::server(named.cert, named.key));
    const std::vector<std::string> names = served_host_names(o);
    for (const char* name : {"wall.test", "node7.test", "wall-listen.test", "proxy.test"})
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    EXPECT_EQ(TlsContext::client("").certificate_dns_names().size(), 0u);
}

TEST(RemoteTls, BadCertificateFilesNameTheFileAndTheOption) {
    const auto dir = scratch_dir("tls_bad_files");
    const TestCert a = make_test_cert(dir, "a"), b = make_test_cert(dir, "b");
    const std::string missing = (dir / "missing.pem").string();
    const std::string text = (dir / "text.pem").string();
    std::ofstream(text) << "not a certificate\n";
    auto server_error = [](const std::string& cert, const std::string& key) {
        return error_of<InputError>([&] { TlsContext::server(cert, key); });
    };
    expect_words(server_error(missing, a.key), {"missing.pem", "--tls-cert", "cannot read"});
    expect_words(server_error(a.cert, missing), {"missing.pem", "--tls-key", "cannot read"});
    expect_words(server_error(text, a.key), {"text.pem", "--tls-cert", "not a PEM certificate"});
    expect_words(server_error(a.cert, text), {"text.pem", "--tls-key", "not a PEM private key"});
    expect_words(server_error(a.cert, b.key), {"b.key", "--tls-key", "does not match", "a.crt"});
    expect_words(error_of<InputError>([&] { TlsContext::client(text); }), {"text.pem", "--tls-ca"});
    expect_words(error_of<InputError>([&] { TlsContext::client(missing); }),
                 {"missing.pem", "--tls-ca", "cannot read"});
    EXPECT_NO_THROW(TlsContext::server(a.cert, a.key));
}

TEST(RemoteTls, AnAddressOtherThanLoopbackNeedsTlsAndAToken) {
    ServerOptions o;
    o.address = "0.0.0.0";
    expect_words(exposure_problem(o, "listening"), {"0.0.0.0", "TLS", "--token"});
    o.token = "secret";
    expect_words(exposure_problem(o, "listening"), {"TLS", "--tls-cert"});
    o.tls = server_tls();
    EXPECT_EQ(exposure_problem(o, "listening"), "");
    o.token.clear();
    expect_words(exposure_problem(o, "listening"), {"--token"});
    o.address = "127.0.0.1";
    EXPECT_EQ(exposure_problem(o, "listening"), "");
    std::vector<Dataset> none;
    o.address = "0.0.0.0";
    o.port = 0;
    expect_words(error_of<InputError>([&] { ViewServer s(std::move(none), o); }), {"--listen"});
}

// A framed connection pair over TLS on loopback: the server's side accepted in a thread.
struct TlsPair {
    std::unique_ptr<Connection> server, client;
    TlsPair() {
        Listener l = Listener::open("127.0.0.1", 0);
        std::thread accept([&] {
            std::optional<Socket> s = l.accept(10);
            if (!s) return;
            server = std::make_unique<Connection>(std::move(*s), "client", 8u << 20);
            accept_tls(server->socket(), *server_tls(), "client", 10);
        });
        client = std::make_unique<Connection>(connect_tcp("127.0.0.1", l.port(), 10), "server",
                                              8u << 20);
        const auto ctx = TlsContext::client(server_cert().cert);
        connect_tls(client->socket(), ctx, "127.0.0.1", "server", 10);
        accept.join();
    }
};

TEST(RemoteTls, AFramedConnectionCarriesLargeMessagesBothWaysAndWakesOnShutdown) {
    TlsPair p;
    ASSERT_TRUE(p.server);
    EXPECT_NE(tls_description(p.client->socket()).find("TLS"), std::string::npos);
    // Two 4 MiB groups, echoed by the server: the client reads the first echo while its own
    // thread still writes the second, so one TLS session reads and writes at once.
    GroupMsg big = remote_testing::sample_group();
    big.encoded.assign(4u << 20, std::byte{7});
    big.encoded[12345] = std::byte{1};
    std::string echo_error, send_error;
    std::thread echo([&] {
        try {
            for (int i = 0; i < 2; ++i)
                if (auto m = p.server->receive(60)) p.server->send(*m);
        } catch (const std::exception& e) {
            echo_error = e.what();
        }
    });
    std::thread sender([&] {
        try {
            p.client->send(big);
            p.client->send(big);
        } catch (const std::exception& e) {
            send_error = e.what();
        }
    });
    for (int i = 0; i < 2; ++i) {
        auto got = p.client->receive(60);
        ASSERT_TRUE(got) << "echo " << i;
        EXPECT_EQ(*got, RemoteMessage(big)) << "echo " << i;
    }
    sender.join();
    echo.join();
    EXPECT_EQ(echo_error, "");
    EXPECT_EQ(send_error, "");
    // Nothing more comes: a receive with a timeout returns empty, and a blocked one wakes when
    // another thread shuts the connection down.
    EXPECT_FALSE(p.client->receive(0.05));
    std::atomic<bool> woke{false};
    std::thread reader([&] {
        try {
            p.client->receive(-1);
        } catch (const PeerClosed&) {
            woke = true;
        }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    p.client->shutdown();
    reader.join();
    EXPECT_TRUE(woke);
}

}  // namespace
}  // namespace isowall::test
