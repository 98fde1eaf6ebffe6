// Every number option of every subcommand, against every class of hostile value, parsed in
// process: CLI11 refuses it naming the option and the value (main prints that as one line, exit
// 2), so no value reaches the program to make a black image with exit 0.
#include <gtest/gtest.h>

#include <sstream>

#include "app/program_cli.h"
#include "tests/cli_parse_util.h"

namespace isowall {
namespace {

struct CliSlot {
    std::string args;                 // with {} where the value goes
    std::string option;               // the option the error names
    std::vector<std::string> beyond;  // finite values outside the option's range
};

const std::vector<std::string> kTimeouts = {"0", "-5", "1e7", "1e300"};
const std::vector<CliSlot> kCliSlots = {
    {"render --iso {}", "--iso", {}},  // any finite isovalue: the volume's range decides
    {"render --orbit {} 0", "--orbit", {"1e300", "-1e300", "1000001"}},
    {"render --orbit 0 {}", "--orbit", {"1e300", "-1000001"}},
    {"render --zoom {}", "--zoom", {"0", "-5", "1e-7", "1e7", "1e300", "1e-300"}},
    {"render --max-count {}", "--max-count", {"0", "-5", "2.5", "1e300", "2147483648"}},
    {"render --cutoff-angle {}", "--cutoff-angle", {"0", "-5", "181", "1e300"}},
    {"render --foldback-tolerance {}", "--foldback-tolerance", {"-5", "181", "1e300"}},
    {"render --adaptive-max-level {}", "--adaptive-max-level", {"0", "4", "-5", "2.5"}},
    {"render --adaptive-pixels {}", "--adaptive-pixels", {"0", "-5", "64.5", "1e300"}},
    {"render --footprint-pixels {}", "--footprint-pixels", {"-0.5", "-5", "64.5", "1e300"}},
    {"render --snapshots 90,{}", "--snapshots", {"0", "-5", "100.5", "1e300"}},
    {"render --snapshot-rays 100,{}", "--snapshot-rays", {"-5", "2.5", "1e16", "1e300"}},
    {"render --spacing 1 {} 1", "--spacing", {"0", "-5", "1e300", "1e-300"}},
    {"render --dims 4 {} 4", "--dims", {"0", "-5", "2.5", "2147483648"}},
    {"render --header-bytes {}", "--header-bytes", {"-5", "2.5", "1e300"}},
    {"render --http-timeout {}", "--http-timeout", {"0", "-5", "0.05", "3601", "1e300"}},
    {"render --http-connections {}", "--http-connections", {"0", "-1", "65", "2.5", "1e300"}},
    {"render --time {}", "--time", {"-1", "2.5", "100000", "1e300"}},
    {"render --iso 40:skin:{}", "--iso", {"1.5", "-0.1", "1e300"}},
    {"extract --iso {} --out s.ply", "--iso", {}},
    {"wall --wall w.toml --iso {}", "--iso", {}},
    {"wall --wall w.toml --orbit 0 {}", "--orbit", {"1e300"}},
    {"wall --wall w.toml --zoom {}", "--zoom", {"0", "1e7"}},
    {"wall --wall w.toml --pan {} 0", "--pan", {"1001", "-1e300"}},
    {"wall --wall w.toml --timeout {}", "--timeout", kTimeouts},
    {"wall --wall w.toml --startup-timeout {}", "--startup-timeout", kTimeouts},
    {"wall --wall w.toml --threads {}", "--threads", {"-5", "1025", "2.5"}},
    {"wall --wall w.toml --emulate-cores {}", "--emulate-cores", {"-1", "4097", "1.5", "x"}},
};

std::string cli_fill(const std::string& slot, const std::string& value) {
    std::string args = slot;
    return args.replace(args.find("{}"), 2, value);
}

using test::parse_error;

TEST(CliNumbers, EveryNumberOptionRefusesNonFiniteAndOutOfRangeValues) {
    int tried = 0;
    for (const CliSlot& s : kCliSlots) {
        std::vector<std::string> bad = {"nan", "-nan", "inf", "-inf", "1e999", "0x10", "5abc"};
        bad.insert(bad.end(), s.beyond.begin(), s.beyond.end());
        for (const std::string& b : bad) {
            const std::string e = parse_error(cli_fill(s.args, b));
            SCOPED_TRACE(cli_fill(s.args, b));
            EXPECT_NE(e.find(s.option), std::string::npos) << e;
            // CLI11 takes "-nan" and "-inf" for options, not values: refused all the same.
            if (b != "-nan" && b != "-inf") {
                EXPECT_NE(e.find(b), std::string::npos) << e;
            }
            ++tried;
        }
    }
    EXPECT_GT(tried, 200);
    // The good values of the same slots parse.
    for (const char* ok :
         {"render --zoom 1e-6", "render --zoom 1e6", "render --orbit -1e6 1e6",
          "render --snapshots 0.001,100", "render --snapshot-rays 0,1e15",
          "wall --wall w.toml --pan -1000 1000", "wall --wall w.toml --threads 1024",
          "render --cutoff-angle 180 --foldback-tolerance 0"})
        EXPECT_EQ(parse_error(ok), "") << ok;
}

TEST(CliNumbers, IntegersReachTheProgramAsDecimal) {
    // CLI11 alone reads "010" as octal 8 and an unsigned "-5" as 2^64 - 5.
    ProgramCli cli;
    const char* argv[] = {"isowall", "render", "--max-count", "010", "--snapshot-rays", "1e3,+7"};
    cli.app.parse(6, argv);
    EXPECT_EQ(cli.re.engine.max_count, 10);
    EXPECT_EQ(cli.re.snapshot_rays, (std::vector<std::size_t>{1000, 7}));
}

}  // namespace
}  // namespace isowall
