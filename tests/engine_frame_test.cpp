// EngineFrame, as a wall rank uses it: a region cast in two bands (a coarse band of a ray limit,
// then the rest) casts every pixel of the region once, and its image is the one-call frame's.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>

#include "common/volume/phantom.h"
#include "engine/progressive_engine.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"

namespace isowall {
namespace {

TEST(EngineFrame, ACoarseBandThenTheRestCastEveryPixelOnceWithLimitedPropagation) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.order = RayOrderKind::refining_grid;
    // Tiny groups: the image comes from the rays, not from propagation, so a pixel left without
    // its ray shows (a band that cast nothing left most of the screen to the coarse levels).
    opt.propagation.max_count = 4;
    const FrameView fv = test::make_view(p, 200, 150, kPhantomSkinIso);
    ProgressiveEngine engine(*ex, opt);
    const FrameResult whole = engine.run(fv, *renderer);
    ASSERT_TRUE(whole.completed);

    std::atomic<bool> stop{false};
    RendererSink sink(*renderer);
    sink.begin(fv);
    EngineFrame frame(engine, fv, stop);
    RegionCursor c = frame.cursor(fv, fv.screen());
    const std::size_t area = c.pixels;  // the screen mask's pixels in the region
    ASSERT_GT(area, 0u);
    ASSERT_LE(area, std::size_t(c.rect.width) * c.rect.height);
    ASSERT_TRUE(frame.cast(fv, c, sink, area / 16));  // the coarse band
    EXPECT_FALSE(c.done);
    EXPECT_GE(c.rays, area / 16);
    EXPECT_LT(c.rays, area);
    ASSERT_TRUE(frame.cast(fv, c, sink));  // the fine band: every ray left
    EXPECT_TRUE(c.done);
    EXPECT_EQ(c.rays, area);
    Image banded;
    sink.read_back(banded);
    const test::ImageComparison m = test::compare_images(banded, whole.final_image);
    EXPECT_GE(m.mask_iou, 0.999) << m;
    EXPECT_GE(m.equal_share, 0.999) << m;
}

}  // namespace
}  // namespace isowall
