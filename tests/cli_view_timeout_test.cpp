// `view --timeout` covers the connection's start too: a server that accepts and never answers
// the hello ends the client after --timeout seconds (once a fixed 10 s whatever --timeout said).
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "core/util.h"
#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

TEST(CliView, AServerThatNeverAnswersTheHelloEndsTheClientAfterTimeout) {
    const auto dir = test::scratch_dir("cli_view_timeout");
    // A listener that accepts one connection and says nothing for a minute.
    std::ofstream(dir / "mute.py") << "import socket, sys, time\n"
                                      "s = socket.socket()\n"
                                      "s.bind(('127.0.0.1', 0))\n"
                                      "s.listen()\n"
                                      "open(sys.argv[1], 'w').write(str(s.getsockname()[1]))\n"
                                      "c, _ = s.accept()\n"
                                      "time.sleep(60)\n";
    const auto port_file = dir / "port.txt";
    std::filesystem::remove(port_file);
    const std::string start = "timeout 90 /usr/bin/python3 '" + (dir / "mute.py").string() + "' '" +
                              port_file.string() + "' & echo $! > '" + (dir / "pid.txt").string() +
                              "'";
    ASSERT_EQ(std::system(start.c_str()), 0);
    std::string port;
    for (int i = 0; i < 200 && port.empty(); ++i) {
        port = test::slurp(port_file);
        if (port.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_FALSE(port.empty()) << "the listener did not start";
    Stopwatch took;
    const test::RunResult r =
        test::run_isowall(dir, "view --connect 127.0.0.1:" + port + " --timeout 1 --out v.png");
    const double seconds = took.seconds();
    std::system(("kill $(cat '" + (dir / "pid.txt").string() + "') 2>/dev/null").c_str());
    test::expect_one_line_error(r, {"no answer to hello within 1"});
    // Bounded by --timeout, not by the old fixed 10 s (a loaded machine adds a few seconds).
    EXPECT_LT(seconds, 8.0) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "v.png"));
}

}  // namespace
}  // namespace isowall
