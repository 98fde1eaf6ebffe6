// The screen mask in the engine ("empty space costs nothing"): the final image is the
// one without the mask, pixel for pixel, in every view, intersection mode, ray order and
// resolution; it never casts more rays; a region whose frustum holds no active node casts none;
// and the active nodes it projects hold every triangle of the surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <string>
#include <vector>

#include "app/whole_frame.h"
#include "core/ray.h"
#include "engine/progressive_engine.h"
#include "render/renderer_sink.h"
#include "tests/engine_util.h"
#include "tests/test_util.h"
#include "volume/phantom.h"
#include "volume/volume.h"

namespace isowall {
namespace {

struct NamedView {
    std::string name;
    FrameView view;
};

// Front, turned, zoomed in until the volume fills the screen, and orthographic.
std::vector<NamedView> views(const Volume& v, int w, int h, double iso) {
    std::vector<NamedView> out{{"front", test::make_view(v, w, h, iso)},
                               {"turned", test::make_view(v, w, h, iso, 40, 25)},
                               {"zoomed_in", test::make_view(v, w, h, iso, -20, 10, 3.0f)}};
    FrameView ortho = out[0].view;
    ortho.camera = fit_depth_range(
        orbit(front_full_view(v.bounds(), float(w) / float(h), Projection::orthographic), 30, -15),
        v.bounds());
    ortho.frustum = ortho.camera.frustum(float(w) / float(h));
    out.push_back({"orthographic", ortho});
    return out;
}

FrameResult run_engine(SurfaceExtractor& ex, Renderer& r, EngineOptions opt, const FrameView& fv,
                       bool mask) {
    opt.screen_mask = mask;
    ProgressiveEngine engine(ex, opt);
    return draw_frame(engine, fv, r);
}

// With and without the mask: the same final colour and depth, and no more rays with it.
void expect_mask_changes_nothing_but_rays(SurfaceExtractor& ex, Renderer& r,
                                          const EngineOptions& opt, const FrameView& fv) {
    const FrameResult with = run_engine(ex, r, opt, fv, true);
    const FrameResult without = run_engine(ex, r, opt, fv, false);
    ASSERT_TRUE(with.completed && without.completed);
    EXPECT_LE(with.rays_cast, without.rays_cast);
    EXPECT_GE(with.mask_level, 0);
    EXPECT_EQ(without.mask_level, -1);
    ASSERT_EQ(with.final_image.width, without.final_image.width);
    std::size_t colour = 0, depth = 0;
    for (std::size_t i = 0; i < with.final_image.rgba.size(); ++i)
        colour += with.final_image.rgba[i] != without.final_image.rgba[i];
    for (std::size_t i = 0; i < with.final_image.depth.size(); ++i)
        depth += with.final_image.depth[i] != without.final_image.depth[i];
    EXPECT_EQ(colour, 0u) << "colour channels differ; rays " << with.rays_cast << " vs "
                          << without.rays_cast;
    EXPECT_EQ(depth, 0u) << "depths differ";
}

void expect_identical_images(const Volume& v, double iso, int w, int h) {
    auto ex = make_surface_extractor(v);
    auto renderer = make_renderer("osmesa");
    for (const NamedView& nv : views(v, w, h, iso))
        for (IntersectMode mode : {IntersectMode::exact, IntersectMode::approximate})
            for (RayOrderKind order : {RayOrderKind::refining_grid, RayOrderKind::screen_readback,
                                       RayOrderKind::dynamic_grid}) {
                EngineOptions opt;
                opt.intersect = mode;
                opt.order = order;
                SCOPED_TRACE(nv.name + " " + std::string(to_string(order)) +
                             (mode == IntersectMode::exact ? " exact" : " approximate"));
                expect_mask_changes_nothing_but_rays(*ex, *renderer, opt, nv.view);
            }
}

TEST(ScreenMaskEngine, PhantomImagesAreTheSameWithAndWithoutTheMask) {
    const Volume p = make_phantom();
    for (double iso : {kPhantomSkinIso, kPhantomBoneIso}) expect_identical_images(p, iso, 160, 120);
}

TEST(ScreenMaskEngine, SharedToothImagesAreTheSameWithAndWithoutTheMask) {
    const auto data = test::shared_data_dir();
    if (!data) GTEST_SKIP() << "../shared/data is absent: skipping the tooth";
    const Volume v = load_nrrd(*data / "tooth.nhdr");
    expect_identical_images(v, 620, 160, 120);
}

// Meta-cells reach past the cells the octree's finest levels test: adaptive resolution far away
// and every uniform level of remote viewing keep the image too.
TEST(ScreenMaskEngine, MetaCellsKeepTheImage) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    FrameView far = test::make_view(p, 160, 120, kPhantomBoneIso, 20, 10, 0.25f);
    for (int level = 0; level <= kMaxMetaLevel; ++level) {
        EngineOptions opt;
        opt.adaptive = level == 0;
        opt.uniform_level = level;
        SCOPED_TRACE("uniform level " + std::to_string(level) + (level == 0 ? " (adaptive)" : ""));
        expect_mask_changes_nothing_but_rays(*ex, *renderer, opt, far);
    }
}

// A wall tile's region beside the surface, inside the volume's screen box: the box alone casts
// every pixel of it, the mask none, and the region is done at once.
TEST(ScreenMaskEngine, ARegionWithNoActiveNodeCastsNoRay) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    const std::atomic<bool> stop{false};
    for (const FrameView& fv : {test::make_view(p, 320, 240, kPhantomSkinIso),
                                test::make_view(p, 320, 240, kPhantomSkinIso, 30, 20)}) {
        const PixelRect box =
            screen_box(p.bounds(), fv.camera.view(), fv.frustum, fv.width, fv.height);
        const PixelRect corner{box.x, box.y, 12, 12};  // the box's corner: no skin there
        EngineOptions opt;
        for (bool mask : {false, true}) {
            opt.screen_mask = mask;
            ProgressiveEngine engine(*ex, opt);
            RendererSink sink(*renderer);
            const FrameResult fr = engine.run(fv, corner, sink, stop);
            EXPECT_TRUE(fr.completed);
            if (mask) {
                EXPECT_EQ(fr.rays_cast, 0u) << fv;
                EXPECT_EQ(fr.group_count, 0u);
                EXPECT_EQ(fr.screen_pixels, 0u);
            } else {
                EXPECT_EQ(fr.rays_cast, 144u) << "the corner is inside the screen box";
            }
        }
        ProgressiveEngine engine(*ex);
        EngineFrame frame(engine, fv, stop);
        const RegionCursor c = frame.cursor(fv, corner);
        EXPECT_TRUE(c.done);
        EXPECT_EQ(c.pixels, 0u);
    }
}

TEST(ScreenMaskEngine, AnIsovalueAboveEveryVoxelCastsNoRay) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    auto renderer = make_renderer("osmesa");
    ProgressiveEngine engine(*ex);
    const FrameResult fr =
        draw_frame(engine, test::make_view(p, 160, 120, ex->value_max() + 1), *renderer);
    EXPECT_TRUE(fr.completed);
    EXPECT_EQ(fr.rays_cast, 0u);
    EXPECT_EQ(fr.mask_nodes, 0u);
}

// Every triangle of the full surface lies in an active node the mask projects; the level is the
// finest within the budget and never below the one asked for.
TEST(ScreenMaskEngine, ActiveNodesHoldTheWholeSurface) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    const Mesh m = ex->extract_full(kPhantomSkinIso);
    ASSERT_GT(m.positions.size(), 0u);
    for (std::size_t budget : {std::size_t(1), std::size_t(64), std::size_t(4096)})
        for (int finest : {0, 1, 3}) {
            const ActiveBoxes a = ex->active_boxes(kPhantomSkinIso, budget, finest);
            SCOPED_TRACE("budget " + std::to_string(budget) + " finest " + std::to_string(finest));
            EXPECT_GE(a.level, std::min(finest, ex->octree_shape().depth()));
            EXPECT_LE(a.boxes.size(), std::max<std::size_t>(budget, 1));
            for (std::size_t i = 0; i < m.positions.size(); i += 17) {
                const glm::vec3 q = m.positions[i];
                bool in = false;
                for (const Box3& b : a.boxes)
                    in = in || (glm::all(glm::greaterThanEqual(q, b.min - 1e-4f)) &&
                                glm::all(glm::lessThanEqual(q, b.max + 1e-4f)));
                ASSERT_TRUE(in) << "vertex (" << q.x << ", " << q.y << ", " << q.z
                                << ") outside every active node";
            }
        }
    EXPECT_EQ(ex->active_boxes(kPhantomSkinIso, 4096, 0).level, 1) << "the phantom's skin";
}

}  // namespace
}  // namespace isowall
