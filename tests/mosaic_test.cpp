// The master's mosaic and depth compositing are pure functions over images.
#include <gtest/gtest.h>

#include "master/mosaic.h"

namespace isowall {
namespace {

Image solid(int w, int h, std::uint8_t grey, float depth) {
    Image img;
    img.resize(w, h);
    for (std::size_t i = 0; i < img.pixel_count(); ++i) {
        for (int k = 0; k < 3; ++k) img.rgba[4 * i + k] = grey;
        img.rgba[4 * i + 3] = 255;
        img.depth[i] = depth;
    }
    return img;
}

std::uint8_t red_at(const Image& img, int x, int y) {
    return img.rgba[4 * (std::size_t(y) * img.width + x)];
}

TEST(Mosaic, EmptyIsBezelGreyAndATileLandsAtItsRectangle) {
    Mosaic m = empty_mosaic(10, 4);
    EXPECT_EQ(red_at(m.image, 0, 0), kBezelGrey);
    paste(m, solid(4, 4, 200, 0.5f), {6, 0, 4, 4});
    EXPECT_EQ(red_at(m.image, 5, 2), kBezelGrey);
    EXPECT_EQ(red_at(m.image, 6, 2), 200);
    EXPECT_EQ(red_at(m.image, 9, 3), 200);
}

TEST(Mosaic, OverlapsAverageAndPixelsOffTheMosaicAreSkipped) {
    Mosaic m = empty_mosaic(6, 2);
    paste(m, solid(4, 2, 100, 0.5f), {0, 0, 4, 2});
    paste(m, solid(4, 2, 200, 0.5f), {2, 0, 4, 2});
    EXPECT_EQ(red_at(m.image, 1, 0), 100);
    EXPECT_EQ(red_at(m.image, 2, 0), 150);  // both projectors light it
    EXPECT_EQ(red_at(m.image, 5, 1), 200);
    paste(m, solid(4, 4, 10, 0.5f), {-2, -2, 4, 4});   // a degenerate placement, partly outside
    EXPECT_EQ(red_at(m.image, 0, 0), (100 + 10) / 2);  // lit by the first tile and this one
}

TEST(Mosaic, DepthCompositingKeepsTheNearerPixel) {
    Image owner = solid(4, 4, 50, 0.6f);
    Image helper = solid(2, 2, 250, 0.4f);
    helper.depth[3] = 0.9f;  // behind the owner's surface there
    composite_by_depth(owner, helper, {1, 1, 2, 2});
    EXPECT_EQ(red_at(owner, 0, 0), 50);
    EXPECT_EQ(red_at(owner, 1, 1), 250);
    EXPECT_FLOAT_EQ(owner.depth[1 * 4 + 1], 0.4f);
    EXPECT_EQ(red_at(owner, 2, 2), 50);  // the helper's pixel was farther
    Image no_depth;
    no_depth.width = 1;
    no_depth.height = 1;
    no_depth.rgba = {1, 2, 3, 4};
    EXPECT_THROW(composite_by_depth(owner, no_depth, {0, 0, 1, 1}), std::invalid_argument);
}

}  // namespace
}  // namespace isowall
