// `isowall serve --http` on the command line: a port out of range, a port in use and
// a non-loopback address without a token each end the program with one line.
#include <gtest/gtest.h>

#include "remote/net/socket.h"
#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

using test::expect_one_line_error;
using test::run_isowall;

TEST(CliServeHttp, APortOutOfRangeIsOneLine) {
    const auto dir = test::scratch_dir("cli_serve_http_range");
    expect_one_line_error(run_isowall(dir, "serve --http 70000"), {"--http", "70000"});
    expect_one_line_error(run_isowall(dir, "serve --http -1"), {"--http"});
    expect_one_line_error(run_isowall(dir, "serve --http web"), {"--http", "web"});
}

TEST(CliServeHttp, APortInUseNamesHttpAndEndsTheServer) {
    const auto dir = test::scratch_dir("cli_serve_http_in_use");
    remote::Listener taken = remote::Listener::open("127.0.0.1", 0);
    const test::RunResult r =
        run_isowall(dir, "serve --port 0 --http " + std::to_string(taken.port()));
    expect_one_line_error(r, {"--http", std::to_string(taken.port())});
    EXPECT_EQ(r.exit_code, 1) << r.err;
}

TEST(CliServeHttp, ANonLoopbackAddressNeedsAToken) {
    const auto dir = test::scratch_dir("cli_serve_http_token");
    const test::RunResult r = run_isowall(dir, "serve --listen 0.0.0.0 --port 0 --http 0");
    expect_one_line_error(r, {"--listen", "--token"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
}

}  // namespace
}  // namespace isowall
