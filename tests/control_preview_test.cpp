// Previews for the control window: the box filter that shrinks a tile's frame, the preview
// message made from it, and nearest-neighbour scaling back into the window.
#include <gtest/gtest.h>

#include "core/image_ops.h"
#include "core/preview.h"
#include "wall_protocol/protocol.h"

namespace isowall {
namespace {

Image solid(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    Image img;
    img.resize(w, h);
    for (std::size_t i = 0; i < img.pixel_count(); ++i) {
        img.rgba[4 * i] = r;
        img.rgba[4 * i + 1] = g;
        img.rgba[4 * i + 2] = b;
        img.rgba[4 * i + 3] = 255;
    }
    return img;
}

std::uint8_t red_at(const Image& img, int x, int y) {
    return img.rgba[4 * (static_cast<std::size_t>(y) * img.width + x)];
}

TEST(ControlPreview, ShrinkFactorOfDegenerateSizes) {
    EXPECT_EQ(shrink_factor(0, 0, 256), 1);
    EXPECT_EQ(shrink_factor(1, 1, 256), 1);
    EXPECT_EQ(shrink_factor(256, 10, 256), 1);
    EXPECT_EQ(shrink_factor(257, 10, 256), 2);
    EXPECT_EQ(shrink_factor(10, 1000, 0), 1000);  // max_side < 1 counts as 1
    EXPECT_EQ(shrink_factor(1024, 768, 512), 2);
    EXPECT_EQ(shrink_factor(1024, 768, 170), 7);  // 147x110: never more than 170 a side
}

TEST(ControlPreview, ShrinkBoxAveragesEachBoxAndClipsTheEdges) {
    // 5x3, red = x * 10 + y: factor 2 gives 3x2, the last column and row from clipped boxes.
    Image img = solid(5, 3, 0, 7, 200);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x)
            img.rgba[4 * (static_cast<std::size_t>(y) * 5 + x)] =
                static_cast<std::uint8_t>(x * 10 + y);
    const Image small = shrink_box(img, 2);
    ASSERT_EQ(small.width, 3);
    ASSERT_EQ(small.height, 2);
    EXPECT_TRUE(small.depth.empty());
    EXPECT_EQ(red_at(small, 0, 0), 6);   // (0 + 1 + 10 + 11) / 4 = 5.5, rounded
    EXPECT_EQ(red_at(small, 2, 0), 41);  // (40 + 41) / 2 = 40.5, rounded
    EXPECT_EQ(red_at(small, 1, 1), 27);  // (22 + 32) / 2: the last row alone
    EXPECT_EQ(red_at(small, 2, 1), 42);  // one pixel
    EXPECT_EQ(small.rgba[1], 7);
    EXPECT_EQ(small.rgba[2], 200);
    EXPECT_EQ(small.rgba[3], 255);
}

TEST(ControlPreview, ShrinkBoxByOneIsACopy) {
    const Image img = solid(4, 3, 1, 2, 3);
    EXPECT_EQ(shrink_box(img, 1).rgba, img.rgba);
    EXPECT_EQ(shrink_box(img, 0).rgba, img.rgba);
    const Image empty = shrink_box(Image{}, 3);
    EXPECT_EQ(empty.width, 0);
    EXPECT_TRUE(empty.rgba.empty());
}

TEST(ControlPreview, AThinLineFadesInsteadOfVanishing) {
    // One white column in black: point sampling would drop it; the box keeps a quarter of it.
    Image img = solid(8, 8, 0, 0, 0);
    for (int y = 0; y < 8; ++y)
        for (int k = 0; k < 3; ++k) img.rgba[4 * (static_cast<std::size_t>(y) * 8 + 5) + k] = 255;
    const Image small = shrink_box(img, 4);
    EXPECT_EQ(red_at(small, 1, 0), 64);  // 255 * 4 / 16, rounded
    EXPECT_EQ(red_at(small, 0, 0), 0);
}

TEST(ControlPreview, MakePreviewKeepsTheLargerSideWithinTheLimit) {
    const Image frame = solid(1024, 768, 10, 20, 30);
    const PreviewMsg p{make_preview(frame, 42, 300)};
    EXPECT_EQ(p.generation, 42u);
    EXPECT_EQ(p.width, 256);  // factor 4
    EXPECT_EQ(p.height, 192);
    ASSERT_EQ(p.rgb.size(), 256u * 192 * 3);
    EXPECT_EQ(p.rgb[0], 10);
    EXPECT_EQ(p.rgb[1], 20);
    EXPECT_EQ(p.rgb[2], 30);
    // It goes on the wire as it is.
    EXPECT_NO_THROW(decode_as<PreviewMsg>(Tag::preview, encode(p)));
    // The limit is clamped to what a message carries.
    const PreviewMsg big{make_preview(solid(3000, 10, 0, 0, 0), 1, 1 << 20)};
    EXPECT_LE(big.width, kMaxPreviewSide);
    EXPECT_EQ(make_preview(solid(3, 2, 0, 0, 0), 1, 0).width, 1);  // max_side 0 counts as 1
}

TEST(ControlPreview, AnEmptyFrameGivesOneBlackPixel) {
    const PreviewMsg p{make_preview(Image{}, 7, 256)};
    EXPECT_EQ(p.width, 1);
    EXPECT_EQ(p.height, 1);
    EXPECT_EQ(p.rgb, (std::vector<std::uint8_t>{0, 0, 0}));
    EXPECT_NO_THROW(decode_as<PreviewMsg>(Tag::preview, encode(p)));
}

TEST(ControlPreview, PreviewImageIsTheRgbWithOpaqueAlpha) {
    PreviewMsg p;
    p.width = 2;
    p.height = 1;
    p.rgb = {1, 2, 3, 4, 5, 6};
    const Image img = preview_image(p);
    EXPECT_EQ(img.width, 2);
    EXPECT_EQ(img.rgba, (std::vector<std::uint8_t>{1, 2, 3, 255, 4, 5, 6, 255}));
}

TEST(ControlPreview, ResampleNearestTakesThePixelUnderEachCentre) {
    Image src = solid(2, 1, 0, 0, 0);
    src.rgba[4] = 200;  // right pixel red 200
    const Image up = resample_nearest(src, 4, 2);
    ASSERT_EQ(up.width, 4);
    EXPECT_EQ(red_at(up, 0, 0), 0);
    EXPECT_EQ(red_at(up, 1, 1), 0);
    EXPECT_EQ(red_at(up, 2, 0), 200);
    EXPECT_EQ(red_at(up, 3, 1), 200);
    const Image down = resample_nearest(solid(9, 9, 5, 5, 5), 2, 2);
    EXPECT_EQ(red_at(down, 1, 1), 5);
    // Degenerate: an empty source gives black, an empty target nothing.
    const Image from_empty = resample_nearest(Image{}, 2, 2);
    const std::vector<std::uint8_t> black{0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 255};
    EXPECT_EQ(from_empty.rgba, black);
    EXPECT_TRUE(resample_nearest(src, 0, 5).rgba.empty());
}

}  // namespace
}  // namespace isowall
