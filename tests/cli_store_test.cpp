// `isowall import` and `--volume STORE` as a user runs them: the picture from a store under a
// small memory limit is the picture from the file, `info` says what the store holds, and a bad
// store or option is one line naming it.
#include <gtest/gtest.h>

#include <zlib.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <vector>

#include "tests/cli_util.h"
#include "tests/test_util.h"
#include "volume/phantom.h"

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
    // A malformed size is a bad command line (exit 2), whatever its spelling.
    for (const char* bad : {"12X", "0x100000000", "' 512M'", "''", "-1G", "1e3M"}) {
        const test::RunResult r =
            run_isowall(dir, std::string("info --volume ph.zarr --memory-limit ") + bad);
        expect_one_line_error(r, {"--memory-limit"});
        EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    }
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

// The peak resident memory `import` prints, in MiB (-1 when it prints none).
double peak_mib(const std::string& out) {
    const std::size_t at = out.find("peak resident memory ");
    return at == std::string::npos ? -1 : std::stod(out.substr(at + 21));
}

// A gzip NRRD of `n` x `n` x `depth` uint8 voxels (a few smooth waves), written a plane at a time.
void write_gzip_nrrd(const fs::path& p, int n, int depth) {
    std::ofstream out(p, std::ios::binary);
    out << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << n << " " << n << " " << depth
        << "\nencoding: gzip\n\n";
    z_stream z{};
    ASSERT_EQ(deflateInit2(&z, 1, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::vector<unsigned char> plane(std::size_t(n) * n), packed(1 << 20);
    for (int k = 0; k < depth; ++k) {
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                plane[std::size_t(y) * n + x] = static_cast<unsigned char>(
                    128 + 40 * (std::sin(x / 23.0) + std::cos(y / 17.0) + std::sin(k / 29.0)));
        z.next_in = plane.data();
        z.avail_in = uInt(plane.size());
        do {
            z.next_out = packed.data();
            z.avail_out = uInt(packed.size());
            deflate(&z, k + 1 == depth ? Z_FINISH : Z_NO_FLUSH);
            out.write(reinterpret_cast<const char*>(packed.data()),
                      std::streamsize(packed.size() - z.avail_out));
        } while (z.avail_out == 0);
    }
    deflateEnd(&z);
}

// A format decoded by a library (here gzip NRRD; every reader's planes are checked against its
// whole read in the formats tests) streams into the store: the import's memory grows by a slab
// of planes, not by the volume. The phantom's mapped import gives the process's own size.
TEST(CliStore, AGzipVolumeImportsASlabAtATimeInBoundedMemory) {
    const fs::path dir = test::scratch_dir("cli_store_stream");
    phantom_raw(dir);
    const auto small =
        run_isowall(dir, std::string("import phantom.raw") + kRawOptions + " --out ph.zarr -q");
    ASSERT_EQ(small.exit_code, 0) << small.err;
    write_gzip_nrrd(dir / "big.nrrd", 512, 384);  // 96 MiB of voxels
    const auto big = run_isowall(dir, "import big.nrrd --out big.zarr -q");
    ASSERT_EQ(big.exit_code, 0) << big.err;
    EXPECT_NE(big.out.find("import: wrote big.zarr  512x512x384 uint8"), std::string::npos)
        << big.out;
    EXPECT_NE(big.out.find("source decoded a slab of planes at a time"), std::string::npos)
        << big.out;
    const double base = peak_mib(small.out), peak = peak_mib(big.out);
    ASSERT_GT(base, 0) << small.out;
    std::printf(
        "import peak resident memory: %.0f MiB for 96 MiB of gzip NRRD, %.0f MiB for "
        "the 6 MiB phantom mapped\n",
        peak, base);
    EXPECT_LT(peak - base, 48) << "the import held more than half the volume";
}

// A source that fails part-way through a streamed import (gzip cut short: the planes of the first
// slabs decode, a later one cannot) is one line naming the file; no store and no temporary folder
// are left.
TEST(CliStore, ASourceThatFailsMidStreamLeavesNoStore) {
    const fs::path dir = test::scratch_dir("cli_store_stream_fail");
    write_gzip_nrrd(dir / "whole.nrrd", 128, 160);
    const std::string whole = slurp(dir / "whole.nrrd");
    std::ofstream(dir / "cut.nrrd", std::ios::binary) << whole.substr(0, whole.size() * 3 / 4);
    const auto r = run_isowall(dir, "import cut.nrrd --out cut.zarr -q");
    expect_one_line_error(r, {"cut.nrrd", "data", "ends early"});
    EXPECT_FALSE(fs::exists(dir / "cut.zarr"));
    EXPECT_FALSE(fs::exists(dir / ".cut.zarr.importing"));
}

// A stop signal mid-import (SIGTERM, which the import raises itself after its first slab, as an
// operator's kill would arrive) ends it by that signal: its temporary folder removed, no store.
TEST(CliStore, ASignalMidImportEndsItByThatSignalLeavingNothing) {
    const fs::path dir = test::scratch_dir("cli_store_signal");
    phantom_raw(dir);
    const auto r =
        run_isowall(dir, std::string("import phantom.raw") + kRawOptions + " --out ph.zarr -q",
                    "env ISOWALL_TEST_FAULT=term@slab:0 ");
    EXPECT_EQ(r.exit_code, 128 + SIGTERM) << r.err;
    EXPECT_NE(r.err.find("import: stopped; "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(".ph.zarr.importing removed, no store written (signal 15)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(test::files_in(dir), std::vector<std::string>{"phantom.raw"});
}

TEST(CliStore, AnEmptyOutIsABadCommandLine) {
    const fs::path dir = test::scratch_dir("cli_store_empty_out");
    phantom_raw(dir);
    const auto r = run_isowall(dir, std::string("import phantom.raw") + kRawOptions + " --out ''");
    expect_one_line_error(r, {"--out", "name the store folder to write"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
}

}  // namespace
}  // namespace isowall
