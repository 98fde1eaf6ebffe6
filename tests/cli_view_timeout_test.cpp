// `view --timeout` covers the connection's start too: a server that accepts and never answers
// the hello ends the client after --timeout seconds (once a fixed 10 s whatever --timeout said).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

TEST(CliView, AServerThatNeverAnswersTheHelloEndsTheClientAfterTimeout) {
    const auto dir = test::scratch_dir("cli_view_timeout");
    // A listener that never accepts: the kernel completes the client's connection into its
    // backlog, and nothing is ever said on it.
    const int s = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    ASSERT_GE(s, 0);
    sockaddr_in at{};
    at.sin_family = AF_INET;
    at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof at;
    ASSERT_EQ(::bind(s, reinterpret_cast<sockaddr*>(&at), sizeof at), 0);
    ASSERT_EQ(::listen(s, 4), 0);
    ASSERT_EQ(::getsockname(s, reinterpret_cast<sockaddr*>(&at), &len), 0);
    const std::string port = std::to_string(ntohs(at.sin_port));
    const test::RunResult r =
        test::run_isowall(dir, "view --connect 127.0.0.1:" + port + " --timeout 1 --out v.png");
    ::close(s);
    // The line names the limit that ended it: --timeout's 1 s, not the old fixed 10 s.
    test::expect_one_line_error(r, {"no answer to hello within 1"});
    EXPECT_FALSE(std::filesystem::exists(dir / "v.png"));
}

}  // namespace
}  // namespace isowall
