// `isowall import` and `--volume STORE` as a user runs them: the picture from a store under a
// small memory limit is the picture from the file, `info` says what the store holds, and a bad
// store or option is one line naming it.
#include <gtest/gtest.h>

#include <fstream>

#include "common/volume/phantom.h"
#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {
namespace fs = std::filesystem;
using test::expect_one_line_error;
using test::run_isowall;
using test::slurp;

// The phantom as a raw file (200x184x168 uint8), the source users give most: a file on disk.
fs::path phantom_raw(const fs::path& dir) {
    const Volume v = make_phantom();
    const fs::path p = dir / "phantom.raw";
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(v.bytes().data()),
               static_cast<std::streamsize>(v.bytes().size()));
    return p;
}

constexpr const char* kRawOptions = " --dims 200 184 168 --type uint8";

TEST(CliStore, ImportThenRenderUnderALimitDrawsThePictureOfTheFile) {
    const fs::path dir = test::scratch_dir("cli_store_render");
    phantom_raw(dir);
    const auto imp = run_isowall(
        dir, std::string("import phantom.raw") + kRawOptions + " --out ph.zarr --cache-dir cache");
    ASSERT_EQ(imp.exit_code, 0) << imp.err;
    EXPECT_NE(imp.out.find("import: wrote ph.zarr  200x184x168 uint8"), std::string::npos)
        << imp.out;
    EXPECT_NE(imp.out.find("import: octree written to ph.zarr/octree.isowall"), std::string::npos)
        << imp.out;

    const auto info = run_isowall(dir, "info --volume ph.zarr --cache-dir cache");
    ASSERT_EQ(info.exit_code, 0) << info.err;
    if (info.out.find("read whole: no paging here") != std::string::npos)
        GTEST_SKIP() << "no userfaultfd here: " << info.out;
    EXPECT_NE(info.out.find("in a store (paged"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("octree: mapped"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("store: Zarr v2 (OME-Zarr 0.4)"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("on disk:"), std::string::npos) << info.out;

    const auto from_store = run_isowall(
        dir,
        "render --volume ph.zarr --iso 50 --size 320x240 --memory-limit 10M --out s.png "
        "--cache-dir cache --no-measure");
    ASSERT_EQ(from_store.exit_code, 0) << from_store.err;
    EXPECT_NE(from_store.out.find("store: bricks:"), std::string::npos) << from_store.out;
    EXPECT_NE(from_store.out.find("of the 10 MiB limit"), std::string::npos) << from_store.out;
    const auto from_file =
        run_isowall(dir, std::string("render --volume phantom.raw") + kRawOptions +
                             " --iso 50 --size 320x240 --out f.png --no-measure");
    ASSERT_EQ(from_file.exit_code, 0) << from_file.err;
    EXPECT_EQ(slurp(dir / "s.png"), slurp(dir / "f.png"));
}

TEST(CliStore, BadStoresAndOptionsAreOneLineEach) {
    const fs::path dir = test::scratch_dir("cli_store_bad");
    phantom_raw(dir);
    ASSERT_EQ(run_isowall(dir, std::string("import phantom.raw") + kRawOptions +
                                   " --out ph.zarr --no-cache -q")
                  .exit_code,
              0);
    expect_one_line_error(run_isowall(dir, "info --volume ph.zarr --memory-limit 12X"),
                          {"--memory-limit", "12X"});
    expect_one_line_error(
        run_isowall(dir, std::string("info --volume phantom.raw --memory-limit 1G") + kRawOptions),
        {"--memory-limit", "store"});
    expect_one_line_error(
        run_isowall(dir, std::string("import phantom.raw") + kRawOptions + " --out ph.zarr"),
        {"ph.zarr", "--force"});
    expect_one_line_error(run_isowall(dir, "import nothing.nrrd --out x.zarr"), {"nothing.nrrd"});
    EXPECT_FALSE(fs::exists(dir / "x.zarr"));
    expect_one_line_error(run_isowall(dir, "import --out y.zarr"), {"source"});
    expect_one_line_error(run_isowall(dir, "import ph.zarr --out copy.zarr"),
                          {"ph.zarr", "a store already"});
    EXPECT_FALSE(fs::exists(dir / "copy.zarr"));

    // A chunk flipped on disk: the frame that reads it ends with the chunk's line, no image.
    {
        std::fstream f(dir / "ph.zarr/0/1/1/0", std::ios::in | std::ios::out | std::ios::binary);
        ASSERT_TRUE(f.good());
        f.seekp(60);
        f.write("garbage!", 8);
    }
    const auto r = run_isowall(dir, "render --volume ph.zarr --iso 50 --no-cache --out bad.png");
    expect_one_line_error(r, {"ph.zarr", "0/1/1/0"});
    EXPECT_FALSE(fs::exists(dir / "bad.png"));
    // A chunk gone: refused before any frame.
    fs::remove(dir / "ph.zarr/0/1/1/0");
    expect_one_line_error(run_isowall(dir, "info --volume ph.zarr --no-cache"),
                          {"ph.zarr", "0/1/1/0", "missing"});
}

}  // namespace
}  // namespace isowall
