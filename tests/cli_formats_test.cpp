// The readers of other formats through the program: a good file of each shared format renders
// and `info` names what it carried; a bad one is one line naming the file and the field, a
// non-zero exit and no image.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>

#include "tests/cli_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

using test::expect_one_line_error;
using test::run_isowall;

// A NIfTI-1 file (.nii) of n^3 uint8 voxels (a ramp along x), with only `data_bytes` written.
void write_nifti(const std::filesystem::path& path, int n, std::size_t data_bytes,
                 float slope = 0) {
    char h[352] = {};
    const auto put = [&](std::size_t at, auto v) { std::memcpy(h + at, &v, sizeof v); };
    put(0, std::int32_t(348));  // sizeof_hdr
    const std::int16_t dims[8] = {3, std::int16_t(n), std::int16_t(n), std::int16_t(n), 1, 1, 1, 1};
    std::memcpy(h + 40, dims, sizeof dims);
    put(70, std::int16_t(2));  // datatype: uint8
    put(72, std::int16_t(8));  // bitpix
    const float pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    std::memcpy(h + 76, pixdim, sizeof pixdim);
    put(108, 352.0f);  // vox_offset
    put(112, slope);   // scl_slope
    std::memcpy(h + 344, "n+1", 4);
    std::ofstream out(path, std::ios::binary);
    out.write(h, sizeof h);
    std::string data(data_bytes, '\0');
    for (std::size_t i = 0; i < data_bytes; ++i) data[i] = char((i % std::size_t(n)) * 12);
    out.write(data.data(), std::streamsize(data_bytes));
}

class CliFormats : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = test::scratch_dir(std::string("cli_formats_") +
                                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
    }
    std::filesystem::path dir_;
};

TEST_F(CliFormats, AGoodNiftiRendersAndABadOneIsOneLine) {
    write_nifti(dir_ / "good.nii", 16, 16 * 16 * 16);
    auto ok =
        run_isowall(dir_, "render -v good.nii --iso 30 --size 64x48 --no-measure --out a.png");
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_TRUE(std::filesystem::exists(dir_ / "a.png"));

    write_nifti(dir_ / "short.nii", 64, 100);
    auto r = run_isowall(dir_, "render -v short.nii --iso 30 --out b.png");
    expect_one_line_error(r, {"short.nii", "dim", "the file holds"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "b.png"));

    write_nifti(dir_ / "nan.nii", 16, 16 * 16 * 16, std::nanf(""));
    r = run_isowall(dir_, "render -v nan.nii --iso 30 --out c.png");
    expect_one_line_error(r, {"nan.nii", "scl_slope", "not a finite number"});
    EXPECT_FALSE(std::filesystem::exists(dir_ / "c.png"));

    r = run_isowall(dir_, "info -v notes.txt");
    expect_one_line_error(r, {"notes.txt", "file", "no such file"});
}

TEST_F(CliFormats, TheSharedFilesRenderAndInfoSaysWhatTheyCarried) {
    const auto data = test::shared_data_dir();
    if (!data || !std::filesystem::exists(*data / "formats"))
        GTEST_SKIP() << "../shared/data/formats absent";
    const std::string f = (*data / "formats").string();
    auto r = run_isowall(dir_, "info --no-cache -v " + f + "/mrhead_t1_dicom");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* line : {"format: DICOM", "modality: MR", "(120 files)", "orientation: LPS"})
        EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
    r = run_isowall(dir_, "info --no-cache -v " + f + "/ct_pitch.nii.gz");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("orientation from: sform"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("patient bounds:"), std::string::npos) << r.out;
    r = run_isowall(dir_, "render --no-cache -v " + f +
                              "/engine.nii.gz --iso 80 --size 80x60 --no-measure --out e.png");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(std::filesystem::exists(dir_ / "e.png"));
}

}  // namespace
}  // namespace isowall
