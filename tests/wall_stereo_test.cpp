// A stereo wall with every rank a thread (comm/inproc_comm.h): a pair of ranks per tile, their
// mosaics and anaglyph. The disparity is checked on known geometry: two small balls, one nearer
// than the screen plane and one beyond it, whose centres' disparity follows from the eye
// separation and their depths (wall_spec/eyes.h); and each eye is the mono wall seen from that
// eye's head position.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>

#include "app/wall_run.h"
#include "comm/inproc_comm.h"
#include "files/image_io.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"
#include "wall_spec/eyes.h"

namespace isowall {
namespace {

constexpr int kSide = 64;
// Two balls of radius 4 voxels: A left and near the eye (front views look along +y), B right
// and far.
constexpr glm::vec3 kBallA{16, 12, 32}, kBallB{48, 52, 32};

std::filesystem::path write_balls(const std::filesystem::path& dir) {
    std::string data(std::size_t(kSide) * kSide * kSide, '\0');
    for (int z = 0; z < kSide; ++z)
        for (int y = 0; y < kSide; ++y)
            for (int x = 0; x < kSide; ++x) {
                const glm::vec3 p(x, y, z);
                const float d = std::min(glm::length(p - kBallA), glm::length(p - kBallB));
                // 128 at 4 voxels from a centre, falling by 32 a voxel: a ball at iso 128.
                const float v = std::clamp(256.0f - 32.0f * d, 0.0f, 255.0f);
                data[(std::size_t(z) * kSide + y) * kSide + x] = char(std::uint8_t(v));
            }
    const auto path = dir / "balls.nrrd";
    std::ofstream(path, std::ios::binary)
        << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 64 64 64\nencoding: raw\n\n"
        << data;
    return path;
}

std::vector<int> run(WallOptions o, int ranks) {
    testing::internal::CaptureStderr();
    const std::vector<int> codes =
        run_in_process(ranks, [&](Comm& comm) { return run_wall(o, comm); });
    const std::string err = testing::internal::GetCapturedStderr();
    if (!err.empty()) std::printf("%s", err.c_str());
    return codes;
}

// The centroid of the lit pixels in columns [x0, x1) of `img`.
glm::dvec2 centroid(const Image& img, int x0, int x1) {
    glm::dvec2 sum(0);
    double n = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = x0; x < x1; ++x) {
            const std::uint8_t* p = &img.rgba[4 * (std::size_t(y) * img.width + x)];
            if (p[0] || p[1] || p[2]) sum += glm::dvec2(x + 0.5, y + 0.5), n += 1;
        }
    return n > 0 ? sum / n : glm::dvec2(-1);
}

TEST(StereoWall, SideBySideEyesShowEachBallWithTheDisparityOfItsDepth) {
    const auto dir = test::scratch_dir("stereo_balls");
    std::ofstream(dir / "sbs.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n"
                                       "[stereo]\nmode = \"side-by-side\"\neye_separation = 0.5\n";
    WallOptions o;
    o.wall = (dir / "sbs.toml").string();
    o.out = (dir / "m.png").string();
    std::filesystem::create_directories(dir / "tiles");
    o.tiles_out = (dir / "tiles").string();
    o.volume.path = write_balls(dir).string();
    o.volume.no_cache = true;
    o.iso = {"128"};
    const std::vector<int> codes = run(o, 9);
    for (int code : codes) EXPECT_EQ(code, 0);
    const Image left = read_image(dir / "m-left.png"), right = read_image(dir / "m-right.png");
    const Image both = read_image(dir / "m.png");
    ASSERT_EQ(left.width, 160);  // the virtual screen's 320 px, squeezed
    ASSERT_EQ(left.height, 240);
    ASSERT_EQ(right.width, 160);
    EXPECT_EQ(both.width, 320);
    EXPECT_EQ(both.height, 240);
    EXPECT_TRUE(std::filesystem::exists(dir / "tiles" / "tile_3-right.png"));

    // The expected disparity of each ball's centre, in the eye mosaic's pixels.
    const WallSpec spec = load_wall(o.wall);
    const Box3 bounds{glm::vec3(0), glm::vec3(kSide - 1)};
    const float aspect = 320.0f / 240.0f;
    const Camera cam = front_full_view(bounds, aspect);
    const double d = screen_plane_distance(cam, spec);
    const auto expected = [&](const glm::vec3& ball) {
        const double depth = ball.y - cam.eye.y;
        return 0.5 * left.width * (1.0 - d / depth);
    };
    const glm::dvec2 al = centroid(left, 0, 80), ar = centroid(right, 0, 80);
    const glm::dvec2 bl = centroid(left, 80, 160), br = centroid(right, 80, 160);
    ASSERT_GT(al.x, 0);
    ASSERT_GT(bl.x, 0);
    // The near ball is in front of the screen plane (crossed: further left in the right eye),
    // the far one behind it; neither moves vertically.
    std::printf("disparity A %.2f px (expected %.2f), B %.2f px (expected %.2f)\n", ar.x - al.x,
                expected(kBallA), br.x - bl.x, expected(kBallB));
    EXPECT_LT(expected(kBallA), -3.0);
    EXPECT_GT(expected(kBallB), 3.0);
    EXPECT_NEAR(ar.x - al.x, expected(kBallA), 0.6);
    EXPECT_NEAR(br.x - bl.x, expected(kBallB), 0.6);
    EXPECT_NEAR(ar.y, al.y, 0.3);
    EXPECT_NEAR(br.y, bl.y, 0.3);
    // The anaglyph: red from the left eye, green from the right, stretched to the wall.
    for (int x = 0; x < both.width; x += 7)
        for (int y = 0; y < both.height; y += 5) {
            const std::size_t a = 4 * (std::size_t(y) * both.width + x);
            const std::size_t e = 4 * (std::size_t(y) * left.width + x / 2);
            ASSERT_EQ(both.rgba[a], left.rgba[e]);
            ASSERT_EQ(both.rgba[a + 1], right.rgba[e + 1]);
        }
}

TEST(StereoWall, EachEyeIsTheMonoWallSeenFromThatEyesHead) {
    const auto dir = test::scratch_dir("stereo_eyes");
    std::ofstream(dir / "full.toml") << "tiles = [2, 2]\ntile_size_px = [80, 60]\n"
                                        "[stereo]\nmode = \"full\"\neye_separation = 0.06\n";
    std::ofstream(dir / "mono.toml") << "tiles = [2, 2]\ntile_size_px = [80, 60]\n";
    std::ofstream(dir / "left.txt") << "head -0.03 0 0\nwait done\n";
    std::ofstream(dir / "right.txt") << "head 0.03 0 0\nwait done\n";
    WallOptions o;
    o.volume.no_cache = true;
    o.wall = (dir / "full.toml").string();
    o.out = (dir / "stereo.png").string();
    for (int code : run(o, 9)) EXPECT_EQ(code, 0);
    o.wall = (dir / "mono.toml").string();
    for (const char* eye : {"left", "right"}) {
        o.script = (dir / (std::string(eye) + ".txt")).string();
        o.out = (dir / (std::string("mono-") + eye + ".png")).string();
        for (int code : run(o, 5)) EXPECT_EQ(code, 0);
        const Image stereo = read_image(dir / (std::string("stereo-") + eye + ".png"));
        const Image mono = read_image(o.out);
        const test::ImageComparison m = test::compare_images(stereo, mono);
        EXPECT_GE(m.mask_iou, 0.999) << eye << ": " << m;
        EXPECT_GE(m.equal_share, 0.999) << eye << ": " << m;
        if (m.equal_share < 0.999) test::write_diff_images(dir, eye, stereo, mono);
    }
    // And the eyes differ from each other.
    const test::ImageComparison lr = test::compare_images(read_image(dir / "stereo-left.png"),
                                                          read_image(dir / "stereo-right.png"));
    EXPECT_LT(lr.equal_share, 0.95) << lr;
}

TEST(StereoWall, AHeadPastTheScreenIsRefusedNamingItsLine) {
    const auto dir = test::scratch_dir("stereo_head");
    std::ofstream(dir / "sbs.toml") << "tiles = [2, 2]\ntile_size_px = [80, 60]\n"
                                       "[stereo]\nmode = \"side-by-side\"\n";
    std::ofstream(dir / "s.txt") << "head 0 0 -1000\n";
    WallOptions o;
    o.volume.no_cache = true;
    o.wall = (dir / "sbs.toml").string();
    o.out = (dir / "m.png").string();
    o.script = (dir / "s.txt").string();
    testing::internal::CaptureStderr();
    const std::vector<int> codes = run_in_process(9, [&](Comm& comm) { return run_wall(o, comm); });
    const std::string err = testing::internal::GetCapturedStderr();
    for (int code : codes) EXPECT_NE(code, 0) << err;
    EXPECT_NE(err.find("s.txt:1"), std::string::npos) << err;
    EXPECT_NE(err.find("head"), std::string::npos) << err;
    EXPECT_NE(err.find("in front of the screen plane"), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(dir / "m.png"));
}

}  // namespace
}  // namespace isowall
