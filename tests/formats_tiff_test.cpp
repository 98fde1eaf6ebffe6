// The TIFF stack reader (readers/tiff_reader.cpp): multi-page files and folders of slices
// written here through OpenImageIO load voxel for voxel, the folder in natural name order (s2
// before s10); every bad stack is one line naming the file and the field.
#include <OpenImageIO/imageio.h>

#include <fstream>

#include "readers/read_volume.h"
#include "readers/readers.h"
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

}  // namespace
}  // namespace isowall
