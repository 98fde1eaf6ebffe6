// Hostile volume files, by class: every bad header or data file is one InputError line naming the
// file and the field (never a crash, a hang or a silently different volume), and the odd but
// valid spellings still load.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <fstream>

#include "core/error.h"
#include "tests/test_util.h"
#include "volume/volume.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;

const std::string kU8 = "NRRD0004\ntype: uchar\ndimension: 3\n";
const std::string kF32 = "NRRD0004\ntype: float\ndimension: 3\nendian: little\n";

// bzip2 of the bytes 0..7, and of 100 zero bytes (made with Python's bz2).
const std::string kBzip2Of8(
    "\x42\x5a\x68\x39\x31\x41\x59\x26\x53\x59\xb5\x35\x23\xed\x00\x00\x00\x40\x00\x7f\x80\x20"
    "\x00\x31\x0c\x08\x19\x1a\x69\x93\x35\x73\xf9\x45\xdc\x91\x4e\x14\x24\x2d\x4d\x48\xfb\x40",
    44);
const std::string kBzip2Of100(
    "\x42\x5a\x68\x39\x31\x41\x59\x26\x53\x59\x53\x63\x11\x99\x00\x00\x00\x41\x00\x40\x00\x40"
    "\x00\x20\x00\x21\x00\x82\x83\x17\x72\x45\x38\x50\x90\x53\x63\x11\x99",
    39);

void write_file(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out << bytes;
}

std::string read_file(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A folder with the files the cases point at: v.raw (8 bytes 0..7), lines.raw (a text line,
// then 8 bytes), a FIFO, a folder, a link to /dev/zero, and a gzip stream of 8 bytes.
struct Scene {
    fs::path dir;
    std::string gzip8;  // a gzip stream of the bytes 0..7
};

Scene make_scene(const std::string& name) {
    Scene s{test::scratch_dir(name), {}};
    write_file(s.dir / "v.raw", std::string("\0\1\2\3\4\5\6\7", 8));
    write_file(s.dir / "lines.raw", std::string("a text line\n\0\1\2\3\4\5\6\7", 20));
    EXPECT_EQ(::mkfifo((s.dir / "fifo.raw").c_str(), 0600), 0);
    fs::create_directories(s.dir / "folder");
    fs::create_directories(s.dir / "folder.nrrd");
    fs::create_symlink("/dev/zero", s.dir / "zero.nrrd");
    fs::create_symlink("/dev/zero", s.dir / "zero.raw");
    // A gzip stream from our own writer, for the attached gzip cases.
    std::vector<std::byte> bytes(8);
    for (int i = 0; i < 8; ++i) bytes[std::size_t(i)] = std::byte(i);
    save_nrrd(s.dir / "g.nhdr", Volume({2, 2, 2}, VoxelType::u8, glm::vec3(1), bytes, "g"), "gzip",
              host_endian());
    s.gzip8 = read_file(s.dir / "g.raw.gz");
    return s;
}

struct BadCase {
    const char* name;     // the file written (or already in the scene) and loaded
    std::string content;  // empty: the scene's file as it is
    const char* field;
    const char* says;  // a part of the message
};

// Sizes that wrap or overflow.
std::vector<BadCase> size_cases([[maybe_unused]] const Scene& s) {
    const std::string raw = "encoding: raw\n";
    const std::string s222 = "sizes: 2 2 2\n";
    return {
        {"wrap32.nhdr", kU8 + "sizes: 4294967298 2 2\n" + raw + "data file: v.raw\n", "sizes",
         "2147483647"},
        {"wrap64.nhdr", kU8 + "sizes: 18446744073709551618 2 2\n" + raw + "data file: v.raw\n",
         "sizes", "64 bits"},
        {"int31.nhdr", kU8 + "sizes: 2147483648 2 2\n" + raw + "data file: v.raw\n", "sizes",
         "2147483647"},
        {"product.nhdr",
         kU8 + "sizes: 2000000000 2000000000 2000000000\n" + raw + "data file: v.raw\n", "sizes",
         "overflow"},
        {"negative.nhdr", kU8 + "sizes: -5 2 2\n" + raw + "data file: v.raw\n", "sizes",
         "whole numbers"},
        {"huge.nhdr", kU8 + "sizes: 65536 65536 65536\n" + raw + "data file: v.raw\n", "size",
         "shorter"},
        {"huge_gzip.nrrd", kU8 + "sizes: 65536 65536 16384\nencoding: gzip\n\n" + s.gzip8, "sizes",
         "memory"},
    };
}

// Data files that are not regular files, or not there.
std::vector<BadCase> file_cases([[maybe_unused]] const Scene& s) {
    const std::string raw = "encoding: raw\n";
    const std::string s222 = "sizes: 2 2 2\n";
    return {
        {"zero.nhdr", kU8 + s222 + raw + "data file: /dev/zero\n", "data file", "character device"},
        {"zero_skip.nhdr", kU8 + s222 + raw + "line skip: 1\ndata file: zero.raw\n", "data file",
         "character device"},
        {"fifo.nhdr", kU8 + s222 + raw + "data file: fifo.raw\n", "data file", "FIFO"},
        {"folder.nhdr", kU8 + s222 + raw + "data file: folder\n", "data file", "folder"},
        {"missing.nhdr", kU8 + s222 + raw + "data file: nope.raw\n", "data file", "no such file"},
        {"empty_name.nhdr", kU8 + s222 + raw + "data file: \n", "data file", "no file name"},
        {"list.nhdr", kU8 + s222 + raw + "data file: LIST\nv.raw\nv.raw\n", "data file", "several"},
        {"pattern.nhdr", kU8 + s222 + raw + "data file: v%d.raw 0 1 1\n", "data file", "several"},
        {"zero.nrrd", "", "file", "character device"},
        {"folder.nrrd", "", "file", "folder"},
    };
}

// Skips that point past the data, or are not numbers.
std::vector<BadCase> skip_cases([[maybe_unused]] const Scene& s) {
    const std::string raw = "encoding: raw\n";
    const std::string s222 = "sizes: 2 2 2\n";
    return {
        {"lineskip_eof.nhdr", kU8 + s222 + raw + "line skip: 5\ndata file: lines.raw\n",
         "line skip", "ends after 1"},
        {"lineskip_neg.nhdr", kU8 + s222 + raw + "line skip: -1\ndata file: v.raw\n", "line skip",
         ">= 0"},
        {"byteskip_neg.nhdr", kU8 + s222 + raw + "byte skip: -2\ndata file: v.raw\n", "byte skip",
         ">= -1"},
        {"byteskip_big.nhdr", kU8 + s222 + raw + "byte skip: 99999999999\ndata file: v.raw\n",
         "byte skip", "only 8"},
        {"byteskip_gzip.nhdr", kU8 + s222 + "encoding: gzip\nbyte skip: -1\ndata file: g.raw.gz\n",
         "byte skip", "raw"},
        {"byteskip_twice.nhdr", kU8 + s222 + raw + "byte skip: 1\nbyteskip: 1\ndata file: v.raw\n",
         "byte skip", "twice"},
    };
}

// Compressed data of the wrong length.
std::vector<BadCase> compressed_cases([[maybe_unused]] const Scene& s) {
    const std::string raw = "encoding: raw\n";
    const std::string s222 = "sizes: 2 2 2\n";
    return {
        {"gzip_long.nrrd", kU8 + s222 + "encoding: gzip\n\n" + s.gzip8 + s.gzip8, "data", "longer"},
        {"gzip_short.nrrd", kU8 + "sizes: 2 2 3\nencoding: gzip\n\n" + s.gzip8, "data", "shorter"},
        {"gzip_cut.nrrd", kU8 + s222 + "encoding: gzip\n\n" + s.gzip8.substr(0, 12), "data",
         "ends early"},
        {"gzip_junk.nrrd", kU8 + s222 + "encoding: gzip\n\n" + s.gzip8 + "junk", "data", "follow"},
        {"gzip_garbage.nrrd", kU8 + s222 + "encoding: gzip\n\n" + std::string(40, 'x'), "data",
         "corrupt"},
        {"bzip2_long.nrrd", kU8 + s222 + "encoding: bzip2\n\n" + kBzip2Of100, "data", "longer"},
        {"bzip2_cut.nrrd", kU8 + s222 + "encoding: bzip2\n\n" + kBzip2Of8.substr(0, 30), "data",
         "ends early"},
    };
}

// Text encodings: long, binary, too many, too few, out of range.
std::vector<BadCase> text_cases([[maybe_unused]] const Scene& s) {
    const std::string raw = "encoding: raw\n";
    const std::string s222 = "sizes: 2 2 2\n";
    return {
        {"ascii_long.nrrd", kU8 + s222 + "encoding: ascii\n\n" + std::string(100000, '1'), "data",
         "longer than 64"},
        {"ascii_nul.nrrd", kU8 + s222 + "encoding: ascii\n\n" + std::string(100000, '\0'), "data",
         "\\x00"},
        {"ascii_more.nrrd", kU8 + s222 + "encoding: ascii\n\n1 2 3 4 5 6 7 8 9\n", "data",
         "longer"},
        {"ascii_fewer.nrrd", kU8 + s222 + "encoding: ascii\n\n1 2 3\n", "data", "shorter"},
        {"ascii_range.nrrd", kU8 + s222 + "encoding: ascii\n\n1 2 3 4 5 6 7 300\n", "data",
         "value 8"},
        {"ascii_frac.nrrd", kU8 + s222 + "encoding: ascii\n\n1 2 3 4 5 6 7 1.5\n", "data",
         "\"1.5\""},
        {"ascii_big_float.nrrd", kF32 + s222 + "encoding: ascii\n\n1 2 3 4 5 6 7 1e300\n", "data",
         "value 8"},
        {"hex_long.nrrd", kU8 + s222 + "encoding: hex\n\n" + std::string(200000, '0'), "data",
         "longer"},
        {"hex_bad.nrrd", kU8 + s222 + "encoding: hex\n\n0001020304050607zz", "data", "hex digit"},
        {"hex_half.nrrd", kU8 + s222 + "encoding: hex\n\n000102030405060", "data", "half"},
    };
}

// Fields Teem accepts but a volume cannot use.
std::vector<BadCase> field_cases([[maybe_unused]] const Scene& s) {
    const std::string raw = "encoding: raw\n";
    const std::string s222 = "sizes: 2 2 2\n";
    return {
        {"dim4.nhdr",
         "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 2 2 2 1\n" + raw + "data file: v.raw\n",
         "dimension", "expected 3"},
        {"int64.nhdr",
         "NRRD0004\ntype: int64\ndimension: 3\nsizes: 2 2 2\nendian: little\n" + raw +
             "data file: v.raw\n",
         "type", "unsupported"},
        {"content_long_kv_mark.nhdr",
         kU8 + s222 + "content: " + std::string(1500, 'x') + " :=1\n" + raw + "data file: v.raw\n",
         "content", "expected at most 512"},
        {"zrl.nrrd", kU8 + s222 + "encoding: zrl\n\n" + std::string(8, '\0'), "encoding",
         "not supported"},
        {"spacing_inf.nhdr", kU8 + s222 + "spacings: 1e300 1 1\n" + raw + "data file: v.raw\n",
         "spacings", "unusable"},
        {"spacing_tiny.nhdr", kU8 + s222 + "spacings: 1e-300 1 1\n" + raw + "data file: v.raw\n",
         "spacings", "unusable"},
        // A side past what a view can frame: once "--zoom: ... expected at least inf".
        {"spacing_1e30.nhdr", kU8 + s222 + "spacings: 1e30 1 1\n" + raw + "data file: v.raw\n",
         "spacings", "at most 1e+07 object units a side"},
        // Teem reads "nan" as a missing spacing; the docs say a spacing is a positive number.
        {"spacing_nan.nhdr", kU8 + s222 + "spacings: -2 nan 0.5\n" + raw + "data file: v.raw\n",
         "spacings", "axis 1: spacing nan (expected a finite non-zero number)"},
        {"spacing_zero.nhdr", kU8 + s222 + "spacings: 1 1 0\n" + raw + "data file: v.raw\n",
         "header", "axis 2 spacing (0) invalid"},  // Teem's own words
        {"direction_zero.nhdr",
         kU8 + s222 + "space dimension: 3\nspace directions: (1,0,0) (0,0,0) (0,0,1)\n" + raw +
             "data file: v.raw\n",
         "space directions", "axis 1 is the zero vector"},
        {"direction_none.nhdr",
         kU8 + s222 + "space dimension: 3\nspace directions: (1,0,0) (0,1,0) none\n" + raw +
             "data file: v.raw\n",
         "space directions", "axis 2 has no direction"},
        {"direction_inf.nhdr",
         kU8 + s222 + "space dimension: 3\nspace directions: (1e300,0,0) (0,1,0) (0,0,1)\n" + raw +
             "data file: v.raw\n",
         "space directions", "unusable"},
        {"kinds.nhdr", kU8 + s222 + "kinds: 2-vector domain domain\n" + raw + "data file: v.raw\n",
         "kinds", "not a space axis"},
        {"sizes_u32max.nhdr",
         kU8 + "sizes: 4294967295 4294967295 4294967295\n" + raw + "data file: v.raw\n", "sizes",
         "2147483647"},
        {"not_nrrd.nrrd", std::string(1000, '\0'), "header", "not a NRRD file"},
        {"nul_header.nrrd",
         kU8 + std::string("sizes: 2 2\0 2\n", 14) + raw + "\n" + std::string(8, '\0'), "header",
         "NUL"},
        {"no_blank.nrrd", kU8 + s222 + raw, "header", "no blank line"},
        {"endian_missing.nhdr",
         "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 2 2 2\n" + raw + "data file: v.raw\n",
         "header", "endian"},
    };
}

std::vector<BadCase> bad_cases(const Scene& s) {
    std::vector<BadCase> all;
    for (auto* part :
         {size_cases, file_cases, skip_cases, compressed_cases, text_cases, field_cases}) {
        auto cases = part(s);
        all.insert(all.end(), cases.begin(), cases.end());
    }
    return all;
}

TEST(VolumeHostile, EveryBadNrrdIsOneLineNamingTheFileAndField) {
    const Scene s = make_scene("hostile_nrrd");
    int checked = 0;
    for (const BadCase& c : bad_cases(s)) {
        SCOPED_TRACE(c.name);
        const fs::path file = s.dir / c.name;
        if (!c.content.empty()) write_file(file, c.content);
        try {
            const Volume v = load_nrrd(file);
            ADD_FAILURE() << c.name << " loaded as " << v.dims().x << "x" << v.dims().y << "x"
                          << v.dims().z << ", expected an error in " << c.field;
            continue;
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(std::string(": ") + c.field + ": "), std::string::npos) << what;
            EXPECT_NE(what.find(c.says), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            EXPECT_LT(what.size(), 400u) << what;  // never the whole input
            // The file named is the header or, for data errors, the data file beside it.
            EXPECT_EQ(what.rfind(s.dir.string(), 0), 0u) << what;
        }
        ++checked;
    }
    EXPECT_EQ(checked, static_cast<int>(bad_cases(s).size()));
}

struct GoodCase {
    const char* name;
    std::string content;
    std::vector<float> values;  // the voxels expected, as float
    glm::vec3 spacing{1.0f};
};

std::vector<GoodCase> good_cases(const Scene& s) {
    const std::vector<float> ramp{0, 1, 2, 3, 4, 5, 6, 7};
    const float nan = std::nanf(""), inf = INFINITY;
    const std::string s222 = "sizes: 2 2 2\n";
    return {
        {"ascii.nrrd", kU8 + s222 + "encoding: ascii\n\n0 1 2 3\n4 5 6 7\n", ramp},
        {"ascii_commas.nrrd", kU8 + s222 + "encoding: ascii\n\n0, 1, 2, 3,\n+4,5,6,7", ramp},
        {"ascii_float.nrrd",
         kF32 + s222 + "encoding: ascii\n\n1 2.5 -3 nan 5 inf -inf 8e1\n",
         {1, 2.5f, -3, nan, 5, inf, -inf, 80}},
        {"hex.nrrd", kU8 + s222 + "encoding: hex\n\n00 01 02 03\n04050607\n", ramp},
        {"gzip_two_members.nrrd",
         kU8 + "sizes: 2 2 4\nencoding: gzip\n\n" + s.gzip8 + s.gzip8,
         {0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7}},
        {"bzip2.nrrd", kU8 + s222 + "encoding: bzip2\n\n" + kBzip2Of8, ramp},
        {"lineskip.nhdr", kU8 + s222 + "encoding: raw\nline skip: 1\ndata file: lines.raw\n", ramp},
        {"byteskip_end.nhdr", kU8 + s222 + "encoding: raw\nbyte skip: -1\ndata file: lines.raw\n",
         ramp},
        {"byteskip.nhdr", kU8 + s222 + "encoding: raw\nbyteskip: 12\ndatafile: lines.raw\n", ramp},
        {"spacing_neg.nhdr",
         kU8 + s222 + "spacings: -2 1 0.5\nencoding: raw\ndata file: v.raw\n",
         ramp,
         {2, 1, 0.5f}},
        {"gzip.nhdr", "", ramp},
    };
}

TEST(VolumeHostile, OddButValidSpellingsLoadExactly) {
    const Scene s = make_scene("hostile_good");
    write_file(s.dir / "gzip.nhdr", read_file(s.dir / "g.nhdr"));
    write_file(s.dir / "gzip.raw.gz", s.gzip8);
    std::string nhdr = read_file(s.dir / "gzip.nhdr");
    nhdr.replace(nhdr.find("g.raw.gz"), 8, "gzip.raw.gz");
    write_file(s.dir / "gzip.nhdr", nhdr);
    for (const GoodCase& c : good_cases(s)) {
        SCOPED_TRACE(c.name);
        if (!c.content.empty()) write_file(s.dir / c.name, c.content);
        const Volume v = load_nrrd(s.dir / c.name);
        EXPECT_EQ(v.spacing(), c.spacing);
        ASSERT_EQ(v.voxel_count(), c.values.size());
        dispatch_voxel_type(v.type(), [&](auto tag) {
            using T = decltype(tag);
            const auto view = v.view<T>();
            for (std::size_t i = 0; i < c.values.size(); ++i) {
                const auto got = static_cast<float>(view.data[i]);
                if (std::isnan(c.values[i]))
                    EXPECT_TRUE(std::isnan(got)) << "voxel " << i;
                else
                    EXPECT_EQ(got, c.values[i]) << "voxel " << i;
            }
        });
        ASSERT_FALSE(v.files().empty());
        EXPECT_EQ(v.files().front(), s.dir / c.name);
    }
}

TEST(VolumeHostile, RawFilesAreCheckedLikeNrrdData) {
    const Scene s = make_scene("hostile_raw");
    struct RawCase {
        fs::path file;
        glm::ivec3 dims;
        std::size_t header_bytes;
        const char* field;
        const char* says;
    };
    const RawCase cases[] = {
        {s.dir / "zero.raw", {2, 2, 2}, 0, "file", "character device"},
        {s.dir / "fifo.raw", {2, 2, 2}, 0, "file", "FIFO"},
        {s.dir / "folder", {2, 2, 2}, 0, "file", "folder"},
        {s.dir / "nope.raw", {2, 2, 2}, 0, "file", "no such file"},
        {s.dir / "v.raw", {2, 2, 2}, std::size_t(-8), "size", "shorter"},  // offset + need wraps
        {s.dir / "v.raw", {2000000000, 2000000000, 2000000000}, 0, "--dims", "overflow"},
        {s.dir / "v.raw", {2, -2, 2}, 0, "--dims", ">= 2"},
    };
    for (const RawCase& c : cases) {
        SCOPED_TRACE(c.file.string());
        RawSpec spec;
        spec.dims = c.dims;
        spec.type = VoxelType::f64;
        spec.header_bytes = c.header_bytes;
        try {
            load_raw(c.file, spec);
            ADD_FAILURE() << "expected an error in " << c.field;
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(std::string(": ") + c.field + ": "), std::string::npos) << what;
            EXPECT_NE(what.find(c.says), std::string::npos) << what;
        }
    }
}

}  // namespace
}  // namespace isowall
