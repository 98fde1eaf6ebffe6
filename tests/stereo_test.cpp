// Stereo walls without MPI or GL: the [stereo] table, which rank drives which eye of which tile,
// the eyes' squeezed frames, and the eyes' off-axis frusta (wall_spec/eyes.h) checked by
// projecting points of known depth: zero parallax on the screen plane, the eye separation at
// infinity, no vertical parallax, and a tracked head that moves both eyes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "core/error.h"
#include "wall_spec/eyes.h"
#include "wall_spec/script.h"
#include "wall_spec/wall.h"

namespace isowall {
namespace {

const std::string kTwoByTwo = "tiles = [2, 2]\ntile_size_px = [320, 240]\n";

WallSpec stereo_wall(const std::string& table) {
    return parse_wall(kTwoByTwo + "[stereo]\n" + table, "s.toml");
}

TEST(StereoWallFile, ModesDefaultsAndUnits) {
    const WallSpec sbs = stereo_wall("mode = \"side-by-side\"\n");
    ASSERT_TRUE(sbs.stereo);
    EXPECT_EQ(sbs.stereo->mode, StereoMode::side_by_side);
    EXPECT_DOUBLE_EQ(sbs.stereo->separation, kDefaultEyeSeparation);
    EXPECT_DOUBLE_EQ(sbs.stereo->convergence, 1.0);
    const WallSpec tb =
        stereo_wall("mode = \"top-bottom\"\neye_separation = 0.05\nconvergence = 0.5\n");
    EXPECT_EQ(tb.stereo->mode, StereoMode::top_bottom);
    EXPECT_DOUBLE_EQ(tb.stereo->separation, 0.05);
    EXPECT_DOUBLE_EQ(tb.stereo->convergence, 0.5);
    // A wall whose size is known takes the separation in millimetres.
    const WallSpec phys = parse_wall(kTwoByTwo +
                                         "[physical]\ntile_size_mm = [400, 300]\n"
                                         "[stereo]\nmode = \"full\"\n",
                                     "p.toml");
    EXPECT_DOUBLE_EQ(phys.stereo->separation, kDefaultEyeSeparationMm);
    EXPECT_FALSE(parse_wall(kTwoByTwo, "m.toml").stereo);
    // The full mode's right eyes show on a display of their own.
    const WallSpec two = parse_wall(kTwoByTwo + "display = \":0.0\"\n[stereo]\nmode = \"full\"\n" +
                                        "right_display = \":0.1\"\n",
                                    "two.toml");
    EXPECT_EQ(tile_display(two, 3, Eye::left), ":0.0");
    EXPECT_EQ(tile_display(two, 3, Eye::right), ":0.1");
    EXPECT_EQ(tile_display(sbs, 3, Eye::right), "");
}

TEST(StereoWallFile, BadTablesNameTheField) {
    struct Case {
        std::string text, field, says;
    };
    const std::string phys = "[physical]\ntile_size_mm = [400, 300]\n";
    for (const Case& c : std::vector<Case>{
             {"[stereo]\n", "stereo.mode", "missing"},
             {"[stereo]\nmode = \"quad-buffer\"\n", "stereo.mode", "\"quad-buffer\""},
             {"[stereo]\nmode = 3\n", "stereo.mode", "got 3"},
             {"[stereo]\nmode = \"full\"\neye_separation_mm = 60\n", "stereo.eye_separation_mm",
              "needs [physical]"},
             {phys + "[stereo]\nmode = \"full\"\neye_separation = 0.1\n", "stereo.eye_separation",
              "eye_separation_mm"},
             {"[stereo]\nmode = \"full\"\neye_separation = 2\n", "stereo.eye_separation", "[0, 1]"},
             {"[stereo]\nmode = \"full\"\nconvergence = 0\n", "stereo.convergence", "got 0"},
             {"[stereo]\nmode = \"full\"\neyes = 2\n", "stereo.eyes", "unknown key"},
             {"stereo = true\n", "stereo", "expected a table"},
             {"[stereo]\nmode = \"side-by-side\"\nright_display = \":0.1\"\n",
              "stereo.right_display", "only the full mode"},
             {"[stereo]\nmode = \"full\"\nright_display = \"screen two\"\n", "stereo.right_display",
              "expected an X display"},
         }) {
        try {
            parse_wall(kTwoByTwo + c.text, "bad.toml");
            ADD_FAILURE() << c.text << " was accepted";
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("bad.toml"), std::string::npos) << what;
            EXPECT_NE(what.find(c.field), std::string::npos) << what;
            EXPECT_NE(what.find(c.says), std::string::npos) << what;
        }
    }
    try {
        parse_wall("tiles = [2, 1]\ntile_size_px = [1, 100]\n[stereo]\nmode = \"side-by-side\"\n",
                   "thin.toml");
        ADD_FAILURE() << "a side-by-side wall of 1 px tiles was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("at least 2 px wide"), std::string::npos) << e.what();
    }
}

TEST(StereoRanks, APairOfRanksPerTileLeftThenRight) {
    WallSpec w = stereo_wall("mode = \"side-by-side\"\n");
    w.rank_order = RankOrder::column_major;
    w.overrides.push_back({1, 0, true});  // tile 1 disabled
    EXPECT_EQ(eyes_per_tile(w), 2);
    EXPECT_EQ(rank_count(w), 1 + 3 * 2);
    // Column-major: tiles 0, 2, (1 disabled), 3.
    const int tiles[] = {0, 0, 2, 2, 3, 3};
    for (int rank = 1; rank < rank_count(w); ++rank) {
        const Eye eye = rank % 2 ? Eye::left : Eye::right;
        EXPECT_EQ(tile_of_rank(w, rank), tiles[rank - 1]) << rank;
        EXPECT_EQ(eye_of_rank(w, rank), eye) << rank;
        EXPECT_EQ(rank_of_tile(w, tiles[rank - 1], eye), rank) << rank;
    }
    EXPECT_EQ(rank_of_tile(w, 1, Eye::left), kNoRank);
    EXPECT_EQ(eye_of_rank(w, kMasterRank), Eye::centre);
    EXPECT_EQ(tile_name(w, 2), "tile 0, right eye");
    w.stereo.reset();
    EXPECT_EQ(rank_count(w), 4);
    EXPECT_EQ(eye_of_rank(w, 1), Eye::centre);
    EXPECT_EQ(tile_name(w, 1), "tile 0");
}

TEST(StereoRanks, EachModeSqueezesTheEyesFrame) {
    WallSpec w = parse_wall(kTwoByTwo + "bezel_px = 3\n[stereo]\nmode = \"side-by-side\"\n", "b");
    // Tiles 320x240 with 6 px between them: a 646x486 virtual screen.
    const PixelRect t3 = tile_rect(w, 3);
    EXPECT_EQ(t3.x, 326);
    const PixelRect e3 = eye_rect(w, 3);
    EXPECT_EQ(e3.x, 163);
    EXPECT_EQ(e3.y, t3.y);
    EXPECT_EQ(e3.width, 160);
    EXPECT_EQ(e3.height, 240);
    EXPECT_EQ(eye_screen_size(w).width, 323);
    EXPECT_EQ(eye_screen_size(w).height, 486);
    w.stereo->mode = StereoMode::top_bottom;
    EXPECT_EQ(eye_rect(w, 3).x, 326);
    EXPECT_EQ(eye_rect(w, 3).y, 123);
    EXPECT_EQ(eye_rect(w, 3).height, 120);
    EXPECT_EQ(eye_screen_size(w).height, 243);
    w.stereo->mode = StereoMode::full;
    EXPECT_EQ(eye_rect(w, 3).width, 320);
    EXPECT_EQ(eye_screen_size(w).width, 646);
}

// Where `p` lands on a width x height screen seen through `v` (pixels, x right, y down).
glm::dvec2 pixel_of(const EyeView& v, const glm::vec3& p, int width, int height) {
    const glm::vec4 clip = v.wall.matrix() * v.camera.view() * glm::vec4(p, 1);
    const glm::vec2 w = ndc_to_window(clip.x / clip.w, clip.y / clip.w, width, height);
    return {w.x, w.y};
}

struct Scene {
    Box3 bounds{glm::vec3(-1), glm::vec3(1)};
    Camera camera;
    float aspect = 640.0f / 480.0f;
    Scene() { camera = front_full_view(bounds, aspect); }
    // A point on the camera's axis at `depth` (object units in front of the eye), `side` right.
    glm::vec3 at(double depth, double side = 0, double lift = 0) const {
        const glm::dvec3 f = glm::normalize(glm::dvec3(camera.target - camera.eye));
        return glm::vec3(glm::dvec3(camera.eye) + depth * f + side * glm::dvec3(1, 0, 0) +
                         lift * glm::dvec3(0, 0, 1));
    }
};

TEST(StereoEyes, TheCentreEyeAtTheNominalHeadIsTheMonoView) {
    const Scene s;
    const WallSpec mono = parse_wall(kTwoByTwo, "m");
    const EyeView v = eye_view(s.camera, s.aspect, mono, Eye::centre, glm::dvec3(0), s.bounds);
    const Camera fitted = fit_depth_range(s.camera, s.bounds);
    const Frustum f = fitted.frustum(s.aspect);
    EXPECT_EQ(v.camera.eye, fitted.eye);
    EXPECT_EQ(v.camera.near_z, fitted.near_z);
    EXPECT_EQ(v.wall.left, f.left);
    EXPECT_EQ(v.wall.top, f.top);
    EXPECT_TRUE(head_problem(s.camera, s.aspect, mono, glm::dvec3(0)).empty());
}

TEST(StereoEyes, DisparityIsZeroOnTheScreenPlaneAndTheSeparationAtInfinity) {
    const Scene s;
    for (const double convergence : {1.0, 0.6, 1.5}) {
        WallSpec w = stereo_wall("mode = \"full\"\neye_separation = 0.05\n");
        w.stereo->convergence = convergence;
        const int width = 640, height = 480;  // the full mode's eye mosaic: the virtual screen
        const EyeView l = eye_view(s.camera, s.aspect, w, Eye::left, glm::dvec3(0), s.bounds);
        const EyeView r = eye_view(s.camera, s.aspect, w, Eye::right, glm::dvec3(0), s.bounds);
        const double d = screen_plane_distance(s.camera, w);
        const double sep_px = 0.05 * width;  // a twentieth of the wall's width
        for (const double depth : {0.5 * d, d, 1.3 * d, 3.0 * d, 1e4 * d}) {
            for (const double side : {0.0, 0.2}) {
                const glm::vec3 p = s.at(depth, side, 0.1);
                const glm::dvec2 pl = pixel_of(l, p, width, height);
                const glm::dvec2 pr = pixel_of(r, p, width, height);
                // Right minus left: 0 on the plane, positive behind it, the separation at
                // infinity, negative in front; the same row in both eyes.
                const double want = sep_px * (1.0 - d / depth);
                EXPECT_NEAR(pr.x - pl.x, want, 2e-3 * width)
                    << "convergence " << convergence << " depth " << depth / d;
                EXPECT_NEAR(pr.y, pl.y, 1e-3 * height);
            }
        }
    }
}

TEST(StereoEyes, OnAPhysicalWallTheSeparationIsInMillimetres) {
    // 2x2 of 1920x1080 at 0.63 mm a pixel, 20 px between tiles: 65 mm is 103.2 px.
    const WallSpec w = parse_wall(
        "tiles = [2, 2]\ntile_size_px = [1920, 1080]\n[physical]\n"
        "tile_size_mm = [1209.6, 680.4]\nbezel_mm = 6.3\nviewer_mm = [0, -100, 2000]\n"
        "[stereo]\nmode = \"full\"\n",
        "phys.toml");
    const PixelSize vs = virtual_screen_size(w);
    Scene s;
    s.aspect = float(vs.width) / float(vs.height);
    s.camera = front_full_view(s.bounds, s.aspect);
    const EyeView l = eye_view(s.camera, s.aspect, w, Eye::left, glm::dvec3(0), s.bounds);
    const EyeView r = eye_view(s.camera, s.aspect, w, Eye::right, glm::dvec3(0), s.bounds);
    const glm::vec3 far = s.at(1e5 * s.camera.distance());
    const double disparity =
        pixel_of(r, far, vs.width, vs.height).x - pixel_of(l, far, vs.width, vs.height).x;
    EXPECT_NEAR(disparity, 65.0 / 0.63, 0.5);
}

TEST(StereoEyes, AHeadMovesBothEyesAndMayNotPassTheScreen) {
    const Scene s;
    const WallSpec w = stereo_wall("mode = \"full\"\neye_separation = 0.05\n");
    // A head moved a tenth of the wall right: a point on the screen plane stays where it was
    // for every eye, one behind it moves right with the head in both.
    const glm::dvec3 head(0.1, 0, 0);
    const double d = screen_plane_distance(s.camera, w);
    for (const Eye eye : {Eye::left, Eye::right}) {
        const EyeView at = eye_view(s.camera, s.aspect, w, eye, glm::dvec3(0), s.bounds);
        const EyeView moved = eye_view(s.camera, s.aspect, w, eye, head, s.bounds);
        const glm::vec3 on = s.at(d, 0.3), behind = s.at(2 * d);
        EXPECT_NEAR(pixel_of(moved, on, 640, 480).x, pixel_of(at, on, 640, 480).x, 0.5);
        EXPECT_NEAR(pixel_of(moved, behind, 640, 480).x - pixel_of(at, behind, 640, 480).x,
                    0.1 * 640 * 0.5, 1.0);
    }
    // Wall widths: the screen plane is about 1.9 widths away here (a 30 degree view).
    EXPECT_TRUE(head_problem(s.camera, s.aspect, w, glm::dvec3(0, 0, -1)).empty());
    EXPECT_NE(head_problem(s.camera, s.aspect, w, glm::dvec3(0, 0, -5)).find("in front of"),
              std::string::npos);
    Camera ortho = s.camera;
    ortho.projection = Projection::orthographic;
    EXPECT_NE(head_problem(ortho, s.aspect, w, glm::dvec3(0)).find("perspective"),
              std::string::npos);
    const WallSpec mono = parse_wall(kTwoByTwo, "m");
    EXPECT_TRUE(head_problem(ortho, s.aspect, mono, glm::dvec3(0)).empty());
    EXPECT_FALSE(head_problem(ortho, s.aspect, mono, head).empty());
}

TEST(StereoScript, HeadTakesThreeNumbers) {
    const ScriptCommand c = parse_command("head 12.5 -3 40", "s.txt:1");
    ASSERT_TRUE(std::holds_alternative<HeadCmd>(c));
    EXPECT_EQ(std::get<HeadCmd>(c).offset, glm::dvec3(12.5, -3, 40));
    for (const char* bad : {"head 1 2", "head 1 2 3 4", "head 1 nan 3", "head 1 2 1e8"}) {
        try {
            parse_command(bad, "s.txt:2");
            ADD_FAILURE() << bad << " was accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("s.txt:2"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace isowall
