// EngineFrame, as a wall rank uses it: a region cast in two bands (a coarse band of a ray limit,
// then the rest) casts every pixel of the region once, and its image is the one-call frame's;
// and a region whose rays meet groups an earlier region found hears of them (seen()), at each
// ray or, where the sink allows, after each level with the level cast on several threads.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <set>
#include <vector>

#include "app/whole_frame.h"
#include "engine/progressive_engine.h"
#include "progressive/trace.h"
#include "render/renderer_sink.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "volume/phantom.h"

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
    const FrameResult whole = draw_frame(engine, fv, *renderer);
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

// Records what the engine tells a sink: the groups added and the groups seen.
class SeenSink final : public GroupSink, public SeenGroups {
  public:
    void add(const Group& g) override { added.insert(g.id); }
    void seen(std::uint32_t id) override { seen_ids.push_back(id); }
    std::set<std::uint32_t> added;
    std::vector<std::uint32_t> seen_ids;
};

TEST(EngineFrame, ARegionHearsOfTheEarlierGroupsItsRaysMeetAtEachRayOrAfterEachLevel) {
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 160, 120, kPhantomSkinIso);
    const PixelRect left{0, 0, 80, 120}, right{80, 0, 80, 120};
    for (const bool after_level : {false, true}) {
        SCOPED_TRACE(after_level ? "after each level, on two threads" : "at each ray, on one");
        auto ex = make_surface_extractor(p, {}, nullptr, ThreadBudget{2});
        EngineOptions opt;
        opt.threads = after_level ? 2 : 1;
        ProgressiveEngine engine(*ex, opt);
        std::atomic<bool> stop{false};
        EngineFrame frame(engine, fv, stop);
        // The left half first: its groups (passes of up to 1000 cells) reach across.
        SeenSink left_sink;
        RegionCursor a = frame.cursor(fv, left);
        ASSERT_TRUE(frame.cast(fv, a, left_sink));
        ASSERT_FALSE(left_sink.added.empty());
        SeenSink sink;
        RegionCursor b = frame.cursor(fv, right);
        const double workers0 = frame.workers().sum_s;
        ASSERT_TRUE(frame.cast(fv, b, sink));
        ASSERT_FALSE(sink.seen_ids.empty());
        std::size_t earlier = 0;
        for (const std::uint32_t id : sink.seen_ids) {
            // Each seen group is one of the left half's or one this region found itself.
            const bool of_left = left_sink.added.count(id) == 1;
            EXPECT_TRUE(of_left || sink.added.count(id) == 1) << id;
            earlier += of_left;
        }
        EXPECT_GT(earlier, 0u) << "the right half's rays met none of the left half's groups";
        // One thread hears at each ray; on two, the level runs on both and hears after it.
        if (after_level)
            EXPECT_GT(frame.workers().sum_s, workers0);
        else
            EXPECT_EQ(frame.workers().sum_s, workers0);
    }
}

// A wall job enters the engine from whatever stage its rank was in (a help job sets up its image
// as render): the region's rays are intersection from the cast's first ray. They once went on in
// the caller's stage until a group or a coverage read switched it, and the wall study read that
// as render costs of help jobs.
TEST(EngineFrame, ARegionsRaysAreIntersectionWhateverStageItWasEnteredFrom) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    TraceRecorder trace;
    EngineOptions opt;
    opt.trace = &trace;
    opt.screen_box = opt.screen_mask = false;  // every ray is cast
    ProgressiveEngine engine(*ex, opt);
    // An isovalue above every voxel: the rays find nothing, so nothing in the cast draws.
    const FrameView fv = test::make_view(p, 320, 240, 1e6);
    std::atomic<bool> stop{false};
    RecordingSink sink;
    EngineFrame frame(engine, fv, stop);
    RegionCursor c = frame.cursor(fv, fv.screen());
    trace.switch_to(Stage::render);
    const std::size_t entered = trace.spans().size();
    ASSERT_TRUE(frame.cast(fv, c, sink));
    ASSERT_TRUE(c.done);
    ASSERT_EQ(c.rays, std::size_t(320 * 240));
    ASSERT_TRUE(sink.groups.empty());
    trace.close();
    const auto& spans = trace.spans();
    ASSERT_GT(spans.size(), entered + 1);
    ASSERT_EQ(spans[entered].stage, std::uint8_t(Stage::render));  // the caller's
    double render = 0, intersection = 0;
    for (std::size_t i = entered; i < spans.size(); ++i) {
        if (spans[i].stage == std::uint8_t(Stage::render)) render += spans[i].cpu_s;
        if (spans[i].stage == std::uint8_t(Stage::intersection)) intersection += spans[i].cpu_s;
    }
    EXPECT_GT(intersection, 0.0);
    EXPECT_LT(render, 0.2 * intersection)
        << "render " << render << " s, intersection " << intersection << " s";
}

}  // namespace
}  // namespace isowall
