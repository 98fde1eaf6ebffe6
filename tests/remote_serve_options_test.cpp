// `isowall serve --idle-timeout` ("Nothing lies, nothing hangs, round two", class 4) goes through
// the number rules of every other option (core/number.h): CLI11 refuses a non-finite or
// out-of-range value naming the option and the value, and a good one reaches the ServeCommand.
#include <sstream>

#include <gtest/gtest.h>

#include "app/program_cli.h"
#include "tests/cli_parse_util.h"

namespace isowall {
namespace {

using test::parse_error;

TEST(ServeOptions, IdleTimeoutRefusesNonFiniteAndOutOfRangeValues) {
    for (const std::string bad : {"nan", "inf", "1e999", "0x10", "5abc", "0", "-5", "1e7"}) {
        ProgramCli cli;
        const std::string e = parse_error(cli, "serve --idle-timeout " + bad);
        EXPECT_NE(e.find("--idle-timeout"), std::string::npos) << bad << ": " << e;
        EXPECT_NE(e.find(bad), std::string::npos) << bad << ": " << e;
    }
}

// serve's max count is remote viewing's own; every other engine default is the engine's, and
// --max-count still sets it.
TEST(ServeOptions, TheMaxCountIsRemoteViewingsOwn) {
    {
        ProgramCli cli;
        EXPECT_EQ(parse_error(cli, "serve"), "");
        EXPECT_EQ(cli.serve.engine.max_count, kServeMaxCount);
        EXPECT_EQ(to_engine_options(cli.serve.engine).propagation.max_count, kServeMaxCount);
        EXPECT_EQ(to_engine_options(cli.serve.engine).order, EngineOptions{}.order);
    }
    ProgramCli cli;
    EXPECT_EQ(parse_error(cli, "serve --max-count 700"), "");
    EXPECT_EQ(cli.serve.engine.max_count, 700);
}

TEST(ServeOptions, IdleTimeoutReachesTheServeCommand) {
    {
        ProgramCli cli;
        EXPECT_EQ(parse_error(cli, "serve"), "");
        EXPECT_EQ(cli.serve.idle_timeout_s, 300);
    }
    for (const double s : {0.5, 1e6}) {
        ProgramCli cli;
        std::ostringstream args;
        args << "serve --idle-timeout " << s;
        EXPECT_EQ(parse_error(cli, args.str()), "") << args.str();
        EXPECT_EQ(cli.serve.idle_timeout_s, s);
    }
}

}  // namespace
}  // namespace isowall
