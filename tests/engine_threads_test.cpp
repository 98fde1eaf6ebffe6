// The engine on several threads (EngineOptions::threads): the final image is the full surface's
// for every rule, the same from run to run, and every visited unit is in exactly one group.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <tuple>

#include "app/whole_frame.h"
#include "engine/progressive_engine.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"
#include "volume/phantom.h"
#include "volume/volume.h"

namespace isowall {
namespace {

struct Rule {
    std::string name;
    EngineOptions options;
};

std::vector<Rule> rules() {
    std::vector<Rule> r;
    r.push_back({"exact_count", {}});
    EngineOptions approx;
    approx.intersect = IntersectMode::approximate;
    approx.propagation.mode = PropagationMode::cutoff_angle;
    r.push_back({"approximate_angle", approx});
    EngineOptions facing;
    facing.propagation.facing_only = true;
    facing.propagation.max_count = 300;  // many passes, so that threads meet often
    r.push_back({"facing_only_small_passes", facing});
    return r;
}

FrameResult run(const Volume& volume, const FrameView& fv, EngineOptions opt, int threads) {
    auto ex = make_surface_extractor(volume, {}, nullptr, ThreadBudget{threads});
    auto renderer = make_renderer("osmesa");
    opt.threads = threads;
    FrameResult fr = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer);
    EXPECT_TRUE(fr.completed);
    // Every group's units are distinct from every other group's.
    std::set<std::tuple<int, int, int, int>> units;
    std::size_t repeated = 0;
    for (const Group& g : fr.groups) {
        if (g.refinement) continue;
        for (const glm::ivec3 c : g.cells)
            repeated += !units.insert({c.x, c.y, c.z, g.level}).second;
    }
    EXPECT_EQ(repeated, 0u) << threads << " threads";
    return fr;
}

TEST(Threads, FinalImageMatchesTheFullSurfaceAndRepeats) {
    const Volume p = make_phantom();
    for (const Rule& rule : rules())
        for (const double iso : {kPhantomSkinIso, kPhantomBoneIso}) {
            const FrameView fv = test::make_view(p, 240, 180, iso, 25, 10);
            auto ex = make_surface_extractor(p);
            auto renderer = make_renderer("osmesa");
            const Image full = test::full_surface_image(*ex, *renderer, fv);
            const FrameResult one = run(p, fv, rule.options, 1);
            for (const int threads : {2, 3}) {
                const FrameResult a = run(p, fv, rule.options, threads);
                const FrameResult b = run(p, fv, rule.options, threads);
                const test::ImageComparison vs_full = test::compare_images(a.final_image, full);
                const test::ImageComparison again =
                    test::compare_images(a.final_image, b.final_image);
                const test::ImageComparison vs_one =
                    test::compare_images(a.final_image, one.final_image);
                std::cout << rule.name << " iso " << iso << ", " << threads
                          << " threads: " << a.groups.size()
                          << " groups (1 thread: " << one.groups.size() << "), against full IoU "
                          << vs_full.mask_iou << " equal " << vs_full.equal_share << "; run to run "
                          << again.differing_pixels << " px differ; against 1 thread "
                          << vs_one.differing_pixels << " px\n";
                EXPECT_GE(vs_full.mask_iou, 0.999) << rule.name;
                EXPECT_GE(vs_full.equal_share, 0.999) << rule.name;
                EXPECT_GE(again.equal_share, 0.9999) << rule.name;
                EXPECT_GE(vs_one.equal_share, 0.9999) << rule.name;
                EXPECT_EQ(a.rays_cast, one.rays_cast) << rule.name;
            }
        }
}

TEST(Threads, AdaptiveResolutionRepeatsAcrossThreads) {
    // Meta-cells and refinements (claimed under a lock) on three threads: the image of one thread.
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 240, 180, kPhantomSkinIso, 0, 0, 1.0f);
    for (const bool refine : {true, false}) {
        EngineOptions opt;
        opt.adaptive = true;
        opt.adaptive_pixels = 2.5f;
        opt.adaptive_refine = refine;
        const FrameResult one = run(p, fv, opt, 1);
        const FrameResult three = run(p, fv, opt, 3);
        const test::ImageComparison m = test::compare_images(three.final_image, one.final_image);
        std::cout << "adaptive 2.5 px" << (refine ? "" : ", unrefined") << ": "
                  << m.differing_pixels << " px differ from 1 thread, IoU " << m.mask_iou << "\n";
        EXPECT_GE(m.mask_iou, 0.999);
        EXPECT_GE(m.equal_share, 0.999);
    }
}

TEST(Threads, TheWorkersCpuIsCounted) {
    // The CPU of the threads beside the caller is in the frame's figures (a wall rank's trace and
    // emulated clock add it); one thread has none.
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 240, 180, kPhantomSkinIso);
    const FrameResult one = run(p, fv, {}, 1);
    const FrameResult two = run(p, fv, {}, 2);
    std::cout << "workers' CPU: 1 thread " << one.workers.sum_s << " s, 2 threads "
              << two.workers.sum_s << " s (beyond the caller " << two.workers.beyond_s << " s)\n";
    EXPECT_EQ(one.workers.sum_s, 0.0);
    EXPECT_EQ(one.workers.beyond_s, 0.0);
    EXPECT_GT(two.workers.sum_s, 0.0);
    EXPECT_LE(two.workers.beyond_s, two.workers.sum_s);
}

TEST(Threads, EveryLevelEndsWithASampleOfItsOwn) {
    // On several threads a level's closing sample (and present) waits until the next level's
    // threads run: it still carries its own level's number, the levels and rays never go back,
    // and each level has a sample with at least the rays one thread had cast by its end.
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 240, 180, kPhantomSkinIso, 25, 10);
    const FrameResult one = run(p, fv, {}, 1);
    const FrameResult two = run(p, fv, {}, 2);
    std::map<int, std::size_t> end_one, end_two;  // level -> most rays of a sample of it
    for (const auto& [frame, ends] : {std::tie(one, end_one), std::tie(two, end_two)}) {
        for (std::size_t i = 1; i < frame.timeline.size(); ++i) {
            EXPECT_GE(frame.timeline[i].level, frame.timeline[i - 1].level) << i;
            EXPECT_GE(frame.timeline[i].rays, frame.timeline[i - 1].rays) << i;
        }
        for (const TimelineSample& s : frame.timeline)
            ends[s.level] = std::max(ends[s.level], s.rays);
    }
    ASSERT_GE(end_one.size(), 3u);
    ASSERT_EQ(end_two.size(), end_one.size());
    // The fill level's first part holds the pixels that showed nothing before it (ray_order.h),
    // which depends on what the threads drew by then: its end may differ by a few rays.
    const int fill_first = std::prev(end_one.end(), 2)->first;
    for (const auto& [level, rays] : end_one) {
        ASSERT_TRUE(end_two.count(level)) << "level " << level;
        if (level != fill_first) {
            EXPECT_GE(end_two[level], rays) << "level " << level;
        }
    }
    EXPECT_EQ(end_two.rbegin()->second, end_one.rbegin()->second) << "every ray, in the end";
}

TEST(Threads, AStopEndsEveryThread) {
    // A frame stopped before it starts ends at once, on every thread, with nothing drawn.
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p, {}, nullptr, ThreadBudget{3});
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.threads = 3;
    const std::atomic<bool> stop{true};
    const FrameResult fr =
        draw_frame(ProgressiveEngine(*ex, opt), test::make_view(p, 160, 120, kPhantomSkinIso),
                   *renderer, &stop);
    EXPECT_FALSE(fr.completed);
    EXPECT_EQ(fr.group_count, 0u);
}

}  // namespace
}  // namespace isowall
