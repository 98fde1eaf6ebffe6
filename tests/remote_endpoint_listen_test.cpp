// Where `isowall serve` listens (--listen) in the endpoint form `isowall view --connect` takes.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "remote/net/endpoint.h"

namespace isowall::remote {
namespace {

void expect_listen(const char* text, const std::string& host, int port) {
    const Endpoint e = parse_listen_endpoint(text, 7878, "--listen", "endpoint");
    EXPECT_EQ(e.host, host) << text;
    EXPECT_EQ(e.port, port) << text;
}

TEST(ListenEndpoint, TakesTheConnectFormAndAPortOfZero) {
    expect_listen("127.0.0.1:7991", "127.0.0.1", 7991);
    expect_listen("localhost:1", "localhost", 1);
    expect_listen("[::1]:7991", "::1", 7991);
    expect_listen("127.0.0.1:0", "127.0.0.1", 0);
    expect_listen("[::1]:0", "::1", 0);
    // The same text means the same host and port to view --connect.
    const Endpoint c = parse_endpoint("127.0.0.1:7991", "--connect", "endpoint");
    const Endpoint l = parse_listen_endpoint("127.0.0.1:7991", 7878, "--listen", "endpoint");
    EXPECT_EQ(c.host, l.host);
    EXPECT_EQ(c.port, l.port);
}

TEST(ListenEndpoint, AHostAloneTakesTheDefaultPort) {
    expect_listen("127.0.0.1", "127.0.0.1", 7878);
    expect_listen("0.0.0.0", "0.0.0.0", 7878);
    expect_listen("::1", "::1", 7878);
    expect_listen("[::1]", "::1", 7878);
    expect_listen("localhost", "localhost", 7878);
}

TEST(ListenEndpoint, EachBadOneNamesListen) {
    for (const char* bad : {"", "127.0.0.1:70000", "127.0.0.1:", "127.0.0.1:x", ":7991", "[::1",
                            "[::1]7991", "a b:1", "host/x"}) {
        try {
            parse_listen_endpoint(bad, 7878, "--listen", "endpoint");
            ADD_FAILURE() << "no error for \"" << bad << "\"";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("--listen"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace isowall::remote
