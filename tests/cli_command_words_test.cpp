// The command line names what it did not understand: an unknown subcommand, an unknown option,
// and a server port given twice; serve --listen takes view --connect's HOST:PORT.
#include <gtest/gtest.h>

#include <string>

#include "remote/net/socket.h"
#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

using test::expect_one_line_error;
using test::run_isowall;

TEST(CliWords, AnUnknownSubcommandNamesItselfAndTheSubcommands) {
    const auto dir = test::scratch_dir("cli_words_subcommand");
    const test::RunResult r = run_isowall(dir, "frobnicate");
    expect_one_line_error(r, {"frobnicate", "render", "wall", "serve", "view"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    expect_one_line_error(run_isowall(dir, "rendr --size 10x10"), {"rendr"});
}

TEST(CliWords, AnUnknownOptionNamesItself) {
    const auto dir = test::scratch_dir("cli_words_option");
    expect_one_line_error(run_isowall(dir, "serve --frobnicate 1"), {"--frobnicate"});
    expect_one_line_error(run_isowall(dir, "view --frobnicate"), {"--frobnicate"});
}

TEST(CliWords, ServeListensWhereListenSaysInTheConnectForm) {
    // A port in use, named in --listen as view --connect names one: the server tries that port.
    const auto dir = test::scratch_dir("cli_words_listen");
    remote::Listener taken = remote::Listener::open("127.0.0.1", 0);
    const std::string port = std::to_string(taken.port());
    const test::RunResult r = run_isowall(dir, "serve --listen 127.0.0.1:" + port);
    expect_one_line_error(r, {port});
    EXPECT_EQ(r.exit_code, 1) << r.err;
}

TEST(CliWords, APortInListenAndInPortIsOneLine) {
    const auto dir = test::scratch_dir("cli_words_port_twice");
    expect_one_line_error(run_isowall(dir, "serve --listen 127.0.0.1:7991 --port 7992"),
                          {"--port", "--listen", "twice"});
    expect_one_line_error(run_isowall(dir, "serve --listen 127.0.0.1:70000"), {"--listen"});
}

}  // namespace
}  // namespace isowall
