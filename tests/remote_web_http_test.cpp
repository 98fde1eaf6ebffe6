// `isowall serve --http`: the HTTP side. The routes as pure functions, then over
// loopback: the page, its content type, /datasets with and without a token, 404 and 405, and
// the WebSocket upgrade's Host, Origin and path rules.
#include <cctype>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "remote/http/web_routes.h"
#include "remote/http/web_server.h"
#include "remote/net/socket.h"
#include "tests/remote_web_util.h"

namespace isowall::test {

HttpReply http_exchange(int port, const std::string& request_head, double timeout_s) {
    remote::Socket s = remote::connect_tcp("127.0.0.1", port, timeout_s);
    const std::string request = request_head + "\r\n\r\n";
    remote::send_all(s, std::as_bytes(std::span(request.data(), request.size())), "server");
    std::string raw;
    std::array<std::byte, 4096> buf;
    try {
        for (;;) {
            std::size_t got = 0;
            if (!remote::recv_some(s, buf, timeout_s, got, "server")) break;
            raw.append(reinterpret_cast<const char*>(buf.data()), got);
        }
    } catch (const remote::PeerClosed&) {  // the end of the reply
    }
    HttpReply r;
    const std::size_t head_end = raw.find("\r\n\r\n");
    std::istringstream head(raw.substr(0, head_end));
    std::string line, version;
    std::getline(head, line);
    std::istringstream(line) >> version >> r.status;
    while (std::getline(head, line)) {
        const std::size_t colon = line.find(':');
        if (colon == std::string::npos) continue;
        std::string name = line.substr(0, colon), value = line.substr(colon + 1);
        for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        value.erase(0, value.find_first_not_of(' '));
        if (!value.empty() && value.back() == '\r') value.pop_back();
        r.headers[name] = value;
    }
    if (head_end != std::string::npos) r.body = raw.substr(head_end + 4);
    return r;
}

namespace {

using namespace remote;

std::string placeholder_page() {
    std::ifstream in(std::string(ISOWALL_SOURCE_DIR) + "/web/dist/index.html", std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(RemoteWebRoutes, ContentTypesQueriesAndJson) {
    EXPECT_EQ(content_type_for("index.html"), "text/html; charset=utf-8");
    EXPECT_EQ(content_type_for("app.js"), "text/javascript; charset=utf-8");
    EXPECT_EQ(content_type_for("app.css"), "text/css; charset=utf-8");
    EXPECT_EQ(content_type_for("a/b.png"), "image/png");
    EXPECT_EQ(content_type_for("icon.svg"), "image/svg+xml");
    EXPECT_EQ(content_type_for("app.js.map"), "application/json");
    EXPECT_EQ(content_type_for("x.json"), "application/json");
    EXPECT_EQ(content_type_for("README"), "application/octet-stream");
    EXPECT_EQ(content_type_for(".js"), "application/octet-stream");

    EXPECT_EQ(query_value("a=1&token=x%20y+z", "token"), "x y z");
    EXPECT_EQ(query_value("token=", "token"), "");
    EXPECT_EQ(query_value("tokens=1", "token"), std::nullopt);
    EXPECT_EQ(query_value("token=%4", "token"), std::nullopt);
    EXPECT_EQ(query_value("token=%zz", "token"), std::nullopt);
    EXPECT_EQ(query_value("", "token"), std::nullopt);

    EXPECT_EQ(datasets_json({"phantom", "head"}, false),
              R"({"datasets":["phantom","head"],"token_required":false})");
    EXPECT_EQ(datasets_json({}, true), R"({"datasets":[],"token_required":true})");
    EXPECT_EQ(datasets_json({"a\"b\\c\n"}, false),
              R"({"datasets":["a\"b\\c\u000a"],"token_required":false})");
}

TEST(RemoteWebRoutes, EveryRouteWithoutASocket) {
    const unsigned char js[] = {'x', '=', '1'};
    const WebAsset assets[] = {{"app.js", js}, {"index.html", js}};
    const RouteContext c{{"phantom"}, "sesame", assets};
    EXPECT_EQ(route({"GET", "/app.js", ""}, c).content_type, "text/javascript; charset=utf-8");
    EXPECT_EQ(route({"GET", "/", ""}, c).body, "x=1");
    EXPECT_EQ(route({"GET", "/index.html", ""}, c).status, 200);
    EXPECT_EQ(route({"GET", "/app.css", ""}, c).status, 404);
    EXPECT_EQ(route({"GET", "/../app.js", ""}, c).status, 404);
    EXPECT_EQ(route({"POST", "/", ""}, c).status, 405);
    EXPECT_EQ(route({"GET", "/datasets", ""}, c).status, 403);
    EXPECT_EQ(route({"GET", "/datasets", "token=sesam"}, c).status, 403);
    EXPECT_EQ(route({"GET", "/datasets", "token=sesame"}, c).status, 200);
}

TEST(RemoteWebHttp, ThePageItsTypeAndNoStore) {
    WebTestServer server;
    const std::string page = placeholder_page();
    ASSERT_FALSE(page.empty());
    for (const char* path : {"/", "/index.html"}) {
        HttpReply r = http_get(server.http_port(), path);
        EXPECT_EQ(r.status, 200) << path;
        EXPECT_EQ(r.headers["content-type"], "text/html; charset=utf-8") << path;
        EXPECT_EQ(r.headers["cache-control"], "no-store") << path;
        EXPECT_EQ(r.body, page) << path;
    }
    HttpReply missing = http_get(server.http_port(), "/no-such-file.js");
    EXPECT_EQ(missing.status, 404);
    EXPECT_EQ(missing.headers["cache-control"], "no-store");
    EXPECT_NE(missing.body.find("not found"), std::string::npos) << missing.body;
    const HttpReply post = http_exchange(server.http_port(),
                                         "POST / HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                                         "Connection: close\r\nContent-Length: 0");
    EXPECT_EQ(post.status, 405);
}

TEST(RemoteWebHttp, DatasetsWithAndWithoutAToken) {
    {
        WebTestServer open_server;
        HttpReply r = http_get(open_server.http_port(), "/datasets");
        EXPECT_EQ(r.status, 200);
        EXPECT_EQ(r.headers["content-type"], "application/json");
        EXPECT_EQ(r.body, R"({"datasets":["phantom"],"token_required":false})");
    }
    ServerOptions o;
    o.token = "open sesame";
    WebTestServer server(o);
    for (const char* path : {"/datasets", "/datasets?token=", "/datasets?token=open%20sesam"}) {
        HttpReply r = http_get(server.http_port(), path);
        EXPECT_EQ(r.status, 403) << path;
        EXPECT_EQ(r.headers["content-type"], "application/json") << path;
        EXPECT_EQ(r.body, R"({"error":"wrong token"})") << path;
    }
    HttpReply r = http_get(server.http_port(), "/datasets?token=open%20sesame");
    EXPECT_EQ(r.status, 200);
    EXPECT_EQ(r.body, R"({"datasets":["phantom"],"token_required":true})");
}

// A WebSocket handshake by hand, to see the status of a refused one.
int upgrade_status(int port, const std::string& path, const std::string& origin,
                   const std::string& host = "") {
    std::string head = "GET " + path + " HTTP/1.1\r\nHost: " +
                       (host.empty() ? "127.0.0.1:" + std::to_string(port) : host) +
                       "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                       "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13";
    if (!origin.empty()) head += "\r\nOrigin: " + origin;
    return http_exchange(port, head, 1).status;  // a 101 stays open: read for 1 s
}

TEST(RemoteWebHttp, UpgradesOnlyAtWsFromTheSameOrigin) {
    WebTestServer server;
    const int port = server.http_port();
    const std::string self = "http://127.0.0.1:" + std::to_string(port);
    EXPECT_EQ(upgrade_status(port, "/ws", ""), 101);
    EXPECT_EQ(upgrade_status(port, "/ws", self), 101);
    EXPECT_EQ(upgrade_status(port, "/ws", "http://evil.example"), 403);
    EXPECT_EQ(upgrade_status(port, "/ws", "https://127.0.0.1:" + std::to_string(port)), 403);
    EXPECT_EQ(upgrade_status(port, "/other", self), 404);
    EXPECT_EQ(upgrade_status(port, "/", ""), 404);
}

// Over TLS the page's origin is https://<Host>, and only that one.
TEST(RemoteWebHttp, OverTlsTheSameOriginIsHttps) {
    EXPECT_TRUE(web::origin_allowed("https://127.0.0.1:8443", "127.0.0.1:8443", true));
    EXPECT_FALSE(web::origin_allowed("http://127.0.0.1:8443", "127.0.0.1:8443", true));
    EXPECT_TRUE(web::origin_allowed("", "127.0.0.1:8443", true));
    EXPECT_FALSE(web::origin_allowed("https://evil.example", "127.0.0.1:8443", true));
    EXPECT_FALSE(web::origin_allowed("https://127.0.0.1:8443", "", true));
    EXPECT_FALSE(web::origin_allowed("https://127.0.0.1:8443", "127.0.0.1:8443", false));
}

// DNS rebinding: a page of evil.example whose name now resolves to this server sends
// Host: evil.example:PORT, and its own Origin, which then matches that Host. Every request by a
// name the server does not serve is refused, plain or upgrade, before any route answers.
TEST(RemoteWebHttp, APageReachingTheServerByAForeignNameIsRefused) {
    remote::ServerOptions o;
    o.allowed_hosts = {"wall.example.org"};
    WebTestServer server(o);
    const int port = server.http_port();
    const std::string p = ":" + std::to_string(port);
    const auto get = [&](const std::string& host) {
        return http_exchange(port,
                             "GET /datasets HTTP/1.1\r\nHost: " + host + "\r\nConnection: close");
    };
    const HttpReply evil = get("evil.example" + p);
    EXPECT_EQ(evil.status, 403);
    EXPECT_NE(evil.body.find("Host evil.example"), std::string::npos) << evil.body;
    EXPECT_NE(evil.body.find("--allow-host"), std::string::npos) << evil.body;
    EXPECT_EQ(evil.body.find("phantom"), std::string::npos) << "the dataset list went out";
    EXPECT_EQ(upgrade_status(port, "/ws", "http://evil.example" + p, "evil.example" + p), 403);
    EXPECT_EQ(get("localhost" + p).status, 200);
    EXPECT_EQ(get("WALL.example.org" + p).status, 200);
    EXPECT_EQ(get("127.0.0.1" + p).status, 200);
}

TEST(RemoteWebHttp, TheHostRuleTakesAddressesLocalhostAndServedNamesOnly) {
    const std::vector<std::string> names = {"wall.example.org", "Node7."};
    for (const char* ok :
         {"127.0.0.1:8080", "10.1.2.3", "[::1]:8080", "[fe80::1]", "localhost", "LocalHost:80",
          "page.localhost:80", "wall.example.org:443", "wall.example.org.", "node7:80", "NODE7"})
        EXPECT_TRUE(web::host_allowed(ok, names)) << ok;
    for (const char* refused :
         {"", "evil.example", "evil.example:8080", "wall.example.org.evil.example",
          "localhost.evil", "127.0.0.1.evil.example", "[::1", "[evil]:80", "[::1]x",
          "wall.example.org:80x", ":80", "node7:80:80"})
        EXPECT_FALSE(web::host_allowed(refused, names)) << refused;
}

TEST(RemoteWebHttp, APortInUseNamesHttp) {
    WebTestServer server;
    TestServer other;
    try {
        HttpFrontEnd second(other.server(), server.http_port());
        FAIL() << "a second front end listened on a port in use";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--http"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace isowall::test
