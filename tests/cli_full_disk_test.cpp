// A full disk: a 1 MiB tmpfs (mounted by the test, root only, as in CI). Every command that writes
// a file there fails with one line naming the file and the cause, a non-zero exit, and leaves
// nothing: no cut-off image that looks written (once a PNG without its end and exit 0).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "tests/cli_util.h"
#include "tests/run_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;

class FullDisk : public testing::Test {
  protected:
    void SetUp() override {
        // A folder of the test's own: CTest runs the two tests side by side. A run stopped
        // before its TearDown may have left its tmpfs mounted.
        const std::string name = std::string("full_disk_") +
                                 testing::UnitTest::GetInstance()->current_test_info()->name();
        const fs::path left = fs::absolute(fs::path("scratch") / name / "disk");
        std::system(("umount '" + left.string() + "' 2>/dev/null").c_str());
        dir_ = fs::absolute(test::scratch_dir(name));
        disk_ = dir_ / "disk";
        fs::create_directories(disk_);
        if (::geteuid() != 0) GTEST_SKIP() << "needs root to mount a 1 MiB tmpfs";
        const std::string mount = "mount -t tmpfs -o size=1m tmpfs '" + disk_.string() + "'";
        if (std::system(mount.c_str()) != 0) GTEST_SKIP() << "cannot mount a tmpfs here";
        mounted_ = true;
    }
    void TearDown() override {
        if (mounted_) std::system(("umount '" + disk_.string() + "'").c_str());
    }

    // The run failed, with one line naming `file` and the full disk, and the disk is empty.
    void expect_clean_failure(const std::string& what, int code, const std::string& err,
                              const std::string& file) {
        SCOPED_TRACE(what);
        EXPECT_NE(code, 0) << err;
        EXPECT_NE(code, 124) << "timed out";
        EXPECT_EQ(test::count_of(err, "isowall: error:"), 1u) << err;
        EXPECT_NE(err.find((disk_ / file).string() + ": cannot write: No space left on device"),
                  std::string::npos)
            << err;
        EXPECT_TRUE(fs::is_empty(disk_)) << "left on the disk: " << test::files_in(disk_).size();
    }

    fs::path dir_, disk_;
    bool mounted_ = false;
};

TEST_F(FullDisk, RenderAndExtractFailNamingTheFileAndLeaveNothing) {
    const test::RunResult big =
        test::run_isowall(dir_, "render --size 4000x3000 -q --no-measure --out '" +
                                    (disk_ / "big.png").string() + "'");
    expect_clean_failure("render", big.exit_code, big.err, "big.png");
    const test::RunResult ply = test::run_isowall(
        dir_, "extract --iso 80 --out '" + (disk_ / "surface.ply").string() + "'");
    expect_clean_failure("extract", ply.exit_code, ply.err, "surface.ply");
    // What fits is written whole.
    const test::RunResult small =
        test::run_isowall(dir_, "render --size 160x120 -q --no-measure --out '" +
                                    (disk_ / "small.png").string() + "'");
    EXPECT_EQ(small.exit_code, 0) << small.err;
    EXPECT_TRUE(fs::exists(disk_ / "small.png"));
}

// A store that does not fit: noise does not compress, so 4 MiB of it fills the disk.
TEST_F(FullDisk, AnImportFailsNamingTheStoreAndLeavesNothing) {
    {
        std::ofstream raw(dir_ / "noise.raw", std::ios::binary);
        std::uint32_t x = 12345;
        for (int i = 0; i < (4 << 20); ++i) {
            x = x * 1664525u + 1013904223u;
            raw.put(static_cast<char>(x >> 24));
        }
    }
    const test::RunResult r = test::run_isowall(
        dir_, "import noise.raw --dims 256 256 64 --type uint8 -q --no-cache --out '" +
                  (disk_ / "noise.zarr").string() + "'");
    SCOPED_TRACE("import");
    EXPECT_NE(r.exit_code, 0) << r.err;
    EXPECT_NE(r.exit_code, 124) << "timed out";
    EXPECT_EQ(test::count_of(r.err, "isowall: error:"), 1u) << r.err;
    EXPECT_NE(r.err.find((disk_ / "noise.zarr").string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(disk_)) << "left on the disk: " << test::files_in(disk_).size();
}

TEST_F(FullDisk, TheWallsMosaicFailsNamingTheFileAndEveryRankEnds) {
    std::ofstream(dir_ / "big.toml") << "tiles = [2, 2]\ntile_size_px = [2000, 1500]\n";
    const fs::path log = dir_ / "wall.log";
    const int code = test::run(test::mpirun(5) + "wall --wall '" + (dir_ / "big.toml").string() +
                                   "' --out '" + (disk_ / "mosaic.png").string() + "'",
                               log, 300);
    expect_clean_failure("wall", code, test::slurp(log), "mosaic.png");
}

}  // namespace
}  // namespace isowall
