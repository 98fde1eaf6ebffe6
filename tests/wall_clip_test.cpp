// Clip planes on the wall, every rank a thread (comm/inproc_comm.h): --clip reaches every tile and
// every helper (the balanced mosaic, with regions migrated, equals the static one), and a script's
// clip command changes the picture as --clip from the start does.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "app/wall_run.h"
#include "comm/inproc_comm.h"
#include "files/image_io.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

WallOptions clip_wall(const std::string& name, bool balance) {
    const auto dir = test::scratch_dir("wall_clip_" + name);
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    WallOptions o;
    o.wall = (dir / "2x2.toml").string();
    o.out = (dir / "mosaic.png").string();
    o.volume.no_cache = true;
    o.balance = balance;
    o.region = "80x60";
    o.orbit = {30, 20};
    return o;
}

std::vector<TileResultMsg> run(WallOptions o) {
    std::vector<TileResultMsg> results;
    o.results_out = &results;
    testing::internal::CaptureStderr();
    const std::vector<int> codes = run_in_process(5, [&](Comm& comm) { return run_wall(o, comm); });
    const std::string err = testing::internal::GetCapturedStderr();
    for (int code : codes) EXPECT_EQ(code, 0) << err;
    return results;
}

test::ImageComparison compare(const std::string& a, const std::string& b) {
    test::CompareOptions within_one;
    within_one.channel_tolerance = 1;
    return test::compare_images(read_image(a), read_image(b), within_one);
}

TEST(WallClip, BalancedAndStaticClippedMosaicsAreEqualAndCut) {
    WallOptions whole = clip_wall("whole", false);
    WallOptions cut = clip_wall("static", false);
    WallOptions balanced = clip_wall("balanced", true);
    for (WallOptions* o : {&cut, &balanced}) o->clip.planes = {"x<100", "0,1,1>170"};
    run(whole);
    run(cut);
    const std::vector<TileResultMsg> results = run(balanced);
    std::uint64_t helped = 0;
    for (const TileResultMsg& t : results) helped += t.jobs_helped;
    EXPECT_GT(helped, 0u) << "nothing migrated";
    const test::ImageComparison same = compare(balanced.out, cut.out);
    EXPECT_GE(same.mask_iou, 0.999) << same;
    EXPECT_GE(same.equal_share, 0.999) << same;
    EXPECT_GT(same.covered_both, 1000u) << same;
    const test::ImageComparison against_whole = compare(cut.out, whole.out);
    EXPECT_LT(against_whole.equal_share, 0.9) << "the planes cut nothing: " << against_whole;
    std::printf("%llu jobs migrated; balanced against static: %s; cut against whole: %s\n",
                (unsigned long long)helped, testing::PrintToString(same).c_str(),
                testing::PrintToString(against_whole).c_str());
}

TEST(WallClip, AScriptsClipCommandCutsAsTheOptionDoes) {
    WallOptions option = clip_wall("option", true);
    option.clip.planes = {"z>84"};
    WallOptions script = clip_wall("script", true);
    const auto dir = std::filesystem::path(script.out).parent_path();
    std::ofstream(dir / "s.txt") << "clip off\nwait done\nclip z>84\nwait done\nsnapshot cut\n"
                                    "clip off\nwait done\n";
    script.script = (dir / "s.txt").string();
    run(option);
    run(script);
    const test::ImageComparison cut = compare((dir / "cut.png").string(), option.out);
    EXPECT_GE(cut.mask_iou, 0.999) << cut;
    EXPECT_GE(cut.equal_share, 0.999) << cut;
    // `clip off` at the end: the mosaic is whole again.
    const test::ImageComparison off = compare(script.out, option.out);
    EXPECT_LT(off.equal_share, 0.9) << off;
}

}  // namespace
}  // namespace isowall
