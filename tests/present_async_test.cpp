// Presents that do not wait for the renderer (Renderer::flush and finished, GroupSink::
// present_async and presented): the frame they start is the one finish() gives, and the engine
// casts on while one is in flight, keeping that present's timeline sample back until its groups
// show.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <set>
#include <vector>

#include "engine/progressive_engine.h"
#include "extract/group_sink.h"
#include "render/renderer_sink.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

TEST(PresentAsync, FlushedFrameIsTheFinishedOneOnEveryBackEnd) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    const FrameView fv = test::make_view(p, 160, 120, kPhantomSkinIso);
    Group surface;
    surface.mesh = ex->extract_full(fv.iso);
    for (const char* backend : {"osmesa", "egl"}) {
        SCOPED_TRACE(backend);
        auto r = make_renderer(backend);
        const Image finished = draw_alone(*r, surface.mesh, fv);  // finish() waits
        EXPECT_TRUE(r->finished(false));                          // no flush outstanding

        RendererSink sink(*r);
        sink.begin(fv);
        sink.add(surface);
        ASSERT_TRUE(sink.present_async());
        // Asked without waiting until it is done: it must end without a wait.
        std::size_t asks = 1;
        while (!sink.presented(false) && asks < 100'000'000) ++asks;
        ASSERT_TRUE(sink.presented(false)) << asks << " asks";
        Image flushed;
        sink.read_back(flushed);
        const test::ImageComparison m = test::compare_images(flushed, finished);
        EXPECT_EQ(m.differing_pixels, 0u) << m;
        EXPECT_GT(m.covered_both, 1000u) << m;

        // A second flush replaces the first fence; a wait ends it.
        sink.begin(fv);
        sink.add(surface);
        r->flush();
        r->flush();
        EXPECT_TRUE(r->finished(true));
        EXPECT_TRUE(r->finished(false));
    }
}

// Counts presents: a sink that cannot present without waiting.
class WaitingSink final : public GroupSink {
  public:
    void add(const Group&) override {}
    double present() override {
        ++presents;
        return 0;
    }
    int presents = 0;
};

TEST(PresentAsync, TeePresentsTheSinksThatCannotWaitAtOnce) {
    auto r = make_renderer("osmesa");
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 64, 48, kPhantomSkinIso);
    RendererSink drawn(*r);
    WaitingSink waiting;
    RecordingSink recorded;
    TeeSink tee({&drawn, &waiting, &recorded});
    tee.begin(fv);
    ASSERT_TRUE(tee.present_async());
    EXPECT_EQ(waiting.presents, 1);
    EXPECT_TRUE(tee.presented(true));
    EXPECT_FALSE(WaitingSink().present_async());  // the default: present() is the caller's
}

// Draws into a renderer and presents without waiting, but says a present is done only after
// `lag` questions, so every present stays in flight while the engine casts on.
class LaggingSink final : public GroupSink, public ShownPixels {
  public:
    explicit LaggingSink(Renderer& r, int lag) : inner_(r), lag_(lag) {}
    void begin(const FrameView& view) override { inner_.begin(view); }
    void add(const Group& group) override {
        inner_.add(group);
        ++added;
        added_in_flight += left_ > 0 ? 1 : 0;
    }
    bool present_async() override {
        EXPECT_EQ(left_, 0) << "a present began while another was in flight";
        inner_.present_async();
        groups_presented.insert(added);
        left_ = lag_;
        return true;
    }
    bool presented(bool wait) override {
        if (left_ > 0 && !wait) {
            --left_;
            return false;
        }
        left_ = 0;
        return inner_.presented(true);
    }
    void coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) override {
        inner_.coverage(covered, rect);
    }
    void read_back(Image& out) { inner_.read_back(out); }

    std::size_t added = 0, added_in_flight = 0;
    std::set<std::size_t> groups_presented;  // the groups added when each present began

  private:
    RendererSink inner_;
    int lag_, left_ = 0;
};

TEST(PresentAsync, EngineCastsOnAndKeepsEachPresentsSampleUntilItShows) {
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 200, 150, kPhantomSkinIso);
    for (int threads : {1, 2}) {
        SCOPED_TRACE(threads);
        auto ex = make_surface_extractor(p, {}, nullptr, ThreadBudget{threads});
        auto r = make_renderer("osmesa");
        EngineOptions opt;
        opt.threads = threads;
        opt.propagation.max_count = 200;  // many groups, so presents come while casting
        ProgressiveEngine engine(*ex, opt);
        const Image full = test::full_surface_image(*ex, *r, fv);

        LaggingSink sink(*r, 50);
        const std::atomic<bool> stop{false};
        const FrameResult fr = engine.run(fv, fv.screen(), sink, stop);
        ASSERT_TRUE(fr.completed);
        Image image;
        sink.read_back(image);

        EXPECT_GT(sink.groups_presented.size(), 2u);
        EXPECT_GT(sink.added_in_flight, 0u) << "no group was drawn while a present was in flight";
        // Every present's sample is in the timeline, counting the groups it presented, and the
        // timeline stays in order.
        std::set<std::size_t> sampled;
        for (std::size_t i = 0; i < fr.timeline.size(); ++i) {
            const TimelineSample& s = fr.timeline[i];
            sampled.insert(s.groups);
            if (i == 0) continue;
            const TimelineSample& b = fr.timeline[i - 1];
            EXPECT_GE(s.time_s, b.time_s) << i;
            EXPECT_GE(s.rays, b.rays) << i;
            EXPECT_GE(s.groups, b.groups) << i;
        }
        for (std::size_t g : sink.groups_presented) EXPECT_TRUE(sampled.count(g)) << g;
        EXPECT_EQ(fr.timeline.back().groups, fr.group_count);
        EXPECT_EQ(sink.added, fr.group_count);

        const test::ImageComparison m = test::compare_images(image, full);
        EXPECT_GE(m.mask_iou, 0.999) << m;
        EXPECT_GE(m.equal_share, 0.999) << m;
    }
}

}  // namespace
}  // namespace isowall
