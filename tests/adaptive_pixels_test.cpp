// Adaptive resolution with a pixel target (--adaptive-pixels): D scales with the target,
// and a target above a pixel takes coarser units, fewer triangles and keeps the image within the
// far view's bound (adaptive_test.cpp) of the full surface at full resolution.
#include <gtest/gtest.h>

#include <iostream>
#include <limits>

#include "app/whole_frame.h"
#include "engine/progressive_engine.h"
#include "extract/adaptive.h"
#include "progressive/correctness.h"
#include "tests/engine_util.h"
#include "volume/phantom.h"
#include "volume/volume.h"

namespace isowall {
namespace {

TEST(AdaptivePixels, ATargetScalesTheDistances) {
    // D[i] is where a meta-cell projects to `pixels` pixels: twice the target, half the distance.
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 320, 240, kPhantomSkinIso, 0, 0, 1.0f);
    const ResolutionLevels one = resolution_levels(fv.camera, fv.frustum, fv.height, p.spacing());
    const ResolutionLevels two =
        resolution_levels(fv.camera, fv.frustum, fv.height, p.spacing(), kMaxMetaLevel, 2.0f);
    for (std::size_t i = 0; i < one.d.size(); ++i)
        EXPECT_NEAR(two.d[i], one.d[i] / 2, 1e-4f * one.d[i]) << "level " << i;
    // No target (0 or below) is full resolution, as no pixels are.
    for (const float d :
         resolution_levels(fv.camera, fv.frustum, fv.height, p.spacing(), kMaxMetaLevel, 0.0f).d)
        EXPECT_EQ(d, std::numeric_limits<float>::infinity());
    // Orthographic: one pixel is frustum height / height units, the same for every distance.
    Camera ortho = fv.camera;
    ortho.projection = Projection::orthographic;
    const Frustum f = ortho.frustum(4.0f / 3.0f);
    const float px = f.height() / 240.0f;
    const glm::vec3 unit(px * 0.9f);  // a cell is 0.9 px: level 1 is 1.8 px, level 2 is 3.6 px
    const ResolutionLevels o2 = resolution_levels(ortho, f, 240, unit, kMaxMetaLevel, 2.0f);
    EXPECT_EQ(o2.level_at(1.0f), 1) << o2;
    const ResolutionLevels o4 = resolution_levels(ortho, f, 240, unit, kMaxMetaLevel, 4.0f);
    EXPECT_EQ(o4.level_at(1.0f), 2) << o4;
}

struct FrameFigures {
    double c = 0;  // final image against the full surface at full resolution
    std::size_t triangles = 0, coarse_units = 0, refinements = 0;
};

FrameFigures run_frame(const Volume& volume, const FrameView& fv, float pixels, bool refine) {
    auto ex = make_surface_extractor(volume);
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.adaptive = true;
    opt.adaptive_pixels = pixels;
    opt.adaptive_refine = refine;
    const FrameResult fr = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer);
    EXPECT_TRUE(fr.completed);
    FrameFigures r;
    for (const Group& g : fr.groups) {
        r.triangles += g.mesh.triangle_count();
        r.refinements += g.refinement;
        if (!g.refinement)
            for (std::size_t i = 0; i < g.cells.size(); ++i)
                r.coarse_units += g.level_of_cell(i) > 0;
    }
    r.c = measure_correctness(fr.final_image, test::full_surface_image(*ex, *renderer, fv)).c;
    std::cout << "  " << pixels << " px" << (refine ? "" : ", unrefined") << ": C " << r.c << ", "
              << r.triangles << " triangles, " << r.coarse_units << " meta-cells, " << r.refinements
              << " refinements\n";
    return r;
}

TEST(AdaptivePixels, ALargerTargetTakesCoarserUnitsAndKeepsTheImage) {
    // The front view at 240 x 180 is full resolution under the text's rule (adaptive_test.cpp).
    // With a target of 2.5 px the phantom's cells (about 1.2 px) are taken two by two by two:
    // under half the triangles, the image within the far view's bound.
    const Volume p = make_phantom();
    const FrameView fv = test::make_view(p, 240, 180, kPhantomSkinIso, 0, 0, 1.0f);
    std::cout << "front view 240x180:\n";
    const FrameFigures one = run_frame(p, fv, 1.0f, true);
    const FrameFigures refined = run_frame(p, fv, 2.5f, true);
    const FrameFigures unrefined = run_frame(p, fv, 2.5f, false);
    EXPECT_EQ(one.coarse_units, 0u);
    EXPECT_GT(refined.coarse_units, 0u);
    EXPECT_LT(unrefined.triangles * 2, one.triangles);
    EXPECT_EQ(unrefined.refinements, 0u);
    EXPECT_GE(refined.c, 0.95);
    EXPECT_GE(unrefined.c, 0.95);
}

}  // namespace
}  // namespace isowall
