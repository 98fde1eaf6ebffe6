// What the wall's picture shows beyond the camera and the isovalue, every rank a thread
// (comm/inproc_comm.h). Clip planes: --clip reaches every tile and every helper (the balanced
// mosaic, with regions migrated, equals the static one), and a script's clip command changes the
// picture as --clip from the start does. A surface coloured by a second field: every rank colours
// its groups alike (balanced equals static), the colours follow the field, and the mosaic carries
// the legend. Several surfaces: every rank draws each surface's layer and composites them, a
// helper's result lands in its surface's layer, and the mosaic is `render`'s picture of the same
// surfaces.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "app/commands.h"
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

// Runs `balanced` (regions migrated) and compares its mosaic with `fixed`'s (run already): the
// same picture. Returns the jobs migrated; `same` gets the comparison.
std::uint64_t expect_balanced_is_static(const WallOptions& balanced, const WallOptions& fixed,
                                        test::ImageComparison& same) {
    const std::vector<TileResultMsg> results = run(balanced);
    std::uint64_t helped = 0;
    for (const TileResultMsg& t : results) helped += t.jobs_helped;
    EXPECT_GT(helped, 0u) << "nothing migrated";
    same = compare(balanced.out, fixed.out);
    EXPECT_GE(same.mask_iou, 0.999) << same;
    EXPECT_GE(same.equal_share, 0.999) << same;
    EXPECT_GT(same.covered_both, 1000u) << same;
    return helped;
}

TEST(WallClip, BalancedAndStaticClippedMosaicsAreEqualAndCut) {
    WallOptions whole = clip_wall("whole", false);
    WallOptions cut = clip_wall("static", false);
    WallOptions balanced = clip_wall("balanced", true);
    for (WallOptions* o : {&cut, &balanced}) o->clip.planes = {"x<100", "0,1,1>170"};
    run(whole);
    run(cut);
    test::ImageComparison same;
    const std::uint64_t helped = expect_balanced_is_static(balanced, cut, same);
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

// A field on the phantom's grid that grows along x, 0 to 255.
std::filesystem::path write_x_ramp(const std::filesystem::path& dir) {
    const glm::ivec3 d{200, 184, 168};
    std::string data(std::size_t(d.x) * d.y * d.z, '\0');
    for (std::size_t i = 0; i < data.size(); ++i)
        data[i] = char(std::uint8_t(int(i % std::size_t(d.x)) * 255 / (d.x - 1)));
    const auto path = dir / "ramp.nrrd";
    std::ofstream(path, std::ios::binary)
        << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 200 184 168\nencoding: raw\n\n"
        << data;
    return path;
}

// The mean colour of the lit pixels in columns [x0, x1), above the legend's rows.
glm::dvec3 mean_colour(const Image& img, int x0, int x1, int y1) {
    glm::dvec3 sum(0);
    double n = 0;
    for (int y = 0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const std::uint8_t* p = &img.rgba[4 * (std::size_t(y) * img.width + x)];
            if (p[0] + p[1] + p[2] == 0) continue;
            sum += glm::dvec3(p[0], p[1], p[2]);
            n += 1;
        }
    return n > 0 ? sum / n : glm::dvec3(0);
}

TEST(WallColour, EveryRankColoursItsGroupsByTheFieldAndTheMosaicHasTheLegend) {
    WallOptions fixed = clip_wall("colour_static", false);
    WallOptions balanced = clip_wall("colour_balanced", true);
    const auto ramp = write_x_ramp(std::filesystem::path(fixed.out).parent_path());
    for (WallOptions* o : {&fixed, &balanced}) {
        o->orbit = {0, 0};
        o->colour.by = ramp.string();
    }
    run(fixed);
    test::ImageComparison same;
    expect_balanced_is_static(balanced, fixed, same);
    // The front view looks along +y, x to the right: viridis runs from purple (blue above red and
    // green) on the left through green to yellow (red and green above blue) on the right.
    const Image m = read_image(fixed.out);
    const glm::dvec3 left = mean_colour(m, 0, m.width / 3, m.height - 40);
    const glm::dvec3 right = mean_colour(m, 2 * m.width / 3, m.width, m.height - 40);
    EXPECT_GT(left.z, left.x) << left.x << " " << left.y << " " << left.z;
    EXPECT_GT(left.z, left.y) << left.x << " " << left.y << " " << left.z;
    EXPECT_GT(right.x, right.z) << right.x << " " << right.y << " " << right.z;
    EXPECT_GT(right.y, 2 * right.z) << right.x << " " << right.y << " " << right.z;
    // The legend's bar at the bottom left: viridis's low end, then its high end.
    int bar_row = -1;
    for (int y = m.height - 1; y > m.height - 40 && bar_row < 0; --y) {
        const std::uint8_t* p = &m.rgba[4 * (std::size_t(y) * m.width + 5)];
        if (p[2] > 60 && p[0] < 90 && p[1] < 30) bar_row = y;
    }
    EXPECT_GE(bar_row, 0) << "no legend bar";
    std::printf("colour: left %.0f %.0f %.0f, right %.0f %.0f %.0f; %s\n", left.x, left.y, left.z,
                right.x, right.y, right.z, testing::PrintToString(same).c_str());
}

// The skin at 0.3 over the bone, cut by a plane: the balanced mosaic, with regions migrated,
// equals the static one and `render`'s single picture of the same view.
TEST(WallSurfaces, TheBalancedMosaicIsRendersPictureOfTheSameSurfaces) {
    WallOptions fixed = clip_wall("surfaces_static", false);
    WallOptions balanced = clip_wall("surfaces_balanced", true);
    for (WallOptions* o : {&fixed, &balanced}) {
        o->iso = {"160:bone", "80:skin:0.3"};
        o->clip.planes = {"x<130"};
    }
    run(fixed);
    test::ImageComparison same;
    const std::uint64_t helped = expect_balanced_is_static(balanced, fixed, same);

    RenderOptions r;
    r.size = "320x240";
    r.orbit = {30, 20};
    r.iso = {"80:skin:0.3", "160:bone"};
    r.clip.planes = {"x<130"};
    r.volume.no_cache = true;
    r.no_measure = true;
    r.quiet = true;
    r.out = (std::filesystem::path(fixed.out).parent_path() / "render.png").string();
    testing::internal::CaptureStdout();
    const int code = run_render(r);
    testing::internal::GetCapturedStdout();
    ASSERT_EQ(code, 0);
    const test::ImageComparison render = compare(fixed.out, r.out);
    EXPECT_GE(render.mask_iou, 0.999) << render;
    EXPECT_GE(render.equal_share, 0.999) << render;
    // The skin is seen through: the bone's colour shows behind it (bone is yellower: more red
    // and green than blue, beyond what the skin alone gives).
    WallOptions skin = clip_wall("surfaces_skin", false);
    skin.iso = {"80:skin:0.3"};
    skin.clip.planes = {"x<130"};
    run(skin);
    EXPECT_LT(compare(skin.out, fixed.out).equal_share, 0.9);
    std::printf("%llu jobs migrated; balanced against static: %s; static against render: %s\n",
                (unsigned long long)helped, testing::PrintToString(same).c_str(),
                testing::PrintToString(render).c_str());
}

}  // namespace
}  // namespace isowall
