// The MetaImage reader (readers/metaimage_reader.cpp): headers written here by hand, as
// ITK writes them (.mhd beside its .raw, .mha with the data inside, zlib-compressed, either byte
// order) load voxel for voxel with their spacing and orientation; every bad header is one line
// naming the file and the key.
#include <zlib.h>

#include <algorithm>
#include <fstream>

#include "readers/readers.h"
#include "tests/formats_more_util.h"
#include "tests/plane_stream_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;
using test::expect_input_error;
using test::kDims;

void write_file(const fs::path& p, std::string_view bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

std::string text_of(const std::vector<std::byte>& b) {
    return {reinterpret_cast<const char*>(b.data()), b.size()};
}

std::string zlib_of(const std::string& raw) {
    uLongf size = compressBound(uLong(raw.size()));
    std::string out(size, '\0');
    EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                        reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()), 6),
              Z_OK);
    out.resize(size);
    return out;
}

// The test volume of T in big-endian order.
template <class T>
std::string big_endian_of(std::vector<std::byte> b) {
    for (std::size_t i = 0; i < b.size(); i += sizeof(T)) std::reverse(&b[i], &b[i] + sizeof(T));
    return text_of(b);
}

const char* met_name(VoxelType t) {
    switch (t) {
        case VoxelType::u8:
            return "MET_UCHAR";
        case VoxelType::i8:
            return "MET_CHAR";
        case VoxelType::u16:
            return "MET_USHORT";
        case VoxelType::i16:
            return "MET_SHORT";
        case VoxelType::u32:
            return "MET_UINT";
        case VoxelType::i32:
            return "MET_INT";
        case VoxelType::f32:
            return "MET_FLOAT";
        case VoxelType::f64:
            return "MET_DOUBLE";
    }
    return "";
}

// A header as ITK writes it, with `extra` lines before ElementType and the data file last.
std::string header(VoxelType t, const std::string& extra, const std::string& data_file,
                   bool msb = false) {
    return "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = " +
           std::string(msb ? "True" : "False") + "\nDimSize = 5 4 3\n" + extra +
           "ElementType = " + met_name(t) + "\nElementDataFile = " + data_file + "\n";
}

template <class T>
std::string raw_of() {
    return text_of(test::as_bytes(test::test_voxels<T>()));
}

template <class T>
void expect_mhd_and_mha(const std::string& name) {
    const fs::path dir = test::scratch_dir("formats_mha_" + name);
    const VoxelType t = voxel_type_of<T>();
    write_file(dir / "v.mhd", header(t, "ElementSpacing = 0.5 0.75 2\n", "v.raw"));
    write_file(dir / "v.raw", raw_of<T>());
    const Volume mhd = formats::read_metaimage(dir / "v.mhd");
    test::expect_test_volume<T>(mhd);
    EXPECT_EQ(mhd.spacing(), glm::vec3(0.5f, 0.75f, 2.0f));
    EXPECT_EQ(mhd.files(), (std::vector<fs::path>{dir / "v.mhd", dir / "v.raw"}));
    EXPECT_EQ(test::fact(mhd, "format"), "MetaImage");
    EXPECT_FALSE(mhd.orientation().known);
    test::expect_streams_alike((dir / "v.mhd").string());

    const auto bytes = test::as_bytes(test::test_voxels<T>());
    write_file(dir / "v.mha", header(t, "", "LOCAL", true) + big_endian_of<T>(bytes));
    const Volume mha = formats::read_metaimage(dir / "v.mha");
    test::expect_test_volume<T>(mha);
    EXPECT_EQ(mha.spacing(), glm::vec3(1.0f));
    EXPECT_EQ(mha.files(), std::vector<fs::path>{dir / "v.mha"});
    test::expect_streams_alike((dir / "v.mha").string());  // swapped a slab at a time
}

TEST(FormatsMetaImage, EveryTypeDetachedAndLocalInBothByteOrders) {
    expect_mhd_and_mha<std::uint8_t>("u8");
    expect_mhd_and_mha<std::int8_t>("i8");
    expect_mhd_and_mha<std::uint16_t>("u16");
    expect_mhd_and_mha<std::int16_t>("i16");
    expect_mhd_and_mha<std::uint32_t>("u32");
    expect_mhd_and_mha<std::int32_t>("i32");
    expect_mhd_and_mha<float>("f32");
    expect_mhd_and_mha<double>("f64");
}

TEST(FormatsMetaImage, CompressedLocalAndDetached) {
    const fs::path dir = test::scratch_dir("formats_mha_zlib");
    // .mha: the compressed data is the rest of the file.
    write_file(dir / "z.mha", header(VoxelType::f32, "CompressedData = True\n", "LOCAL") +
                                  zlib_of(raw_of<float>()));
    test::expect_test_volume<float>(formats::read_metaimage(dir / "z.mha"));
    test::expect_streams_alike((dir / "z.mha").string());  // inflated a slab at a time
    // .mhd: CompressedDataSize is the size of the .zraw beside it.
    const std::string packed = zlib_of(raw_of<std::int16_t>());
    write_file(dir / "z.mhd", header(VoxelType::i16,
                                     "CompressedData = True\nCompressedDataSize = " +
                                         std::to_string(packed.size()) + "\n",
                                     "z.zraw"));
    write_file(dir / "z.zraw", packed);
    const Volume v = formats::read_metaimage(dir / "z.mhd");
    test::expect_test_volume<std::int16_t>(v);
    EXPECT_EQ(test::fact(v, "compression"), "zlib");
    test::expect_streams_alike((dir / "z.mhd").string());
    write_file(dir / "z.zraw", packed + "x");
    expect_input_error([&] { formats::read_metaimage(dir / "z.mhd"); }, (dir / "z.zraw").string(),
                       "size", "longer");
}

TEST(FormatsMetaImage, HeaderSizeSkipsOrPutsTheDataAtTheEnd) {
    const fs::path dir = test::scratch_dir("formats_mha_skip");
    write_file(dir / "skip.mhd", header(VoxelType::u8, "HeaderSize = 7\n", "skip.raw"));
    write_file(dir / "skip.raw", "7 bytes" + raw_of<std::uint8_t>());
    test::expect_test_volume<std::uint8_t>(formats::read_metaimage(dir / "skip.mhd"));
    write_file(dir / "end.mhd", header(VoxelType::u16, "HeaderSize = -1\n", "end.raw"));
    write_file(dir / "end.raw", "any header of any length" + raw_of<std::uint16_t>());
    test::expect_test_volume<std::uint16_t>(formats::read_metaimage(dir / "end.mhd"));
}

TEST(FormatsMetaImage, OrientationFromTransformMatrixColumnsAndOffset) {
    const fs::path dir = test::scratch_dir("formats_mha_orient");
    // x along patient +y (posterior), y along patient -x (right), z along +z: a rotation.
    write_file(dir / "o.mha", header(VoxelType::u8,
                                     "TransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 10 -20 30.5\n"
                                     "CenterOfRotation = 0 0 0\nAnatomicalOrientation = PLS\n"
                                     "ElementSize = 2 2 2\n",
                                     "LOCAL") +
                                  raw_of<std::uint8_t>());
    const Volume v = formats::read_metaimage(dir / "o.mha");
    test::expect_test_volume<std::uint8_t>(v);
    const Orientation& o = v.orientation();
    EXPECT_TRUE(o.known);
    EXPECT_EQ(o.axes[0], glm::vec3(0, 1, 0));
    EXPECT_EQ(o.axes[1], glm::vec3(-1, 0, 0));
    EXPECT_EQ(o.axes[2], glm::vec3(0, 0, 1));
    EXPECT_EQ(o.origin, glm::vec3(10, -20, 30.5f));
    EXPECT_EQ(v.spacing(), glm::vec3(2.0f));
    EXPECT_EQ(test::fact(v, "spacing from"), "ElementSize");
    EXPECT_EQ(test::fact(v, "orientation from"), "TransformMatrix");
    EXPECT_NE(test::fact(v, "anatomical orientation").find("PLS"), std::string::npos);
}

// A header file of `text` (then the test volume's bytes, for LOCAL ones) and its error.
void expect_header_error(const std::string& text, const std::string& key,
                         const std::string& words) {
    static int n = 0;
    const fs::path dir = test::scratch_dir("formats_mha_bad_" + std::to_string(++n));
    write_file(dir / "v.raw", raw_of<std::uint8_t>());
    write_file(dir / "v.mha", text);
    expect_input_error([&] { formats::read_metaimage(dir / "v.mha"); }, (dir / "v.mha").string(),
                       key, words);
}

TEST(FormatsMetaImage, EveryBadHeaderNamesTheKey) {
    const std::string ok = header(VoxelType::u8, "", "v.raw");
    auto replaced = [&](const std::string& from, const std::string& to) {
        std::string s = ok;
        s.replace(s.find(from), from.size(), to);
        return s;
    };
    expect_header_error("ObjectType = Image\nthis line has no equals\n" + ok, "line 2",
                        "expected Key = Value");
    expect_header_error(replaced("MET_UCHAR", "MET_LONG"), "ElementType", "MET_LONG");
    expect_header_error(replaced("DimSize = 5 4 3\n", ""), "DimSize", "missing");
    expect_header_error(replaced("DimSize = 5 4 3", "DimSize = 5 four 3"), "DimSize",
                        "expected 3 numbers");
    expect_header_error(replaced("DimSize = 5 4 3", "DimSize = 5 4 1"), "DimSize", "from 2");
    expect_header_error(replaced("NDims = 3", "NDims = 2"), "NDims", "expected 3");
    expect_header_error(replaced("ObjectType = Image", "ObjectType = Tube"), "ObjectType", "Tube");
    expect_header_error("ElementSpacing = 1 a 1\n" + ok, "ElementSpacing", "expected 3 numbers");
    expect_header_error("ElementSpacing = 1 1 1 1\n" + ok, "ElementSpacing", "3 numbers");
    expect_header_error("ElementSpacing = 1 0 1\n" + ok, "ElementSpacing", "axis 1: spacing 0");
    expect_header_error("NDims = 3\n" + ok, "NDims", "given twice (lines 1 and 3)");
    expect_header_error(replaced("v.raw", "LIST"), "ElementDataFile", "not supported");
    expect_header_error(replaced("v.raw", "missing.raw"), "ElementDataFile", "no such file");
    expect_header_error(replaced("\nElementDataFile = v.raw\n", "\n"), "ElementDataFile",
                        "missing");
    expect_header_error(replaced("True", "Maybe"), "BinaryData", "True or False");
    expect_header_error("ElementNumberOfChannels = 3\n" + ok, "ElementNumberOfChannels",
                        "expected 1");
    expect_header_error("TransformMatrix = 1 0 0 1 0 0 0 0 1\n" + ok, "TransformMatrix",
                        "right angles");
    expect_header_error("HeaderSize = -2\n" + ok, "HeaderSize", "got \"-2\"");
    expect_header_error(std::string(70000, '\n') + ok, "ElementDataFile",
                        "not within the first 65536 bytes");
    expect_header_error("Offset = " + std::string(3000, '1') + " 0 0\n" + ok, "Offset",
                        "expected 3 numbers, got \"1111");
}

TEST(FormatsMetaImage, DataOfTheWrongSizeOrDamagedIsAnError) {
    const fs::path dir = test::scratch_dir("formats_mha_size");
    const std::string u8 = raw_of<std::uint8_t>();
    write_file(dir / "short.mha", header(VoxelType::u8, "", "LOCAL") + u8.substr(1));
    expect_input_error([&] { formats::read_metaimage(dir / "short.mha"); },
                       (dir / "short.mha").string(), "size", "shorter");
    write_file(dir / "long.mhd", header(VoxelType::u8, "", "long.raw"));
    write_file(dir / "long.raw", u8 + "!");
    expect_input_error([&] { formats::read_metaimage(dir / "long.mhd"); },
                       (dir / "long.raw").string(), "size", "longer");
    std::string packed = zlib_of(u8);
    packed[packed.size() / 2] ^= 0x55;
    write_file(dir / "bad.mha", header(VoxelType::u8, "CompressedData = True\n", "LOCAL") + packed);
    expect_input_error([&] { formats::read_metaimage(dir / "bad.mha"); },
                       (dir / "bad.mha").string(), "CompressedData", "");
    write_file(dir / "more.mha",
               header(VoxelType::u8, "CompressedData = True\n", "LOCAL") + zlib_of(u8 + u8));
    expect_input_error([&] { formats::read_metaimage(dir / "more.mha"); },
                       (dir / "more.mha").string(), "CompressedData", "exactly 60 bytes");
    // A gigabyte from a few compressed bytes: refused before anything is allocated.
    std::string huge = header(VoxelType::u8, "CompressedData = True\n", "LOCAL") + packed;
    huge.replace(huge.find("DimSize = 5 4 3"), 15, "DimSize = 1000 1000 1000");
    write_file(dir / "huge.mha", huge);
    expect_input_error([&] { formats::read_metaimage(dir / "huge.mha"); },
                       (dir / "huge.mha").string(), "CompressedData", "cannot hold");
}

}  // namespace
}  // namespace isowall
