// The progressive engine: after every ray its image is the full surface's; propagation keeps its
// invariants; an interrupt stops a frame and the next frame is the new view only.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <tuple>

#include "app/whole_frame.h"
#include "core/image_ops.h"
#include "core/pixel_rect_ops.h"
#include "core/ray.h"
#include "engine/progressive_engine.h"
#include "render/renderer_sink.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"
#include "volume/phantom.h"
#include "volume/volume.h"

namespace isowall {
namespace {

using test::full_surface_image;
using test::make_view;

using Combo = std::tuple<RayOrderKind, IntersectMode, PropagationMode>;

std::string combo_name(const Combo& c) {
    return std::string(to_string(std::get<0>(c))) +
           (std::get<1>(c) == IntersectMode::exact ? "_exact" : "_approximate") +
           (std::get<2>(c) == PropagationMode::max_count ? "_count" : "_angle");
}

class FinalImage : public ::testing::TestWithParam<Combo> {};

void expect_final_matches_full(const Volume& volume, double iso, const Combo& combo, int w, int h,
                               float yaw = 0, bool facing_only = false) {
    auto ex = make_surface_extractor(volume);
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    std::tie(opt.order, opt.intersect, opt.propagation.mode) = combo;
    opt.propagation.max_count = 2000;
    opt.propagation.facing_only = facing_only;
    const FrameView fv = make_view(volume, w, h, iso, yaw, 10);
    ProgressiveEngine engine(*ex, opt);
    FrameResult fr = draw_frame(engine, fv, *renderer);
    ASSERT_TRUE(fr.completed);
    const Image full = full_surface_image(*ex, *renderer, fv);
    const test::ImageComparison m = test::compare_images(fr.final_image, full);
    if (m.mask_iou < 0.999 || m.equal_share < 0.999)
        test::write_diff_images(test::scratch_dir("final_" + combo_name(combo)), "final",
                                fr.final_image, full);
    EXPECT_GE(m.mask_iou, 0.999) << combo_name(combo) << " iso " << iso;
    EXPECT_GE(m.equal_share, 0.999) << combo_name(combo) << " iso " << iso;
    // Every pixel of the screen mask had its ray (and the approximate mode a second, exact one).
    const std::size_t box = fr.screen_pixels;
    EXPECT_GT(box, 0u);
    EXPECT_LE(box, std::size_t(fr.screen_rect.width) * fr.screen_rect.height);
    EXPECT_EQ(fr.rays_cast, std::get<1>(combo) == IntersectMode::exact ? box : 2 * box);
    EXPECT_GT(fr.groups.size(), 0u);
    std::cout << combo_name(combo) << " iso " << iso << ": IoU " << m.mask_iou << ", equal "
              << m.equal_share * 100 << "%, " << fr.groups.size() << " groups, " << fr.rays_cast
              << " rays, " << fr.elapsed_s << " s\n";
}

TEST_P(FinalImage, PhantomMatchesTheFullSurface) {
    const Volume p = make_phantom();
    for (double iso : {kPhantomSkinIso, kPhantomBoneIso})
        expect_final_matches_full(p, iso, GetParam(), 240, 180, 25);
}

TEST_P(FinalImage, SharedCtHeadMatchesTheFullSurface) {
    const auto data = test::shared_data_dir();
    if (!data) GTEST_SKIP() << "../shared/data is absent: skipping the CT head";
    const Volume v = load_nrrd(*data / "cthead.nhdr");
    expect_final_matches_full(v, 600, GetParam(), 200, 150);
}

INSTANTIATE_TEST_SUITE_P(
    AllOptions, FinalImage,
    ::testing::Combine(::testing::Values(RayOrderKind::refining_grid, RayOrderKind::screen_readback,
                                         RayOrderKind::dynamic_grid),
                       ::testing::Values(IntersectMode::exact, IntersectMode::approximate),
                       ::testing::Values(PropagationMode::max_count,
                                         PropagationMode::cutoff_angle)),
    [](const auto& info) { return combo_name(info.param); });

// The visible-surface rule (passes stop where the surface faces away) leaves the image alone:
// what a pass leaves out is seeded by a later ray.
TEST(FacingOnly, FinalImageMatchesTheFullSurface) {
    const Volume p = make_phantom();
    const auto data = test::shared_data_dir();
    for (const IntersectMode mode : {IntersectMode::exact, IntersectMode::approximate})
        for (const PropagationMode prop :
             {PropagationMode::max_count, PropagationMode::cutoff_angle}) {
            const Combo combo{RayOrderKind::dynamic_grid, mode, prop};
            for (double iso : {kPhantomSkinIso, kPhantomBoneIso})
                expect_final_matches_full(p, iso, combo, 240, 180, 25, true);
            if (data)
                expect_final_matches_full(load_nrrd(*data / "cthead.nhdr"), 600, combo, 200, 150, 0,
                                          true);
        }
}

TEST(FacingOnly, PassesTakeNoMoreCellsThanWithout) {
    // From one seed, the rule can only leave cells out: the pass with it takes a subset.
    const Volume p = make_phantom();
    const FrameView fv = make_view(p, 240, 180, kPhantomSkinIso, 25, 10);
    const Ray ray = pixel_ray(glm::inverse(fv.camera.view()), fv.frustum, fv.width, fv.height,
                              {fv.width / 2, fv.height / 2});
    std::vector<std::size_t> sizes;
    std::vector<std::set<std::tuple<int, int, int>>> cells;
    for (const bool facing : {false, true}) {
        auto ex = make_surface_extractor(p);
        ex->begin_frame(fv.iso);
        const RayHit hit = ex->cast(ray, IntersectMode::exact);
        ASSERT_TRUE(hit.found);
        PropagationParams params;
        params.max_count = 1 << 30;  // the whole connected surface, less what the rule stops
        params.facing_only = facing;
        const Group g = ex->propagate(hit.cell, 0, params, ray);
        sizes.push_back(g.cells.size());
        cells.emplace_back();
        for (const glm::ivec3 c : g.cells) cells.back().insert({c.x, c.y, c.z});
    }
    std::cout << "one pass over the phantom's skin: " << sizes[0] << " cells, facing only "
              << sizes[1] << "\n";
    EXPECT_LT(sizes[1], sizes[0]);
    EXPECT_GT(sizes[1] * 4, sizes[0]);  // the front of the surface is a good part of it
    for (const auto& c : cells[1]) EXPECT_TRUE(cells[0].count(c));
}

TEST(Engine, FarViewMatchesTheFullSurface) {
    // Far from the eye the ray parameter is large: a walk that nudges t by a fixed amount stops
    // advancing once the nudge is below one float ulp (it hung at zoom 0.3 on vhp_ct_head).
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    ProgressiveEngine engine(*ex);
    FrameView fv = make_view(p, 320, 240, kPhantomSkinIso);
    fv.camera = fit_depth_range(zoom(fv.camera, 0.02f), p.bounds());
    fv.frustum = fv.camera.frustum(320.0f / 240.0f);
    ASSERT_GT(fv.camera.distance(), 5000.0f);
    FrameResult fr = draw_frame(engine, fv, *renderer);
    ASSERT_TRUE(fr.completed);
    const Image full = full_surface_image(*ex, *renderer, fv);
    const test::ImageComparison m = test::compare_images(fr.final_image, full);
    EXPECT_GE(m.mask_iou, 0.999);
    EXPECT_GE(m.equal_share, 0.999);
}

TEST(Propagation, VisitsOnlyActiveCellsEachInOneGroup) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    for (PropagationMode mode : {PropagationMode::max_count, PropagationMode::cutoff_angle}) {
        EngineOptions opt;
        opt.propagation.mode = mode;
        opt.propagation.max_count = 500;  // many small groups
        opt.footprint_pixels = 0;         // cells alone (footprint units: footprint_engine_test)
        ProgressiveEngine engine(*ex, opt);
        const FrameView fv = make_view(p, 160, 120, kPhantomBoneIso, 30, 20);
        FrameResult fr = draw_frame(engine, fv, *renderer);
        ASSERT_TRUE(fr.completed);
        const auto view = p.view<std::uint8_t>();
        std::set<std::tuple<int, int, int>> seen;
        std::size_t inactive = 0, twice = 0, wrong_group = 0;
        for (const Group& g : fr.groups) {
            EXPECT_LE(g.cells.size(), mode == PropagationMode::max_count ? 500u : g.cells.size());
            for (const glm::ivec3 c : g.cells) {
                double corner[8];
                cell_corners(view, c, corner);
                const int cs = cell_case(corner, fv.iso);
                inactive += cs == 0 || cs == 255;
                twice += !seen.insert({c.x, c.y, c.z}).second;
                wrong_group += ex->group_of(c) != g.id;
            }
        }
        EXPECT_EQ(inactive, 0u);
        EXPECT_EQ(twice, 0u);
        EXPECT_EQ(wrong_group, 0u);
        EXPECT_EQ(seen.size(), ex->visited_count());
        EXPECT_GT(fr.groups.size(), 5u);
    }
}

// Triangles as sorted vertex-position triples, so indexed and unindexed meshes compare.
std::multiset<std::tuple<float, float, float, float, float, float, float, float, float>> soup(
    const Mesh& m) {
    std::multiset<std::tuple<float, float, float, float, float, float, float, float, float>> s;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                        c = m.positions[m.indices[3 * t + 2]];
        s.insert({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z});
    }
    return s;
}

TEST(Propagation, InterpolantCacheGivesTheSameTriangles) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    const FrameView fv = make_view(p, 64, 48, kPhantomSkinIso);
    const Ray ray = pixel_ray(glm::inverse(fv.camera.view()), fv.frustum, 64, 48, {32, 24});
    PropagationParams cached, uncached;
    cached.max_count = uncached.max_count = 3000;
    uncached.interpolant_cache = false;
    ex->begin_frame(fv.iso);
    const RayHit hit = ex->cast(ray, IntersectMode::exact);
    ASSERT_TRUE(hit.found);
    const Group a = ex->propagate(hit.cell, 0, cached, ray);
    ex->begin_frame(fv.iso);
    const Group b = ex->propagate(hit.cell, 0, uncached, ray);
    EXPECT_EQ(a.cells, b.cells);
    EXPECT_EQ(soup(a.mesh), soup(b.mesh));
    // Sharing: about one vertex per two triangles with the cache, three per triangle without.
    EXPECT_LT(a.mesh.vertex_count() * 2, b.mesh.vertex_count());
    EXPECT_EQ(b.mesh.vertex_count(), 3 * b.mesh.triangle_count());
}

// Presents as the renderer's sink does, but in the caller's time (no present in flight): each
// timeline sample then reaches `progress` on the casting thread, before its next ray.
class PresentNow final : public GroupSink {
  public:
    explicit PresentNow(RendererSink& s) : s_(s) {}
    void begin(const FrameView& view) override { s_.begin(view); }
    void add(const Group& group) override { s_.add(group); }
    double present() override { return s_.present(); }

  private:
    RendererSink& s_;
};

TEST(Engine, InterruptStopsTheFrameAndTheNextFrameIsTheNewViewOnly) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.progress_interval_s = 0;  // progress at every sample
    opt.threads = 1;              // stop is read before each ray of the one casting thread
    ProgressiveEngine engine(*ex, opt);
    const FrameView first = make_view(p, 200, 150, kPhantomSkinIso);
    // The stop flag is set as a communication thread would, here from the first sample at 300
    // rays or more; the sample reaches the callback on the casting thread, which reads the flag
    // before its next ray: the frame ends at exactly that sample's rays, whatever the load.
    std::atomic<bool> stop{false};
    std::size_t rays_at_stop = 0;
    RendererSink draw(*renderer);
    PresentNow now(draw);
    FrameResult a = engine.run(first, first.screen(), FrameOutput(now, &draw, nullptr), stop,
                               [&](const TimelineSample& s) {
                                   if (s.rays >= 300 && !stop) {
                                       rays_at_stop = s.rays;
                                       stop = true;
                                   }
                               });
    EXPECT_FALSE(a.completed);
    ASSERT_GE(rays_at_stop, 300u);
    EXPECT_EQ(a.rays_cast, rays_at_stop);
    EXPECT_EQ(a.final_image.pixel_count(), 0u);

    // New view and new isovalue: nothing of the first frame may remain.
    const FrameView second = make_view(p, 200, 150, kPhantomBoneIso, 60, -20);
    FrameResult b = draw_frame(engine, second, *renderer);
    ASSERT_TRUE(b.completed);
    const Image full = full_surface_image(*ex, *renderer, second);
    const test::ImageComparison m = test::compare_images(b.final_image, full);
    EXPECT_GE(m.mask_iou, 0.999);
    EXPECT_GE(m.equal_share, 0.999);
}

TEST(Engine, TimelineIsMonotoneAndReachesFullCorrectness) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    ProgressiveEngine engine(*ex);
    const FrameView fv = make_view(p, 240, 180, kPhantomSkinIso);
    FrameResult fr = draw_frame(engine, fv, *renderer);
    ASSERT_TRUE(fr.completed);
    measure_frame(fr, fv, *renderer);
    ASSERT_GT(fr.timeline.size(), 5u);
    for (std::size_t i = 1; i < fr.timeline.size(); ++i) {
        EXPECT_GE(fr.timeline[i].time_s, fr.timeline[i - 1].time_s);
        EXPECT_GE(fr.timeline[i].rays, fr.timeline[i - 1].rays);
        EXPECT_GE(fr.timeline[i].triangles, fr.timeline[i - 1].triangles);
    }
    EXPECT_DOUBLE_EQ(fr.timeline.back().correctness.c, 1.0);
    EXPECT_DOUBLE_EQ(fr.timeline.back().correctness.final_pixels, 1.0);
    // The progressive promise: most of the image long before most of the rays. Measured against
    // the screen box's pixels, every ray without the screen mask: the mask drops about half of
    // them here, all from the end of the frame, which would only move the denominator.
    const PixelRect box = screen_box(p.bounds(), fv.camera.view(), fv.frustum, fv.width, fv.height);
    for (const auto& s : fr.timeline)
        if (s.correctness.c >= 0.9) {
            EXPECT_LT(double(s.rays) / (double(box.width) * double(box.height)), 0.05);
            break;
        }
}

// Without a caller that wants whole images the replay reads back only the final picture's box,
// and once per set of groups shown: the same figures as the whole-screen replay, sample by sample.
TEST(Engine, TheBoxReplayMeasuresWhatTheWholeScreenReplayDoes) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.sample_ray_factor = 1.05;  // many samples, some with no new group
    ProgressiveEngine engine(*ex, opt);
    const FrameView fv = make_view(p, 240, 180, kPhantomBoneIso, 30, 20);
    FrameResult box = draw_frame(engine, fv, *renderer);
    ASSERT_TRUE(box.completed);
    FrameResult whole = box;
    measure_frame(box, fv, *renderer);
    std::size_t images = 0;
    measure_frame(whole, fv, *renderer, [&](const TimelineSample&, const Image& img) {
        EXPECT_EQ(img.width, fv.width);
        ++images;
    });
    EXPECT_EQ(images, whole.timeline.size());
    std::size_t repeats = 0;
    for (std::size_t i = 0; i < box.timeline.size(); ++i) {
        EXPECT_EQ(box.timeline[i].correctness.c, whole.timeline[i].correctness.c) << i;
        EXPECT_EQ(box.timeline[i].correctness.final_pixels,
                  whole.timeline[i].correctness.final_pixels)
            << i;
        EXPECT_EQ(box.timeline[i].correctness.significant,
                  whole.timeline[i].correctness.significant);
        repeats += i > 0 && box.timeline[i].groups == box.timeline[i - 1].groups;
    }
    EXPECT_GT(repeats, 0u) << "no sample showed the groups of the one before: the case is weak";
    const PixelRect r = covered_box(box.final_image);
    EXPECT_LT(pixel_count(r), box.final_image.pixel_count()) << "the box is the whole screen";
    const Image part = crop(box.final_image, r);
    auto covered = [](const Image& img) {
        return std::count_if(img.depth.begin(), img.depth.end(), [](float d) { return d < 1; });
    };
    EXPECT_EQ(covered(part), covered(box.final_image));
    const PixelRect again = covered_box(part);
    EXPECT_EQ(again.x, 0);
    EXPECT_EQ(again.y, 0);
    EXPECT_EQ(again.width, r.width);
    EXPECT_EQ(again.height, r.height);
}

}  // namespace
}  // namespace isowall

namespace isowall {
namespace {

// The stages of a frame are named steps, each charged to its own trace span: the frame's set-up
// (the adaptive D[] table, clearing visited cells) is "setup", never another stage, and the
// engine alone never charges anything to communication or idle.
TEST(Engine, EveryStepOfAFrameIsChargedToItsOwnStage) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    for (bool adaptive : {false, true}) {
        TraceRecorder trace;
        EngineOptions opt;
        opt.adaptive = adaptive;
        opt.trace = &trace;
        ProgressiveEngine engine(*ex, opt);
        trace.switch_to(Stage::idle);  // what a tile was doing before the view arrived
        const std::size_t first = trace.spans().size();  // the idle span, once closed
        const FrameResult fr =
            draw_frame(engine, test::make_view(p, 160, 120, kPhantomSkinIso), *renderer);
        ASSERT_TRUE(fr.completed);
        trace.close();
        const auto& spans = trace.spans();
        ASSERT_GE(spans.size(), first + 3);
        EXPECT_EQ(spans[first].stage, std::uint8_t(Stage::idle)) << "adaptive " << adaptive;
        EXPECT_EQ(spans[first + 1].stage, std::uint8_t(Stage::setup)) << "adaptive " << adaptive;
        std::set<std::uint8_t> seen;
        for (std::size_t i = first + 1; i < spans.size(); ++i) seen.insert(spans[i].stage);
        for (Stage s : {Stage::intersection, Stage::propagation, Stage::render})
            EXPECT_TRUE(seen.count(std::uint8_t(s)))
                << kTraceStages[int(s)] << ", adaptive " << adaptive;
        for (Stage s : {Stage::comm, Stage::idle, Stage::compose})
            EXPECT_FALSE(seen.count(std::uint8_t(s)))
                << kTraceStages[int(s)] << ", adaptive " << adaptive;
    }
}

}  // namespace
}  // namespace isowall
