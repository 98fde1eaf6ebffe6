// The number rule end to end: the brief's reproductions, and errors that stay one bounded line.
#include <gtest/gtest.h>

#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

using test::expect_one_line_error;
using test::files_in;
using test::run_isowall;

TEST(CliNumbers, TheCameraRefusesADegenerateZoom) {
    const auto dir = test::scratch_dir("cli_zoom");
    // The brief's reproductions: each was a black image and exit 0.
    expect_one_line_error(run_isowall(dir, "render --size 64x48 --zoom 1e-300 -o x.png"),
                          {"--zoom", "1e-300"});
    expect_one_line_error(run_isowall(dir, "render --size 64x48 --orbit 1e300 0 -o x.png"),
                          {"--orbit", "1e300"});
    // In range, but the eye lands on the target at float precision.
    expect_one_line_error(run_isowall(dir, "render --size 64x48 --zoom 1e6 -o x.png"),
                          {"--zoom", "apart"});
    EXPECT_TRUE(files_in(dir).empty());
    // An orbit far past one turn is the same view as its remainder.
    ASSERT_EQ(
        run_isowall(dir, "render --size 64x48 -q --no-measure --orbit 720.5 0 -o a.png").exit_code,
        0);
    ASSERT_EQ(
        run_isowall(dir, "render --size 64x48 -q --no-measure --orbit 0.5 0 -o b.png").exit_code,
        0);
    EXPECT_EQ(test::slurp(dir / "a.png"), test::slurp(dir / "b.png"));
}

TEST(CliNumbers, ErrorsAreOneBoundedLine) {
    const auto dir = test::scratch_dir("cli_bounded");
    const std::string huge(100000, '9');  // under the kernel's 128 KiB per argument
    for (const std::string& args : std::vector<std::string>{
             "render --size " + huge, "render --order " + huge, "render --zoom " + huge,
             "render --" + huge, "render --size \"$(printf '64x48\\n\\033[2J')\""}) {
        const auto e = run_isowall(dir, args);
        expect_one_line_error(e, {});
        EXPECT_LT(e.err.size(), 1000u) << args.substr(0, 40);
        EXPECT_EQ(e.err.find('\x1b'), std::string::npos) << e.err;
    }
    EXPECT_TRUE(files_in(dir).empty());
}

}  // namespace
}  // namespace isowall
