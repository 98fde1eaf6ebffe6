// The OpenImageIO image reader and writer: exact PNG round trips, depth in EXR, errors that name
// the file.
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "common/core/image.h"
#include "common/io/image_io.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

Image test_pattern(int width, int height) {
    Image image;
    image.resize(width, height);
    std::mt19937 random(20240601u);
    std::uniform_int_distribution<int> byte(0, 255);
    for (auto& v : image.rgba) v = static_cast<std::uint8_t>(byte(random));
    for (std::size_t i = 0; i < image.pixel_count(); ++i)
        image.depth[i] = static_cast<float>(i % 97) / 96.0f;
    return image;
}

TEST(ImageIo, PngRoundTripIsExact) {
    const auto dir = test::scratch_dir("image_io_png");
    const Image image = test_pattern(37, 23);
    const auto path = dir / "pattern.png";
    write_image(path, image);
    const Image back = read_image(path);
    ASSERT_EQ(back.width, image.width);
    ASSERT_EQ(back.height, image.height);
    EXPECT_EQ(back.rgba, image.rgba);
    // The temporary file was renamed, not left beside the result.
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
}

TEST(ImageIo, DepthExrIsReadable) {
    const auto dir = test::scratch_dir("image_io_exr");
    const Image image = test_pattern(19, 11);
    const auto path = dir / "depth.exr";
    write_depth(path, image);
    const Image back = read_depth(path);
    ASSERT_EQ(back.width, image.width);
    ASSERT_EQ(back.height, image.height);
    EXPECT_EQ(back.depth, image.depth);
}

TEST(ImageIo, MissingFolderThrowsNamingThePath) {
    const auto path = test::scratch_dir("image_io_missing") / "no" / "such" / "frame.png";
    const Image image = test_pattern(4, 4);
    for (const auto& write : {write_image, write_depth}) {
        try {
            write(path, image);
            FAIL() << "writing " << path << " did not throw";
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(read_image(path), std::runtime_error);
}

TEST(ImageIo, RejectsAnEmptyImage) {
    const auto path = test::scratch_dir("image_io_empty") / "empty.png";
    EXPECT_THROW(write_image(path, Image{}), std::runtime_error);
    EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace isowall
