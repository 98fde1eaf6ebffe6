// The TIFF stack reader (readers/tiff_reader.cpp): multi-page files and folders of slices
// written here through OpenImageIO load voxel for voxel, the folder in natural name order (s2
// before s10); every bad stack is one line naming the file and the field.
#include <OpenImageIO/imageio.h>

#include <fstream>
#include <iterator>
#include <sstream>

#include "readers/read_volume.h"
#include "readers/readers.h"
#include "readers/tiff_directories.h"
#include "tests/formats_more_util.h"
#include "tests/plane_stream_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;
using test::expect_input_error;
using test::kDims;

OIIO::TypeDesc desc_of(VoxelType t) {
    switch (t) {
        case VoxelType::u8:
            return OIIO::TypeDesc::UINT8;
        case VoxelType::i8:
            return OIIO::TypeDesc::INT8;
        case VoxelType::u16:
            return OIIO::TypeDesc::UINT16;
        case VoxelType::i16:
            return OIIO::TypeDesc::INT16;
        case VoxelType::u32:
            return OIIO::TypeDesc::UINT32;
        case VoxelType::i32:
            return OIIO::TypeDesc::INT32;
        case VoxelType::f32:
            return OIIO::TypeDesc::FLOAT;
        case VoxelType::f64:
            return OIIO::TypeDesc::DOUBLE;
    }
    return OIIO::TypeDesc::UINT8;
}

// One page as OpenImageIO writes it: `pages` of `spec`, the bytes of each given in turn.
struct Page {
    OIIO::ImageSpec spec;
    std::vector<std::byte> bytes;
};

void write_tiff(const fs::path& path, const std::vector<Page>& pages) {
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out) << OIIO::geterror();
    for (std::size_t i = 0; i < pages.size(); ++i) {
        const auto mode = i == 0 ? OIIO::ImageOutput::Create : OIIO::ImageOutput::AppendSubimage;
        ASSERT_TRUE(out->open(path.string(), pages[i].spec, mode)) << out->geterror();
        ASSERT_TRUE(out->write_image(pages[i].spec.format, pages[i].bytes.data()))
            << out->geterror();
    }
    ASSERT_TRUE(out->close());
}

// The pages of the test volume of T, one per z.
template <class T>
std::vector<Page> test_pages(glm::ivec3 dims = kDims) {
    const std::vector<std::byte> all = test::as_bytes(test::test_voxels<T>(dims));
    const std::size_t slice = std::size_t(dims.x) * dims.y * sizeof(T);
    std::vector<Page> pages;
    for (int z = 0; z < dims.z; ++z) {
        OIIO::ImageSpec spec(dims.x, dims.y, 1, desc_of(voxel_type_of<T>()));
        pages.push_back({spec, {all.begin() + slice * z, all.begin() + slice * (z + 1)}});
    }
    return pages;
}

template <class T>
void expect_multipage(const std::string& name) {
    const fs::path file = test::scratch_dir("formats_tiff_" + name) / "stack.tif";
    write_tiff(file, test_pages<T>());
    const Volume v = formats::read_tiff_stack(file);
    test::expect_test_volume<T>(v);
    EXPECT_EQ(v.spacing(), glm::vec3(1.0f));
    EXPECT_EQ(test::fact(v, "format"), "TIFF");
    EXPECT_EQ(test::fact(v, "spacing from"), "none in the file (1 1 1)");
    EXPECT_FALSE(v.orientation().known);
    EXPECT_EQ(v.files(), std::vector<fs::path>{file});
    test::expect_streams_alike(file.string());  // what `import` streams, a slab at a time
}

TEST(FormatsTiff, MultiPageOfEveryType) {
    expect_multipage<std::uint8_t>("u8");
    expect_multipage<std::int8_t>("i8");
    expect_multipage<std::uint16_t>("u16");
    expect_multipage<std::int16_t>("i16");
    expect_multipage<std::uint32_t>("u32");
    expect_multipage<std::int32_t>("i32");
    expect_multipage<float>("f32");
    expect_multipage<double>("f64");
}

TEST(FormatsTiff, FolderOfSlicesInNaturalOrder) {
    const glm::ivec3 dims{6, 5, 12};
    const fs::path dir = test::scratch_dir("formats_tiff_folder");
    const std::vector<Page> pages = test_pages<std::uint16_t>(dims);
    // Written in a shuffled order, named s1 .. s12: name order would put s10 after s1.
    std::vector<fs::path> want;
    for (int z = 0; z < dims.z; ++z)  // not "s" + n: that trips GCC 12's -Wrestrict
        want.push_back(dir / std::string("s").append(std::to_string(z + 1)).append(".tif"));
    for (int z : {7, 0, 11, 3, 9, 1, 5, 10, 2, 8, 4, 6}) write_tiff(want[z], {pages[z]});
    std::ofstream(dir / "README.txt") << "not a slice\n";
    const Volume v = formats::read_tiff_stack(dir);
    test::expect_test_volume<std::uint16_t>(v, dims);
    EXPECT_EQ(v.files(), want);
    // --volume's choice agrees: a folder with TIFF slices (and a note) is a TIFF stack.
    const Volume front_door = formats::read_volume(dir.string(), std::nullopt);
    EXPECT_EQ(front_door.files(), want);
    test::expect_streams_alike(dir.string());
}

TEST(FormatsTiff, ImageJSpacingFromDescriptionAndResolution) {
    const fs::path file = test::scratch_dir("formats_tiff_imagej") / "stack.tif";
    std::vector<Page> pages = test_pages<float>();
    for (Page& p : pages) {
        p.spec.attribute(
            "ImageDescription",
            "ImageJ=1.54f\nimages=3\nslices=3\nunit=micron\nspacing=2.5\nloop=false\n");
        p.spec.attribute("XResolution", 2.0f);
        p.spec.attribute("YResolution", 4.0f);
        p.spec.attribute("PixelAspectRatio", 2.0f);  // OIIO writes YResolution as X * this
        p.spec.attribute("ResolutionUnit", "none");
    }
    write_tiff(file, pages);
    const Volume v = formats::read_tiff_stack(file);
    test::expect_test_volume<float>(v);
    EXPECT_EQ(v.spacing(), glm::vec3(0.5f, 0.25f, 2.5f));
    EXPECT_NE(test::fact(v, "spacing from").find("ImageJ"), std::string::npos);
    EXPECT_NE(test::fact(v, "spacing from").find("micron"), std::string::npos);
}

TEST(FormatsTiff, SlicesThatDifferNameTheFirstThatDoes) {
    const fs::path dir = test::scratch_dir("formats_tiff_differ");
    std::vector<Page> pages = test_pages<std::uint8_t>();
    pages[2] = test_pages<std::uint8_t>({4, 4, 3})[2];
    write_tiff(dir / "pages.tif", pages);
    expect_input_error([&] { formats::read_tiff_stack(dir / "pages.tif"); },
                       (dir / "pages.tif").string(), "page 2", "4x4 uint8, but page 0 is 5x4");

    const fs::path folder = dir / "slices";
    fs::create_directories(folder);
    const std::vector<Page> u8 = test_pages<std::uint8_t>();
    write_tiff(folder / "s1.tif", {u8[0]});
    write_tiff(folder / "s2.tif", {u8[1]});
    write_tiff(folder / "s10.tif", {test_pages<std::uint16_t>()[2]});
    write_tiff(folder / "s3.tif", {test_pages<std::uint8_t>({5, 3, 3})[2]});
    expect_input_error([&] { formats::read_tiff_stack(folder); }, (folder / "s3.tif").string(),
                       "size", "5x3 uint8, but the first slice (s1.tif) is 5x4 uint8");
}

TEST(FormatsTiff, ChannelsCountsAndFormatsAreChecked) {
    const fs::path dir = test::scratch_dir("formats_tiff_bad");
    Page rgb{OIIO::ImageSpec(5, 4, 3, OIIO::TypeDesc::UINT8), std::vector<std::byte>(60)};
    write_tiff(dir / "rgb.tif", {rgb, rgb});
    expect_input_error([&] { formats::read_tiff_stack(dir / "rgb.tif"); },
                       (dir / "rgb.tif").string(), "page 0", "3 channels");

    write_tiff(dir / "one.tif", {test_pages<std::uint8_t>()[0]});
    expect_input_error([&] { formats::read_tiff_stack(dir / "one.tif"); },
                       (dir / "one.tif").string(), "pages", "at least 2");

    write_tiff(dir / "png.png", {test_pages<std::uint8_t>()[0]});
    fs::rename(dir / "png.png", dir / "png.tif");
    expect_input_error([&] { formats::read_tiff_stack(dir / "png.tif"); },
                       (dir / "png.tif").string(), "file", "not a TIFF");

    fs::create_directories(dir / "lone");
    write_tiff(dir / "lone" / "a.tif", {test_pages<std::uint8_t>()[0]});
    expect_input_error([&] { formats::read_tiff_stack(dir / "lone"); }, (dir / "lone").string(),
                       "slices", "at least 2");
}

TEST(FormatsTiff, AnImageJHyperstackOfChannelsIsRefused) {
    const fs::path file = test::scratch_dir("formats_tiff_hyperstack") / "stack.tif";
    std::vector<Page> pages = test_pages<std::uint8_t>({5, 4, 4});
    for (Page& p : pages)
        p.spec.attribute("ImageDescription",
                         "ImageJ=1.54f\nimages=4\nchannels=2\nslices=2\nhyperstack=true\n");
    write_tiff(file, pages);
    expect_input_error([&] { formats::read_tiff_stack(file); }, file.string(), "ImageDescription",
                       "2 channels");
}

// The file's bytes, and the byte at which each directory entry of `tag` starts (classic
// little-endian TIFF, as OpenImageIO writes here), in page order.
std::vector<char> file_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint32_t le(const std::vector<char>& b, std::size_t at, int n) {
    std::uint32_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = v << 8 | std::uint8_t(b[at + std::size_t(i)]);
    return v;
}

std::vector<std::size_t> entries_of(const std::vector<char>& b, std::uint16_t tag) {
    EXPECT_EQ(std::string(b.data(), 4), std::string("II*\0", 4));
    std::vector<std::size_t> out;
    for (std::size_t at = le(b, 4, 4); at != 0;) {
        const std::uint32_t n = le(b, at, 2);
        for (std::uint32_t i = 0; i < n; ++i)
            if (le(b, at + 2 + 12 * i, 2) == tag) out.push_back(at + 2 + 12 * i);
        at = le(b, at + 2 + 12 * n, 4);
    }
    return out;
}

void write_bytes(const fs::path& p, const std::vector<char>& b) {
    std::ofstream(p, std::ios::binary).write(b.data(), std::streamsize(b.size()));
}

// A short value (its 2 bytes at byte 8 of the entry) set in every page.
void set_short(std::vector<char>& b, std::uint16_t tag, std::uint16_t value) {
    const std::vector<std::size_t> at = entries_of(b, tag);
    ASSERT_FALSE(at.empty()) << "tag " << tag;
    for (std::size_t e : at) {
        ASSERT_EQ(le(b, e + 2, 2), 3u) << "tag " << tag << " is not a SHORT";
        b[e + 8] = char(value & 0xff);
        b[e + 9] = char(value >> 8);
    }
}

// A file cut inside its last page's directory, or anywhere after its header, is named: libtiff
// alone stops at the last directory it can read, and the stack read one slice fewer.
TEST(FormatsTiff, AFileCutInsideAPageIsNamed) {
    const fs::path dir = test::scratch_dir("formats_tiff_cut");
    write_tiff(dir / "whole.tif", test_pages<std::uint8_t>({5, 4, 20}));
    const std::vector<char> whole = file_bytes(dir / "whole.tif");
    const std::vector<std::size_t> last = entries_of(whole, 256);
    ASSERT_EQ(last.size(), 20u);
    // Cut 4 entries into the last directory, and at every 97th byte past the header.
    std::vector<std::size_t> cuts = {last.back() + 12 * 3};
    for (std::size_t at = 8; at < whole.size(); at += 97) cuts.push_back(at);
    for (std::size_t cut : cuts) {
        const fs::path file = dir / "cut.tif";
        write_bytes(file, {whole.begin(), whole.begin() + std::ptrdiff_t(cut)});
        try {
            const Volume v = formats::read_tiff_stack(file);
            ADD_FAILURE() << "cut at " << cut << " of " << whole.size() << ": read " << v.dims().z
                          << " slices";
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(file.string() + ": ", 0), 0u) << e.what();
        }
    }
    write_bytes(dir / "cut.tif", {whole.begin(), whole.begin() + std::ptrdiff_t(cuts.front())});
    expect_input_error([&] { formats::read_tiff_stack(dir / "cut.tif"); },
                       (dir / "cut.tif").string(), "directories",
                       "the directory of page 19 (at byte ");
}

// The walk itself, on chains written here: BigTIFF, big-endian, a loop, a link past the end.
TEST(FormatsTiff, TheDirectoryWalkReadsEveryLayoutAndNamesLoops) {
    const auto walk = [](const std::string& bytes) {
        std::istringstream in(bytes);
        return formats::tiff_directories(in, bytes.size());
    };
    using namespace std::string_literals;
    // BigTIFF, little-endian: an empty directory at 16, then the end.
    const auto big = walk("II+\0\x08\0\0\0\x10\0\0\0\0\0\0\0"s + std::string(16, '\0'));
    EXPECT_EQ(big.pages, 1);
    EXPECT_EQ(big.problem, "");
    // Classic big-endian: one directory of one entry at 8, then the end.
    const auto mm = walk("MM\0*\0\0\0\x08\0\x01"s + std::string(12, 'x') + std::string(4, '\0'));
    EXPECT_EQ(mm.pages, 1);
    EXPECT_EQ(mm.problem, "");
    // A directory whose link leads back to itself.
    const auto loop = walk("II*\0\x08\0\0\0\0\0\x08\0\0\0"s);
    EXPECT_EQ(loop.pages, 1);
    EXPECT_NE(loop.problem.find("the directory of page 1 (at byte 8) is one seen before"),
              std::string::npos)
        << loop.problem;
    // A link past the end of the file.
    const auto past = walk("II*\0\x08\0\0\0\0\0\xff\0\0\0"s);
    EXPECT_NE(past.problem.find("page 1 (at byte 255) starts past the end of the file (14 bytes)"),
              std::string::npos)
        << past.problem;
    EXPECT_NE(walk("II*\0"s).problem.find("shorter than a TIFF header"), std::string::npos);
}

// A compression libtiff cannot decode is named by the page, not read as zeros.
TEST(FormatsTiff, ACompressionThatCannotBeDecodedIsNamed) {
    const fs::path file = test::scratch_dir("formats_tiff_codec") / "stack.tif";
    write_tiff(file, test_pages<std::uint8_t>({5, 4, 3}));
    std::vector<char> b = file_bytes(file);
    set_short(b, 259, 50000);  // Compression: no scheme has this number
    write_bytes(file, b);
    expect_input_error([&] { formats::read_tiff_stack(file); }, file.string(), "page 0",
                       "OpenImageIO cannot decode it");
}

// A slice whose header claims more than memory could sensibly hold is refused from the header.
TEST(FormatsTiff, AHugeSliceIsRefusedFromItsHeader) {
    const fs::path file = test::scratch_dir("formats_tiff_huge") / "stack.tif";
    write_tiff(file, test_pages<std::uint16_t>({5, 4, 3}));
    std::vector<char> b = file_bytes(file);
    set_short(b, 256, 60000);  // ImageWidth
    set_short(b, 257, 60000);  // ImageLength
    write_bytes(file, b);
    expect_input_error([&] { formats::read_tiff_stack(file); }, file.string(), "page 0",
                       "60000x60000 uint16 is 7200000000 bytes; isowall reads slices of at most "
                       "512 MiB");
}

}  // namespace
}  // namespace isowall
