// A time series on the wall (volume/time_steps.h), every rank a thread: `play` shows every step in
// turn and prints each step's figures, a step's mosaic is that of the step's file given alone, a
// step change mid-frame interrupts every tile as an isovalue change does, and bad steps are one
// line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "app/wall_run.h"
#include "comm/inproc_comm.h"
#include "files/image_io.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

constexpr int kBallSide = 32;
constexpr int kBallSteps = 8;

// Step t: a ball that moves along x as t grows (`side` voxels a side).
void write_ball_step(const std::filesystem::path& path, int t, int side = kBallSide) {
    std::string data(std::size_t(side) * side * side, '\0');
    for (int z = 0; z < side; ++z)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                const double d = std::hypot(x - (9.0 + 2 * t), y - 16.0, z - 16.0);
                data[(std::size_t(z) * side + y) * side + x] =
                    char(std::uint8_t(std::clamp(255.0 - 25.0 * d, 0.0, 255.0)));
            }
    std::ofstream(path, std::ios::binary) << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << side
                                          << " " << side << " " << side << "\nencoding: raw\n\n"
                                          << data;
}

std::filesystem::path write_ball_series(const std::string& name) {
    const auto dir = test::scratch_dir(name);
    for (int t = 0; t < kBallSteps; ++t) {
        char file[32];
        std::snprintf(file, sizeof(file), "ball_%02d.nrrd", t);
        write_ball_step(dir / file, t);
    }
    return dir;
}

WallOptions ball_wall(const std::filesystem::path& dir, const std::string& volume) {
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [80, 60]\n";
    WallOptions o;
    o.wall = (dir / "2x2.toml").string();
    o.out = (dir / "mosaic.png").string();
    o.volume.path = volume;
    o.volume.no_cache = true;
    o.iso = {"128"};
    return o;
}

struct SeriesRun {
    std::vector<int> codes;
    std::vector<TileResultMsg> results;
    std::string out, err;
};

SeriesRun run_series(WallOptions o) {
    SeriesRun r;
    o.results_out = &r.results;
    testing::internal::CaptureStdout();
    testing::internal::CaptureStderr();
    r.codes = run_in_process(5, [&](Comm& comm) { return run_wall(o, comm); });
    r.err = testing::internal::GetCapturedStderr();
    r.out = testing::internal::GetCapturedStdout();
    return r;
}

std::string script_file(const std::filesystem::path& dir, const std::string& text) {
    std::ofstream(dir / "script.txt") << text;
    return (dir / "script.txt").string();
}

// The mosaic of step `t`'s file given alone.
Image step_alone(const std::filesystem::path& series, int t) {
    const auto dir = test::scratch_dir("wall_time_alone_" + std::to_string(t));
    char file[32];
    std::snprintf(file, sizeof(file), "ball_%02d.nrrd", t);
    const SeriesRun r = run_series(ball_wall(dir, (series / file).string()));
    for (int code : r.codes) EXPECT_EQ(code, 0) << r.err;
    return read_image(dir / "mosaic.png");
}

void expect_same_picture(const Image& a, const Image& b, const char* what) {
    const test::ImageComparison c = test::compare_images(a, b);
    EXPECT_GE(c.mask_iou, 0.999) << what << ": " << c;
    EXPECT_GE(c.equal_share, 0.999) << what << ": " << c;
    EXPECT_GT(c.covered_both, 100u) << what << ": " << c;
}

TEST(WallTime, PlayShowsEveryStepInTurnAndEachStepIsItsFilesPicture) {
    const auto series = write_ball_series("wall_time_series");
    WallOptions o = ball_wall(series, (series / "ball_%02d.nrrd").string());
    o.script = script_file(series, "play\nwait done\nsnapshot last\ntime 2\nwait done\n");
    const SeriesRun r = run_series(o);
    for (int code : r.codes) ASSERT_EQ(code, 0) << r.err;
    EXPECT_NE(r.out.find("time series: 8 steps, ball_00.nrrd to ball_07.nrrd"), std::string::npos)
        << r.out;
    for (int t = 0; t < kBallSteps; ++t)
        EXPECT_NE(r.out.find("time " + std::to_string(t) + ": frame " + std::to_string(t + 1) +
                             " done in "),
                  std::string::npos)
            << "step " << t << ":\n"
            << r.out;
    for (int rank = 1; rank <= 4; ++rank) EXPECT_EQ(r.results[rank].frames, 9u) << rank;
    expect_same_picture(read_image(series / "last.png"), step_alone(series, 7), "the last step");
    expect_same_picture(read_image(series / "mosaic.png"), step_alone(series, 2), "step 2");
    // The steps differ: the ball moved.
    EXPECT_LT(test::compare_images(step_alone(series, 2), step_alone(series, 7)).mask_iou, 0.5);
}

TEST(WallTime, AStepChangeMidFrameInterruptsEveryTileAsAnIsovalueChangeDoes) {
    const auto series = write_ball_series("wall_time_interrupt");
    WallOptions o = ball_wall(series, (series / "ball_%02d.nrrd").string());
    // Every tile pauses at each sample point (the `slow` fault), so a few rays into the frame every
    // tile is inside one of its jobs when the step changes.
    o.fault = {FaultAction::slow, FaultMoment::none, TestFault::kEveryTile};
    o.script = script_file(series, "wait rays 4\ntime 3\nwait done\n");
    const SeriesRun r = run_series(o);
    for (int code : r.codes) ASSERT_EQ(code, 0) << r.err;
    for (int rank = 1; rank <= 4; ++rank) {
        EXPECT_EQ(r.results[rank].frames, 2u) << rank;
        EXPECT_GE(r.results[rank].interrupted, 1u) << rank;
    }
    expect_same_picture(read_image(series / "mosaic.png"), step_alone(series, 3), "step 3");
}

TEST(WallTime, BadStepsAreOneLine) {
    const auto series = write_ball_series("wall_time_bad");
    auto one_line = [](const SeriesRun& r, const std::string& mentions) {
        bool failed = false;
        for (int code : r.codes) failed = failed || code != 0;
        EXPECT_TRUE(failed) << r.out;
        EXPECT_NE(r.err.find(mentions), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    };
    WallOptions o = ball_wall(series, (series / "ball_%02d.nrrd").string());
    o.script = script_file(series, "time 8\n");
    one_line(run_series(o), "script.txt:1: time: step 8: the series has 8 steps (0 to 7)");
    // A step of another size: the tile that opens it names the file.
    write_ball_step(series / "ball_05.nrrd", 5, kBallSide + 1);
    o.script = script_file(series, "time 5\nwait done\n");
    one_line(run_series(o),
             "ball_05.nrrd: --volume: time step 5 has 33x33x33 voxels, step 0 has 32x32x32");
    // A step missing from the numbers.
    std::filesystem::remove(series / "ball_05.nrrd");
    o.script.clear();
    one_line(run_series(o), "ball_05.nrrd: --volume: time step 5 is missing (files 0 to 7 found)");
    // Not a series.
    WallOptions plain = ball_wall(series, (series / "ball_00.nrrd").string());
    plain.script = script_file(series, "play\n");
    one_line(run_series(plain), "script.txt:1: play: the volume is not a time series");
}

}  // namespace
}  // namespace isowall
