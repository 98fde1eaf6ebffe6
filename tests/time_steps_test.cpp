// Numbered files as a time series (volume/time_steps.h): the steps in order from the lowest
// number, padded or not, and every way a pattern can name no series as one line naming the file.
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "tests/test_util.h"
#include "volume/time_steps.h"

namespace isowall {
namespace {

void touch(const std::filesystem::path& p) {
    std::ofstream(p) << "x";
}

std::string error_of(const std::string& pattern) {
    try {
        find_series(pattern, "--volume");
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no error for " << pattern;
    return {};
}

TEST(TimeSteps, PatternsAreTold) {
    EXPECT_TRUE(is_series_pattern("run/t_%03d.nrrd"));
    EXPECT_TRUE(is_series_pattern("t%d.nii.gz"));
    EXPECT_FALSE(is_series_pattern("head.nrrd"));
    EXPECT_FALSE(is_series_pattern("100%.nrrd"));
    EXPECT_FALSE(is_series_pattern("a%20b.nrrd"));  // a URL's escape, not a number
    EXPECT_FALSE(is_series_pattern("t_%s.nrrd"));
}

TEST(TimeSteps, StepsRunFromTheLowestNumberInOrder) {
    const auto dir = test::scratch_dir("time_steps_order");
    for (int n : {1, 2, 3, 10, 9, 8, 7, 6, 5, 4}) {
        char name[32];
        std::snprintf(name, sizeof(name), "t_%03d.nrrd", n);
        touch(dir / name);
    }
    touch(dir / "t_abc.nrrd");  // not a number: not a step
    touch(dir / "other_001.nrrd");
    const TimeSeries s = find_series((dir / "t_%03d.nrrd").string(), "--volume");
    EXPECT_EQ(s.first, 1);
    ASSERT_EQ(s.steps.size(), 10u);
    EXPECT_EQ(s.steps[0].filename(), "t_001.nrrd");
    EXPECT_EQ(s.steps[9].filename(), "t_010.nrrd");
    // Unpadded numbers, found by %d as well.
    const auto plain = test::scratch_dir("time_steps_plain");
    for (int n = 0; n < 12; ++n) {
        char name[32];
        std::snprintf(name, sizeof(name), "v%d.nii", n);
        touch(plain / name);
    }
    const TimeSeries p = find_series((plain / "v%d.nii").string(), "--volume");
    ASSERT_EQ(p.steps.size(), 12u);
    EXPECT_EQ(p.steps[11].filename(), "v11.nii");
}

TEST(TimeSteps, AGapOrNothingIsOneLineNamingTheFile) {
    const auto dir = test::scratch_dir("time_steps_gap");
    for (int n : {0, 1, 2, 4}) touch(dir / ("s_" + std::to_string(n) + ".nrrd"));
    const std::string gap = error_of((dir / "s_%d.nrrd").string());
    EXPECT_NE(gap.find("s_3.nrrd"), std::string::npos) << gap;
    EXPECT_NE(gap.find("time step 3 is missing (files 0 to 4 found)"), std::string::npos) << gap;
    EXPECT_NE(error_of((dir / "none_%d.nrrd").string()).find("no file matches"), std::string::npos);
    EXPECT_NE(error_of((dir / "s_%d_%d.nrrd").string()).find("found more"), std::string::npos);
    EXPECT_NE(error_of((dir / "missing_folder/s_%d.nrrd").string()).find("cannot list"),
              std::string::npos);
    EXPECT_EQ(gap.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace isowall
