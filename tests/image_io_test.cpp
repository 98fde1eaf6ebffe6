// The OpenImageIO image reader and writer: exact PNG round trips, depth in EXR, errors that name
// the file.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "core/image.h"
#include "files/image_io.h"
#include "files/ply.h"
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
    using Writer = void (*)(const std::filesystem::path&, const Image&);
    for (const Writer write : {Writer(write_image), Writer(write_depth)}) {
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

// Every writer goes through OutputFiles: whatever fails, the folder is left as it was (no target,
// no temporary), and a staged write appears only at commit.
TEST(ImageIo, AFailedWriteLeavesNothingInTheFolder) {
    const Image image = test_pattern(4, 4);
    Mesh mesh;
    using Write = std::function<void(const std::filesystem::path&)>;
    const std::vector<std::pair<const char*, Write>> writers = {
        {"write_image", [&](const std::filesystem::path& p) { write_image(p, image); }},
        {"write_depth", [&](const std::filesystem::path& p) { write_depth(p, image); }},
        {"write_ply", [&](const std::filesystem::path& p) { write_ply(p, mesh); }},
    };
    for (const auto& [name, write] : writers)
        for (const char* target : {"x.nosuchformat", "busy"}) {
            if (std::string(name) == "write_ply" && *target == 'x') continue;  // any name is PLY
            const auto dir = test::scratch_dir(std::string("image_io_fail_") + name);
            // A folder that is not empty: the final rename onto it fails.
            std::filesystem::create_directories(dir / "busy" / "inside");
            EXPECT_THROW(write(dir / target), std::runtime_error) << name << " " << target;
            std::vector<std::string> left;
            for (const auto& e : std::filesystem::directory_iterator(dir))
                left.push_back(e.path().filename());
            EXPECT_EQ(left, std::vector<std::string>{"busy"}) << name << " " << target;
        }
}

TEST(ImageIo, AStagedWriteAppearsAtCommit) {
    const auto dir = test::scratch_dir("image_io_staged");
    OutputFiles batch;
    write_image(batch, dir / "a.png", test_pattern(4, 4));
    write_ply(batch, dir / "a.ply", Mesh{});
    EXPECT_FALSE(std::filesystem::exists(dir / "a.png"));
    batch.commit();
    EXPECT_EQ(read_image(dir / "a.png").width, 4);
    EXPECT_EQ(read_ply(dir / "a.ply").triangle_count(), 0u);
}

// The extensions image_format_problem() accepts without loading OpenImageIO: each must be one it
// writes, and reads back at the written size, or a command would learn otherwise after its work.
TEST(ImageIo, EveryExtensionKnownWithoutOpenImageIoIsOneItWrites) {
    const auto dir = test::scratch_dir("image_io_extensions");
    for (const std::string& ext : common_image_extensions()) {
        SCOPED_TRACE(ext);
        const auto path = dir / ("a" + ext);
        EXPECT_EQ(image_format_problem(path), "");
        write_image(path, test_pattern(6, 5));
        const Image back = read_image(path);
        EXPECT_EQ(back.width, 6);
        EXPECT_EQ(back.height, 5);
    }
    EXPECT_NE(image_format_problem(dir / "a.nosuchformat"), "");
    EXPECT_EQ(image_format_problem(dir / "A.PNG"), "");
}

}  // namespace
}  // namespace isowall
