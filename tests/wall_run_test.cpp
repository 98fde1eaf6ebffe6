// `isowall wall` under mpirun (5 ranks, oversubscribed): the mosaic of a 2x2 wall equals one view
// of the whole virtual screen, and bad input ends every rank with a non-zero exit, never a hang.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>

#include "tests/test_util.h"
#include "tile/image_io.h"

namespace isowall {
namespace {

// Runs a command under `timeout` (the test guards against hangs itself) and returns its exit code.
int run(const std::string& cmd, const std::filesystem::path& log) {
    const std::string full = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 120 " + cmd +
                             " > '" + log.string() + "' 2>&1";
    const int status = std::system(full.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string mpirun(int np) {
    return "mpirun --oversubscribe -np " + std::to_string(np) + " '" + std::string(ISOWALL_BINARY) + "' ";
}

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(WallRun, MosaicOfA2x2WallEqualsOneViewOfTheVirtualScreen) {
    const auto dir = test::scratch_dir("wall_mosaic");
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [160, 120]\n";
    ASSERT_EQ(run(mpirun(5) + "wall --wall '" + (dir / "2x2.toml").string() + "' --out '" +
                      (dir / "mosaic.png").string() + "'",
                  dir / "wall.log"),
              0)
        << slurp(dir / "wall.log");
    ASSERT_EQ(run("'" + std::string(ISOWALL_BINARY) + "' render --size 320x240 -q --no-measure --out '" +
                      (dir / "single.png").string() + "'",
                  dir / "render.log"),
              0)
        << slurp(dir / "render.log");
    const Image mosaic = read_image(dir / "mosaic.png");
    const Image single = read_image(dir / "single.png");
    ASSERT_EQ(mosaic.width, single.width);
    ASSERT_EQ(mosaic.height, single.height);
    std::size_t inter = 0, uni = 0, equal = 0;
    for (std::size_t i = 0; i < single.pixel_count(); ++i) {
        bool a = false, b = false, same = true;
        for (int k = 0; k < 3; ++k) {
            a = a || mosaic.rgba[4 * i + k] > 0;
            b = b || single.rgba[4 * i + k] > 0;
            same = same && std::abs(int(mosaic.rgba[4 * i + k]) - int(single.rgba[4 * i + k])) <= 1;
        }
        inter += a && b;
        uni += a || b;
        equal += same;
    }
    const double iou = double(inter) / double(uni), share = double(equal) / double(single.pixel_count());
    EXPECT_GE(iou, 0.999);
    EXPECT_GE(share, 0.999);
    std::cout << "mosaic vs single view: mask IoU " << iou << ", " << 100 * share << "% of pixels equal\n";
    const std::string log = slurp(dir / "wall.log");
    EXPECT_NE(log.find("rank  4 -> tile  3"), std::string::npos) << log;
    EXPECT_NE(log.find("makespan"), std::string::npos) << log;
}

TEST(WallRun, BadInputEndsEveryRank) {
    const auto dir = test::scratch_dir("wall_bad");
    std::ofstream(dir / "2x2.toml") << "tiles = [2, 2]\ntile_size_px = [64, 48]\n";
    std::ofstream(dir / "bad.toml") << "tiles = [2, 0]\ntile_size_px = [64, 48]\n";
    const std::string wall = " wall --wall '" + (dir / "2x2.toml").string() + "' --out '" + (dir / "m.png").string() + "'";
    struct Case {
        std::string name, cmd, expect;
    };
    const Case cases[] = {
        {"wrong rank count", mpirun(3) + wall, "needs mpirun -np 5"},
        {"bad wall file", mpirun(5) + " wall --wall '" + (dir / "bad.toml").string() + "'", "tiles"},
        {"missing volume", mpirun(5) + wall + " -v '" + (dir / "nope.nhdr").string() + "' --iso 1", "nope.nhdr"},
        {"isovalue out of range", mpirun(5) + wall + " --iso 999", "--iso"},
    };
    for (const Case& c : cases) {
        const int rc = run(c.cmd, dir / "log.txt");
        const std::string log = slurp(dir / "log.txt");
        EXPECT_NE(rc, 0) << c.name << ": " << log;
        EXPECT_NE(rc, 124) << c.name << " timed out: " << log;
        EXPECT_NE(log.find(c.expect), std::string::npos) << c.name << ": " << log;
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "m.png"));
}

}  // namespace
}  // namespace isowall
