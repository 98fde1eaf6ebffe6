// The readers of other formats against the shared files' twins (readers/): a scanner's
// DICOM series (and the same re-encoded to JPEG-LS and JPEG 2000 with GDCM here), NIfTI twins,
// the value scaling, the orientation, and the bad files of the issue "Bring your own data".
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>
#include <span>
#include <tuple>

#include <gdcmImageChangeTransferSyntax.h>
#include <gdcmImageReader.h>
#include <gdcmImageWriter.h>
#include <gdcmReader.h>
#include <gdcmWriter.h>
#include <gtest/gtest.h>
#include <nifti2_io.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "core/error.h"
#include "extract/surface_extractor.h"
#include "readers/dicom_lengths.h"
#include "readers/read_volume.h"
#include "readers/voxel_ops.h"
#include "tests/plane_stream_util.h"
#include "tests/test_util.h"

namespace isowall::test {
namespace {

namespace fs = std::filesystem;
using formats::read_volume;

std::optional<fs::path> formats_dir() {
    const auto d = shared_data_dir();
    if (!d || !fs::exists(*d / "formats")) return std::nullopt;
    return *d / "formats";
}

#define NEED_FORMATS(dir)           \
    const auto dir = formats_dir(); \
    if (!dir) GTEST_SKIP() << "../shared/data/formats absent: the readers' twins are there"

Volume twin(const std::string& name) {
    return load_nrrd(*shared_data_dir() / (name + ".nhdr"));
}

void expect_same_voxels(const Volume& a, const Volume& b) {
    ASSERT_EQ(a.dims(), b.dims());
    ASSERT_EQ(a.type(), b.type());
    ASSERT_EQ(a.bytes().size(), b.bytes().size());
    EXPECT_EQ(std::memcmp(a.bytes().data(), b.bytes().data(), a.bytes().size()), 0)
        << a.source() << " and " << b.source() << " differ in their voxels";
}

std::string error_of(const std::string& path) {
    try {
        read_volume(path, std::nullopt);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(FormatsDicom, TheScannersSeriesEqualsItsRawTwin) {
    NEED_FORMATS(dir);
    const Volume v = read_volume((*dir / "mrhead_t1_dicom").string(), std::nullopt);
    expect_same_voxels(v, twin("mrhead_t1"));
    EXPECT_NEAR(v.spacing().x, 0.41015625, 1e-6);
    EXPECT_NEAR(v.spacing().z, 1.5, 1e-4);
    EXPECT_EQ(v.files().size(), 120u);
    EXPECT_TRUE(v.orientation().known);
    EXPECT_EQ(formats::orientation_letters(v.orientation().axes), "LPS");
    // What `import` streams: decoded in a child process, slice by slice, handed over a pipe.
    test::expect_streams_alike((*dir / "mrhead_t1_dicom").string());
}

TEST(FormatsDicom, OneFileOfTheSeriesReadsTheWholeSeries) {
    NEED_FORMATS(dir);
    const Volume v = read_volume((*dir / "mrhead_t1_dicom" / "1-077.dcm").string(), std::nullopt);
    EXPECT_EQ(v.dims(), glm::ivec3(512, 512, 120));
}

// Every file of the series through GDCM's change of transfer syntax (the encoders GDCM links:
// CharLS for JPEG-LS, OpenJPEG for JPEG 2000), read back voxel for voxel.
fs::path reencoded_series(const fs::path& from, const gdcm::TransferSyntax& ts,
                          const std::string& name) {
    const fs::path out = scratch_dir(name);
    for (const auto& e : fs::directory_iterator(from)) {
        gdcm::ImageReader r;
        r.SetFileName(e.path().c_str());
        EXPECT_TRUE(r.Read()) << e.path();
        gdcm::ImageChangeTransferSyntax change;
        change.SetTransferSyntax(ts);
        change.SetInput(r.GetImage());
        EXPECT_TRUE(change.Change()) << "GDCM could not encode " << e.path();
        gdcm::ImageWriter w;
        w.SetFileName((out / e.path().filename()).c_str());
        w.SetFile(r.GetFile());
        w.SetImage(change.GetOutput());
        EXPECT_TRUE(w.Write());
    }
    return out;
}

TEST(FormatsDicom, JpegLsAndJpeg2000SeriesEqualTheRawTwin) {
    NEED_FORMATS(dir);
    const Volume raw = twin("mrhead_t1");
    for (const auto& [ts, uid] :
         {std::pair{gdcm::TransferSyntax::JPEGLSLossless, "1.2.840.10008.1.2.4.80"},
          std::pair{gdcm::TransferSyntax::JPEG2000Lossless, "1.2.840.10008.1.2.4.90"}}) {
        const fs::path series =
            reencoded_series(*dir / "mrhead_t1_dicom", gdcm::TransferSyntax(ts), uid);
        const Volume v = read_volume(series.string(), std::nullopt);
        expect_same_voxels(v, raw);
        test::expect_streams_alike(series.string());
        std::string syntax;
        for (const VolumeFact& f : v.facts())
            if (f.name == "transfer syntax") syntax = f.value;
        EXPECT_NE(syntax.find(uid), std::string::npos) << "read as " << syntax;
    }
}

// The series copied into a scratch folder, `change` applied to the data set of each file it
// names (by index in name order), `drop` files left out.
fs::path series_copy(const fs::path& from, const std::string& name,
                     const std::map<int, std::function<void(gdcm::DataSet&)>>& change,
                     const std::set<int>& drop = {}) {
    const fs::path out = scratch_dir(name);
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(from)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (int i = 0; i < int(files.size()); ++i) {
        if (drop.count(i)) continue;
        const auto c = change.find(i);
        if (c == change.end()) {
            fs::copy_file(files[i], out / files[i].filename());
            continue;
        }
        gdcm::Reader r;
        r.SetFileName(files[i].c_str());
        EXPECT_TRUE(r.Read());
        c->second(r.GetFile().GetDataSet());
        gdcm::Writer w;
        w.SetFileName((out / files[i].filename()).c_str());
        w.SetFile(r.GetFile());
        EXPECT_TRUE(w.Write());
    }
    return out;
}

void set_text(gdcm::DataSet& ds, gdcm::Tag tag, std::string value) {
    if (value.size() % 2) value += ' ';
    gdcm::DataElement e(tag);
    e.SetByteValue(value.data(), gdcm::VL(std::uint32_t(value.size())));
    ds.Replace(e);
}

// Other files beside a series are judged by their first 132 bytes: a 3 GiB file (sparse, so it
// costs no disk) is not read whole to find it is not DICOM. A FIFO where a slice belongs is
// named; opening it to read would wait for a writer for ever.
TEST(FormatsDicom, OtherFilesBesideASeriesCostNothingAndAFifoIsNamed) {
    NEED_FORMATS(dir);
    const fs::path big = series_copy(*dir / "mrhead_t1_dicom", "dicom_big_neighbour", {});
    {
        std::ofstream(big / "scan_notes.bin") << "not DICOM";
        fs::resize_file(big / "scan_notes.bin", std::uintmax_t(3) << 30);
    }
    EXPECT_EQ(read_volume(big.string(), std::nullopt).dims(), glm::ivec3(512, 512, 120));
    rusage self{}, children{};
    getrusage(RUSAGE_SELF, &self);
    getrusage(RUSAGE_CHILDREN, &children);
    EXPECT_LT(std::max(self.ru_maxrss, children.ru_maxrss), 1L << 20)
        << "KiB: the 3 GiB neighbour was read";
    fs::remove(big / "scan_notes.bin");
    const fs::path fifo = series_copy(*dir / "mrhead_t1_dicom", "dicom_fifo", {}, {60});
    ASSERT_EQ(::mkfifo((fifo / "1-061.dcm").c_str(), 0644), 0);
    const std::string e = error_of(fifo.string());
    EXPECT_NE(e.find("1-061.dcm: DICOM: "), std::string::npos) << e;
    EXPECT_NE(e.find("is a FIFO, not a regular file"), std::string::npos) << e;
}

struct BadSeries {
    std::string name;
    std::map<int, std::function<void(gdcm::DataSet&)>> change;
    std::set<int> drop;
    std::vector<std::string> expect;  // pieces of the one error line
};

TEST(FormatsDicom, BadSeriesGetOneLineNamingTheFileAndTheField) {
    NEED_FORMATS(dir);
    const auto other_series = [](gdcm::DataSet& ds) {
        set_text(ds, gdcm::Tag(0x0020, 0x000e), "1.2.3.4.5.6.7");
        set_text(ds, gdcm::Tag(0x0020, 0x0011), "7");
    };
    std::string position_of_10;
    {
        gdcm::Reader r;
        r.SetFileName((*dir / "mrhead_t1_dicom" / "1-011.dcm").c_str());
        ASSERT_TRUE(r.Read());
        const gdcm::ByteValue* v =
            r.GetFile().GetDataSet().GetDataElement(gdcm::Tag(0x0020, 0x0032)).GetByteValue();
        ASSERT_TRUE(v);
        position_of_10.assign(v->GetPointer(), v->GetLength());
    }
    std::vector<BadSeries> cases = {
        {"missing_slice", {}, {60}, {"1-062.dcm: ImagePositionPatient", "slices are missing"}},
        {"two_series",
         {{0, other_series}, {1, other_series}},
         {},
         {"SeriesInstanceUID", "2 series in one folder", "series 7"}},
        {"mixed_sizes",
         {{5,
           [](gdcm::DataSet& ds) {
               const std::uint16_t rows = 256;
               gdcm::DataElement e(gdcm::Tag(0x0028, 0x0010));
               e.SetByteValue(reinterpret_cast<const char*>(&rows), 2);
               ds.Replace(e);
           }}},
         {},
         {"Rows/Columns", "512x256"}},
        {"no_pixel_data",
         {{3, [](gdcm::DataSet& ds) { ds.Remove(gdcm::Tag(0x7fe0, 0x0010)); }}},
         {},
         {"1-004.dcm: PixelData"}},
        {"same_position",
         {{9, [&](gdcm::DataSet& ds) { set_text(ds, gdcm::Tag(0x0020, 0x0032), position_of_10); }}},
         {},
         {"ImagePositionPatient", "the same position as"}},
    };
    // A scaling GDCM would read as 1 (or some number) is named as the header holds it.
    const gdcm::Tag slope(0x0028, 0x1053), intercept(0x0028, 0x1052);
    for (const auto& [text, tag, words] :
         {std::tuple{"NaN", slope, "1-005.dcm: RescaleSlope: expected one finite decimal number"},
          std::tuple{"inf", slope, "1-005.dcm: RescaleSlope: expected one finite"},
          std::tuple{"abc", slope, "1-005.dcm: RescaleSlope: expected one finite"},
          std::tuple{"1e400", slope, "1-005.dcm: RescaleSlope: expected one finite"},
          std::tuple{"0", slope, "1-005.dcm: RescaleSlope: a slope of 0"},
          std::tuple{"-1e999", intercept, "1-005.dcm: RescaleIntercept: expected one finite"}})
        cases.push_back({"bad_scaling",
                         {{4, [tag, text](gdcm::DataSet& ds) { set_text(ds, tag, text); }}},
                         {},
                         {words}});
    for (std::size_t k = 0; k < cases.size(); ++k) {
        const BadSeries& c = cases[k];
        const fs::path series = series_copy(*dir / "mrhead_t1_dicom",
                                            c.name + "_" + std::to_string(k), c.change, c.drop);
        const std::string e = error_of(series.string());
        for (const std::string& piece : c.expect)
            EXPECT_NE(e.find(piece), std::string::npos) << c.name << ": " << e;
    }
}

// The check before GDCM reads a file (readers/dicom_lengths.h): a scanner's file passes;
// the same with one element's length raised past the end of the file, or an item tag put where
// a data element belongs, is named.
TEST(FormatsDicom, DeclaredLengthsAreCheckedBeforeGdcmReads) {
    NEED_FORMATS(dir);
    std::ifstream in(*dir / "mrhead_t1_dicom" / "1-001.dcm", std::ios::binary);
    std::vector<char> text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(formats::dicom_length_problem(std::as_bytes(std::span(text))), "");
    // The data set is implicit VR: tag (4 bytes), length (4 bytes). Find (0008,0060) Modality.
    const std::string modality("\x08\x00\x60\x00", 4);
    const auto at = std::search(text.begin() + 132, text.end(), modality.begin(), modality.end());
    ASSERT_NE(at, text.end());
    std::vector<char> long_one = text;
    const std::uint32_t huge = 0xfffffff0;
    std::memcpy(&long_one[std::size_t(at - text.begin()) + 4], &huge, 4);
    const std::string p = formats::dicom_length_problem(std::as_bytes(std::span(long_one)));
    EXPECT_NE(p.find("element (0008,0060) declares 4294967280 bytes"), std::string::npos) << p;
    std::vector<char> item_tag = text;
    const char item[] = {'\xfe', '\xff', '\x00', '\xe0'};
    std::memcpy(&item_tag[std::size_t(at - text.begin())], item, 4);
    EXPECT_NE(formats::dicom_length_problem(std::as_bytes(std::span(item_tag)))
                  .find("outside any sequence"),
              std::string::npos);
    EXPECT_NE(formats::dicom_length_problem(std::as_bytes(std::span(text).first(100))).find("DICM"),
              std::string::npos);
}

TEST(FormatsNifti, EngineAndHeptaneEqualTheirRawTwins) {
    NEED_FORMATS(dir);
    for (const std::string name : {"engine", "heptane"}) {
        const Volume v = read_volume((*dir / (name + ".nii.gz")).string(), std::nullopt);
        expect_same_voxels(v, twin(name));
        EXPECT_EQ(v.spacing(), glm::vec3(1.0f)) << name;
        test::expect_streams_alike((*dir / (name + ".nii.gz")).string());  // a gzip stream
    }
}

// A small NIfTI-1 written through niftilib: a ball of uint8 values, with the given scaling.
fs::path write_nifti(const fs::path& path, float slope, float inter, int n = 24) {
    const int64_t dims[8] = {3, n, n, n, 1, 1, 1, 1};
    nifti_image* nim = nifti_make_new_nim(dims, DT_UINT8, 1);
    auto* data = static_cast<std::uint8_t*>(nim->data);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double r = std::hypot(x - n / 2.0, y - n / 2.0, z - n / 2.0);
                data[(z * n + y) * n + x] = std::uint8_t(std::max(0.0, 200 - 20 * r));
            }
    nim->scl_slope = slope;
    nim->scl_inter = inter;
    nifti_set_filenames(nim, path.c_str(), 0, 1);
    nifti_image_write(nim);
    nifti_image_free(nim);
    return path;
}

TEST(FormatsNifti, AScaleOf2Point5GivesTheSameSurfaceAt2Point5TimesTheIsovalue) {
    const fs::path dir = scratch_dir("nifti_scale");
    const Volume plain = read_volume(write_nifti(dir / "plain.nii", 0, 0).string(), std::nullopt);
    const Volume scaled =
        read_volume(write_nifti(dir / "scaled.nii", 2.5f, 0).string(), std::nullopt);
    EXPECT_EQ(plain.type(), VoxelType::u8);
    EXPECT_EQ(scaled.type(), VoxelType::f32) << "2.5 is not an integer slope";
    const Mesh a = make_surface_extractor(plain)->extract_full(100);
    const Mesh b = make_surface_extractor(scaled)->extract_full(250);
    ASSERT_GT(a.triangle_count(), 100u);
    ASSERT_EQ(a.triangle_count(), b.triangle_count());
    for (std::size_t i = 0; i < a.positions.size(); ++i)
        ASSERT_LT(glm::length(a.positions[i] - b.positions[i]), 1e-4f) << "vertex " << i;
}

TEST(FormatsNifti, AnIntegerScaleWidensOnlyAsFarAsTheValuesNeed) {
    const fs::path dir = scratch_dir("nifti_widen");
    // 0..200 * 1 - 1024: int16, as a CT's Hounsfield units.
    const Volume v = read_volume(write_nifti(dir / "ct.nii", 1, -1024).string(), std::nullopt);
    EXPECT_EQ(v.type(), VoxelType::i16);
    EXPECT_EQ(v.view<std::int16_t>().at(12, 12, 12), 200 - 1024);
    // A stream chooses its type before a voxel: from uint8's range, -1024..-769 is int16 too.
    const auto planes = formats::open_planes((dir / "ct.nii").string(), std::nullopt);
    EXPECT_EQ(planes->type(), VoxelType::i16);
    test::expect_planes_equal(*planes, v);
}

TEST(FormatsNifti, ANanScaleIsNamed) {
    const fs::path dir = scratch_dir("nifti_nan");
    const fs::path p = write_nifti(dir / "nan.nii", 1, 0);
    {
        // scl_slope is the float at byte 112 of a NIfTI-1 header.
        std::fstream f(p, std::ios::in | std::ios::out | std::ios::binary);
        const float nan = std::nanf("");
        f.seekp(112);
        f.write(reinterpret_cast<const char*>(&nan), sizeof nan);
    }
    const std::string e = error_of(p.string());
    EXPECT_NE(e.find("nan.nii: scl_slope: "), std::string::npos) << e;
    EXPECT_NE(e.find("not a finite number"), std::string::npos) << e;
}

void put_float(const fs::path& p, int at, float v) {
    std::fstream f(p, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(at);
    f.write(reinterpret_cast<const char*>(&v), sizeof v);
}

// vox_offset (the float at byte 108 of a NIfTI-1 header) must be a whole byte count past the
// header and inside the file: niftilib casts it to an integer, so NaN, 1e10 or 352.5 read the
// voxels from some other place.
TEST(FormatsNifti, AVoxOffsetThatIsNoPlaceInTheFileIsNamed) {
    const fs::path dir = scratch_dir("nifti_offset");
    const std::vector<std::pair<float, std::string>> cases = {
        {std::nanf(""), "expected a whole number of bytes"},
        {INFINITY, "expected a whole number of bytes"},
        {-1, "expected a whole number of bytes"},
        {352.5f, "expected a whole number of bytes"},
        {1e10f, "the voxels start at byte 10000000000, past the end of the file"},
        {100, "100 lies inside the 352-byte header"},
        {400, "end at byte 14224, the file holds 14176 (a truncated file)"},
    };
    for (const auto& [offset, words] : cases) {
        const fs::path p = write_nifti(dir / "offset.nii", 1, 0);
        put_float(p, 108, offset);
        const std::string e = error_of(p.string());
        EXPECT_EQ(e.rfind(p.string() + ": ", 0), 0u) << offset << ": " << e;
        EXPECT_NE(e.find(words), std::string::npos) << offset << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

// A scaling whose values overflow the type they land in is named, whole or streamed: 200 *
// 1e38 is past float32's 3.4e38.
TEST(FormatsNifti, AScaleThatOverflowsIsNamed) {
    const fs::path dir = scratch_dir("nifti_overflow");
    const fs::path p = write_nifti(dir / "big.nii", 1e38f, 0.5f);
    const std::string e = error_of(p.string());
    EXPECT_NE(e.find("big.nii: scl_slope: "), std::string::npos) << e;
    EXPECT_NE(e.find("overflows float32"), std::string::npos) << e;
    try {
        formats::open_planes(p.string(), std::nullopt);
        ADD_FAILURE() << "a stream of big.nii opened";
    } catch (const InputError& s) {
        const std::string what = s.what();
        EXPECT_NE(what.find("big.nii: scl_slope: value = "), std::string::npos) << what;
        EXPECT_NE(what.find(" overflows float32 for stored values in [0, 255]"), std::string::npos)
            << what;
    }
}

// A gzip stream proves its length only as it is inflated, and its trailer holds the length
// modulo 2^32: a header alone that claims 4096x4096x512 uint8 (8 GiB, 0 modulo 2^32) is read
// until it ends, not zero-filled to what it claims first.
TEST(FormatsNifti, AGzipFileClaimingGigabytesEndsWhereItsBytesDo) {
    const fs::path dir = scratch_dir("nifti_gzip_claim");
    const fs::path plain = write_nifti(dir / "small.nii", 0, 0);
    std::ifstream in(plain, std::ios::binary);
    std::vector<char> header(352);
    in.read(header.data(), 352);
    for (const auto& [at, v] : {std::pair{42, 4096}, {44, 4096}, {46, 512}}) {
        const std::int16_t d = std::int16_t(v);
        std::memcpy(&header[std::size_t(at)], &d, 2);  // dim[1..3]
    }
    const fs::path gz = dir / "claim.nii.gz";
    znzFile f = znzopen(gz.c_str(), "wb", 1);
    ASSERT_FALSE(znz_isnull(f));
    ASSERT_EQ(znzwrite(header.data(), 1, header.size(), f), header.size());
    znzclose(f);
    const std::string e = error_of(gz.string());
    EXPECT_NE(e.find("claim.nii.gz: dim: the file ends after 0 of 8589934592 bytes of voxels"),
              std::string::npos)
        << e;
}

}  // namespace
}  // namespace isowall::test
