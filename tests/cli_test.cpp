// The isowall program end to end: every bad input gives one line naming the file and field, a
// non-zero exit, and no output file; good input writes what it says.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "files/image_io.h"
#include "files/ply.h"
#include "tests/cli_util.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

using test::expect_one_line_error;
using test::run_isowall;
using test::write_text;

class Cli : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = test::scratch_dir(std::string("cli_") +
                                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        write_text(dir_ / "ok.raw", std::string(4 * 4 * 4, '\x01'));
    }
    std::filesystem::path dir_;
};

TEST_F(Cli, MissingFile) {
    auto r = run_isowall(dir_, "render -v nope.nhdr --iso 1 --out img.png");
    expect_one_line_error(r, {"nope.nhdr", "file", "no such file"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "img.png"));
}

TEST_F(Cli, DataFileShorterOrLongerThanTheHeader) {
    const std::string hdr =
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 5\nencoding: raw\ndata file: ok.raw\n";
    write_text(dir_ / "short.nhdr", hdr);
    expect_one_line_error(run_isowall(dir_, "extract -v short.nhdr --iso 1 --out s.ply"),
                          {"ok.raw", "size", "shorter", "80", "64"});
    write_text(
        dir_ / "long.nhdr",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 3\nencoding: raw\ndata file: ok.raw\n");
    expect_one_line_error(run_isowall(dir_, "extract -v long.nhdr --iso 1 --out s.ply"),
                          {"ok.raw", "size", "longer"});
    // Raw files are held to the same rule.
    expect_one_line_error(run_isowall(dir_, "info -v ok.raw --dims 4 4 5 --type uint8"),
                          {"ok.raw", "size", "shorter"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "s.ply"));
}

TEST_F(Cli, MalformedHeader) {
    write_text(
        dir_ / "bad.nhdr",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4\nencoding: raw\ndata file: ok.raw\n");
    expect_one_line_error(run_isowall(dir_, "info -v bad.nhdr"), {"bad.nhdr", "header"});
    write_text(dir_ / "garbage.nrrd", "hello world\n");
    expect_one_line_error(run_isowall(dir_, "info -v garbage.nrrd"), {"garbage.nrrd", "header"});
    write_text(
        dir_ / "dim2.nhdr",
        "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 8 8\nencoding: raw\ndata file: ok.raw\n");
    expect_one_line_error(run_isowall(dir_, "info -v dim2.nhdr"),
                          {"dim2.nhdr", "dimension", "expected 3"});
}

TEST_F(Cli, UnsupportedType) {
    write_text(dir_ / "i64.nhdr",
               "NRRD0004\ntype: long long\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nendian: "
               "little\ndata file: ok.raw\n");
    expect_one_line_error(run_isowall(dir_, "info -v i64.nhdr"),
                          {"i64.nhdr", "type", "unsupported"});
    expect_one_line_error(run_isowall(dir_, "info -v ok.raw --dims 4 4 4 --type int64"),
                          {"ok.raw", "--type", "int64"});
}

TEST_F(Cli, BadSize) {
    for (const char* size : {"100", "0x10", "axb", "10x10x10"}) {
        auto r = run_isowall(dir_, std::string("render --size ") + size + " --out img.png");
        expect_one_line_error(r, {"--size", size});
    }
    EXPECT_FALSE(std::filesystem::exists(dir_ / "img.png"));
}

TEST_F(Cli, IsovalueOutsideTheRange) {
    expect_one_line_error(run_isowall(dir_, "render --iso 999 --size 64x48 --out img.png"),
                          {"phantom", "--iso", "999", "[0, 220]"});
    expect_one_line_error(
        run_isowall(dir_, "extract -v ok.raw --dims 4 4 4 --type uint8 --iso -3 --out s.ply"),
        {"ok.raw", "--iso", "outside"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "img.png"));
    EXPECT_FALSE(std::filesystem::exists(dir_ / "s.ply"));
}

TEST_F(Cli, UnknownOptionAndMissingFolder) {
    auto r = run_isowall(dir_, "render --frobnicate 3");
    expect_one_line_error(r, {"frobnicate"});
    EXPECT_EQ(r.exit_code, 2);
    expect_one_line_error(run_isowall(dir_, "render --size 64x48 --out no/such/dir/img.png"),
                          {"no/such/dir", "--out"});
}

TEST_F(Cli, ExtractWritesThePhantomSurface) {
    auto r = run_isowall(dir_, "extract --iso 160 --out bone.ply");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Mesh m = read_ply(dir_ / "bone.ply");
    EXPECT_GT(m.triangle_count(), 100000u);
    EXPECT_NE(r.out.find("triangles " + std::to_string(m.triangle_count())), std::string::npos)
        << r.out;
    auto info = run_isowall(dir_, "info");
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_NE(info.out.find("suggested isovalues: skin 50, bone 160"), std::string::npos)
        << info.out;
}

// --clip and --clip-box: an extracted mesh has nothing past the planes, a render matches the cut
// full surface, and bad planes are one line naming the option with nothing written.
TEST_F(Cli, ClipCutsTheMeshAndThePicture) {
    auto r =
        run_isowall(dir_, "extract --iso 160 --clip \"x<90\" --clip \"0,1,1>150\" --out cut.ply");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Mesh m = read_ply(dir_ / "cut.ply");
    EXPECT_GT(m.triangle_count(), 1000u);
    for (const glm::vec3& p : m.positions) {  // the phantom's spacing is 1: voxels are object units
        EXPECT_LE(p.x, 90.0f + 1e-3f);
        EXPECT_GE(p.y + p.z, 150.0f - 1e-2f);
    }
    r = run_isowall(dir_,
                    "render --size 96x72 --orbit 30 20 --clip-box 30,20,40,150,140,120 "
                    "--against-full --out box.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("coverage IoU 1.0000"), std::string::npos) << r.out;
    auto bad = [&](const std::string& args) {
        return run_isowall(dir_, "render --size 64x48 --out bad.png " + args);
    };
    expect_one_line_error(bad("--clip \"x<<3\""), {"--clip", "x<<3"});
    expect_one_line_error(bad("--clip \"q>3\""), {"--clip", "x, y, z or three numbers"});
    expect_one_line_error(bad("--clip-box 0,0,0,10,10"), {"--clip-box", "six numbers"});
    expect_one_line_error(bad("--clip-box 0,0,0,10,0,10"), {"--clip-box", "Y0 < Y1"});
    expect_one_line_error(bad("--clip \"x<-5\""), {"--clip", "keep nothing of the volume"});
    expect_one_line_error(bad("--clip \"x<10\" --clip \"x>20\""),
                          {"--clip", "keep nothing of the volume"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.png"));
}

// --color-by: the picture coloured by a second field equals the full surface coloured alike, with
// the legend in the written image; a bad map, range or field is one line and no image.
TEST_F(Cli, ColorByColoursThePictureAndBadFieldsAreOneLine) {
    // A field on the phantom's grid (200x184x168) growing along x, and one a voxel short.
    auto write_field = [&](const char* name, int nx) {
        std::string data(std::size_t(nx) * 184 * 168, '\0');
        for (std::size_t i = 0; i < data.size(); ++i)
            data[i] = char(std::uint8_t(int(i % std::size_t(nx)) * 255 / (nx - 1)));
        std::ofstream(dir_ / name, std::ios::binary)
            << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << nx << " 184 168\nencoding: raw\n\n"
            << data;
    };
    write_field("ramp.nrrd", 200);
    write_field("short.nrrd", 199);
    auto r = run_isowall(dir_,
                         "render --size 160x120 --color-by ramp.nrrd --colormap magma "
                         "--against-full --out coloured.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("coverage IoU 1.0000"), std::string::npos) << r.out;
    const Image img = read_image(dir_ / "coloured.png");
    // magma's low end is near black, its high end a pale yellow: the right of the ball is far
    // brighter in red than the left.
    auto red = [&](int x0, int x1) {
        double sum = 0, n = 0;
        for (int y = 0; y < 80; ++y)
            for (int x = x0; x < x1; ++x) {
                const std::uint8_t* p = &img.rgba[4 * (std::size_t(y) * img.width + x)];
                if (p[0] + p[1] + p[2] == 0) continue;
                sum += p[0];
                n += 1;
            }
        return n > 0 ? sum / n : 0.0;
    };
    EXPECT_GT(red(100, 160), red(0, 60) + 40) << red(0, 60) << " " << red(100, 160);
    auto bad = [&](const std::string& args) {
        return run_isowall(dir_, "render --size 64x48 --out bad.png --color-by " + args);
    };
    expect_one_line_error(bad("ramp.nrrd --colormap rainbow"),
                          {"--colormap", "rainbow", "viridis"});
    expect_one_line_error(bad("ramp.nrrd --color-range 5 2"), {"--color-range", "LO below HI"});
    expect_one_line_error(bad("short.nrrd"),
                          {"short.nrrd", "--color-by", "199x184x168", "same grid"});
    expect_one_line_error(bad("missing.nrrd"), {"missing.nrrd"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.png"));
}

// Several surfaces: the skin at 0.3 over the bone is the same picture with the surfaces given in
// either order, and on two threads as on one; it equals the full surfaces composited (--full)
// with their coverage; bad styles are one line and no image.
TEST_F(Cli, SurfacesInEitherOrderAndOnEitherThreadsAreOnePicture) {
    const std::string common = "render --size 160x120 --orbit 30 20 -q --no-measure ";
    auto r = run_isowall(dir_, common + "--threads 1 --iso 80:skin:0.3 --iso 160:bone --out a.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("2 surfaces"), std::string::npos) << r.out;
    r = run_isowall(dir_, common + "--threads 1 --iso 160:bone --iso 80:skin:0.3 --out b.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_isowall(dir_, common + "--threads 2 --iso 160:bone --iso 80:skin:0.3 --out c.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run_isowall(dir_, common + "--full --iso 160:bone --iso 80:skin:0.3 --out full.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("2 surfaces composited"), std::string::npos) << r.out;
    const Image a = read_image(dir_ / "a.png"), b = read_image(dir_ / "b.png");
    EXPECT_TRUE(a.rgba == b.rgba) << "the order the surfaces were given in changed the picture";
    const test::ImageComparison threads = test::compare_images(read_image(dir_ / "c.png"), a);
    EXPECT_GE(threads.equal_share, 0.999) << threads;
    const test::ImageComparison full = test::compare_images(a, read_image(dir_ / "full.png"));
    EXPECT_GE(full.equal_share, 0.999) << full;
    // The skin is seen through: behind it the bone's colour shows, so the picture is not the
    // skin's alone.
    r = run_isowall(dir_, common + "--threads 1 --iso 80:skin:0.3 --out skin.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_LT(test::compare_images(read_image(dir_ / "skin.png"), a).equal_share, 0.9);

    auto bad = [&](const std::string& args) {
        return run_isowall(dir_, "render --size 64x48 --out bad.png " + args);
    };
    expect_one_line_error(bad("--iso 80:mauve"), {"--iso", "unknown colour 'mauve'"});
    expect_one_line_error(bad("--iso 80:skin:1.5"), {"--iso", "opacity in [0, 1]"});
    expect_one_line_error(bad("--iso 80 --iso 80:red"), {"--iso", "isovalue 80 given twice"});
    expect_one_line_error(bad("--iso 80:skin:0.3 --iso 300"), {"phantom", "--iso", "300"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.png"));
}

// A time series given as a numbered pattern: render --time N draws step N's file as that file
// alone draws; a step past the series, --time on one volume, and a gap are one line and no image.
TEST_F(Cli, RenderDrawsAStepOfATimeSeries) {
    for (int t = 0; t < 3; ++t) {
        std::string data(16 * 16 * 16, '\0');
        for (int i = 0; i < 16 * 16 * 16; ++i) {
            const int x = i % 16, y = i / 16 % 16, z = i / 256;
            const int d2 =
                (x - 5 - 3 * t) * (x - 5 - 3 * t) + (y - 8) * (y - 8) + (z - 8) * (z - 8);
            data[std::size_t(i)] = char(std::uint8_t(d2 < 16 ? 200 : 0));
        }
        std::ofstream(dir_ / ("s_" + std::to_string(t) + ".nrrd"), std::ios::binary)
            << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 16 16 16\nencoding: raw\n\n"
            << data;
    }
    const std::string common = "render --size 64x48 --iso 100 --threads 1 -q --no-measure ";
    auto r = run_isowall(dir_, common + "-v s_%d.nrrd --time 2 --out step.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("time: step 2 of 3 steps"), std::string::npos) << r.out;
    r = run_isowall(dir_, common + "-v s_2.nrrd --out file.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(read_image(dir_ / "step.png").rgba == read_image(dir_ / "file.png").rgba);
    auto bad = [&](const std::string& args) { return run_isowall(dir_, common + args); };
    expect_one_line_error(bad("-v s_%d.nrrd --time 3 --out bad.png"),
                          {"--time", "step 3: the series has 3 steps (0 to 2)"});
    expect_one_line_error(bad("-v s_0.nrrd --time 1 --out bad.png"),
                          {"--time", "applies to a time series"});
    std::filesystem::rename(dir_ / "s_1.nrrd", dir_ / "s_x.nrrd");
    expect_one_line_error(bad("-v s_%d.nrrd --out bad.png"),
                          {"s_1.nrrd", "time step 1 is missing"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.png"));
}

// --against-full: the final image's C and final pixels against the full surface, printed after
// the frame; full resolution matches it, a coarse level of detail does not quite.
TEST_F(Cli, AgainstFullPrintsBothMeasures) {
    auto c_of = [](const std::string& out) {
        const auto at = out.find("against the full surface (");
        if (at == std::string::npos) return -1.0;
        const auto c = out.find("C = ", at);
        return c == std::string::npos ? -1.0 : std::stod(out.substr(c + 4));
    };
    auto iou_of = [](const std::string& out) {
        const auto at = out.find("coverage IoU ", out.find("against the full surface ("));
        return at == std::string::npos ? -1.0 : std::stod(out.substr(at + 13));
    };
    auto full =
        run_isowall(dir_, "render --size 160x120 -q --no-measure --against-full --out a.png");
    ASSERT_EQ(full.exit_code, 0) << full.err;
    EXPECT_GE(c_of(full.out), 0.999) << full.out;
    EXPECT_GE(iou_of(full.out), 0.999) << full.out;
    EXPECT_LE(iou_of(full.out), 1.0) << full.out;
    auto coarse = run_isowall(dir_,
                              "render --size 160x120 -q --no-measure --against-full --adaptive "
                              "--adaptive-pixels 8 --no-adaptive-refine "
                              "--out b.png");
    ASSERT_EQ(coarse.exit_code, 0) << coarse.err;
    const double c = c_of(coarse.out);
    EXPECT_GT(c, 0.8) << coarse.out;
    EXPECT_LT(c, c_of(full.out)) << coarse.out;
}

// --against-truth: the final image and the full surface at one sample a pixel, each against the
// truth (4x4 samples a pixel, box-filtered), and the fidelity gate, which the defaults pass and a
// level of detail far coarser than a pixel fails.
TEST_F(Cli, AgainstTruthPrintsTheGate) {
    auto fine =
        run_isowall(dir_, "render --size 160x120 -q --no-measure --against-truth --out a.png");
    ASSERT_EQ(fine.exit_code, 0) << fine.err;
    EXPECT_NE(fine.out.find("at 4x4 samples a pixel, box-filtered"), std::string::npos) << fine.out;
    EXPECT_NE(fine.out.find("full surface at 1 sample a pixel:  C_T = "), std::string::npos)
        << fine.out;
    EXPECT_NE(fine.out.find("fidelity gate: holds (C_T "), std::string::npos) << fine.out;
    auto coarse = run_isowall(dir_,
                              "render --size 160x120 -q --no-measure --against-truth --adaptive "
                              "--adaptive-pixels 8 --no-adaptive-refine --out b.png");
    ASSERT_EQ(coarse.exit_code, 0) << coarse.err;
    EXPECT_NE(coarse.out.find("fidelity gate: FAILS (C_T "), std::string::npos) << coarse.out;
}

// --against-full with the replay: a second table measures every replayed image against the full
// surface. At full resolution (every cell a unit: no footprint units, whose samples may break a
// tie on a grazing edge the other way than the rasteriser) the final image is the full surface's,
// so the two tables agree row for row; a coarse level of detail never reaches 100% of the truth.
TEST_F(Cli, AgainstFullReplaysAgainstTheTruthToo) {
    auto table = [](const std::string& out, const std::string& heading) {
        const auto at = out.find("correctness (replayed against " + heading);
        const auto end = out.find("all rays", at);
        return at == std::string::npos || end == std::string::npos ? std::string()
                                                                   : out.substr(at, end - at);
    };
    auto rows = [](const std::string& t) { return t.substr(t.find('\n')); };
    auto full = run_isowall(dir_,
                            "render --size 160x120 -q --threads 1 --footprint-pixels 0 "
                            "--against-full --out a.png");
    ASSERT_EQ(full.exit_code, 0) << full.err;
    const std::string own = table(full.out, "the final image"),
                      truth = table(full.out, "the full surface at full resolution");
    ASSERT_FALSE(own.empty()) << full.out;
    ASSERT_FALSE(truth.empty()) << full.out;
    EXPECT_EQ(rows(own), rows(truth)) << full.out;
    auto coarse = run_isowall(dir_,
                              "render --size 160x120 -q --threads 1 --against-full --adaptive "
                              "--adaptive-pixels 8 --no-adaptive-refine "
                              "--out b.png");
    ASSERT_EQ(coarse.exit_code, 0) << coarse.err;
    const std::string coarse_truth = table(coarse.out, "the full surface at full resolution");
    ASSERT_FALSE(coarse_truth.empty()) << coarse.out;
    const auto row = coarse_truth.find("final px = 100%");
    ASSERT_NE(row, std::string::npos) << coarse.out;
    const std::string line = coarse_truth.substr(row, coarse_truth.find('\n', row) - row);
    EXPECT_NE(line.find("not reached"), std::string::npos) << coarse.out;
}

// The warm-up frame (another view, untimed) leaves nothing that changes the timed frame: the same
// image, progressive or full.
TEST_F(Cli, WarmUpFrameLeavesTheTimedFrameAlone) {
    for (const std::string mode : {"", " --full"}) {
        auto cold = run_isowall(dir_, "render --size 160x120 -q --threads 1 --out cold.png" + mode);
        ASSERT_EQ(cold.exit_code, 0) << cold.err;
        EXPECT_EQ(cold.out.find("warm-up"), std::string::npos) << cold.out;
        auto warm = run_isowall(
            dir_, "render --size 160x120 -q --threads 1 --warm-up --out warm.png" + mode);
        ASSERT_EQ(warm.exit_code, 0) << warm.err;
        EXPECT_NE(warm.out.find(mode.empty() ? "warm-up: an untimed frame of the view turned 30"
                                             : "warm-up: the full surface extracted and drawn"),
                  std::string::npos)
            << warm.out;
        const Image a = read_image(dir_ / "cold.png"), b = read_image(dir_ / "warm.png");
        ASSERT_EQ(a.rgba.size(), 160u * 120u * 4u);
        EXPECT_TRUE(a.rgba == b.rgba) << "warm-up changed the image" << mode;
        EXPECT_GT(std::count(a.rgba.begin(), a.rgba.end(), 0), 0);
    }
}

// A user sees how long the picture took to come, the volume's read included: the first picture's
// time from the command's start is at least the load and octree time and at most the whole run.
TEST_F(Cli, RenderPrintsTheFirstPictureFromTheCommandsStart) {
    auto r = run_isowall(dir_, "render --size 160x120 -q --out first.png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto at = r.out.find("first picture: ");
    ASSERT_NE(at, std::string::npos) << r.out;
    double first = -1, load = -1, octree = -1, into = -1;
    ASSERT_EQ(std::sscanf(r.out.c_str() + at,
                          "first picture: %lf s after the command began (volume %lf s, octree "
                          "%lf s; the first group showed %lf s into the frame)",
                          &first, &load, &octree, &into),
              4)
        << r.out.substr(at, 200);
    EXPECT_GE(first, load + octree + into - 1e-3);
    EXPECT_LT(first, 60.0);
}

TEST_F(Cli, HelpListsTheSubcommands) {
    auto r = run_isowall(dir_, "--help");
    EXPECT_EQ(r.exit_code, 0);
    for (const char* sub : {"info", "extract", "render"})
        EXPECT_NE(r.out.find(sub), std::string::npos);
}

}  // namespace
}  // namespace isowall
