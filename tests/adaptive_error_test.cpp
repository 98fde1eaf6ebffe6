// The error rule of adaptive resolution: a meta-cell is drawn coarse only where its
// surface lies within a fraction of a pixel of the full-resolution surface. On a volume of tubes
// and a sheet thinner than a cell (thin_structures.h), the size rule alone loses them; with the
// error rule the final image is the full-resolution surface's, and the smooth ball is still
// drawn from meta-cells.
#include <gtest/gtest.h>

#include <iostream>
#include <limits>

#include "app/whole_frame.h"
#include "engine/progressive_engine.h"
#include "progressive/correctness.h"
#include "tests/engine_util.h"
#include "tests/thin_structures.h"

namespace isowall {
namespace {

struct ErrorFigures {
    double c = 0;  // final image against the full surface at full resolution
    std::size_t triangles = 0, coarse_units = 0;
};

ErrorFigures run_at_error(const Volume& volume, const FrameView& fv, float error_px,
                          int threads = 1) {
    auto ex = make_surface_extractor(volume, {}, nullptr, ThreadBudget{threads});
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.adaptive = true;
    opt.adaptive_pixels = 4.0f;
    opt.adaptive_refine = false;  // the rules alone
    opt.adaptive_error_px = error_px;
    opt.threads = threads;
    const FrameResult fr = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer);
    EXPECT_TRUE(fr.completed);
    ErrorFigures f;
    for (const Group& g : fr.groups) {
        f.triangles += g.mesh.triangle_count();
        for (std::size_t i = 0; i < g.cells.size(); ++i) f.coarse_units += g.level_of_cell(i) > 0;
    }
    f.c = measure_correctness(fr.final_image, test::full_surface_image(*ex, *renderer, fv)).c;
    std::cout << "  error " << error_px << " px, " << threads << " thread(s): C " << f.c << ", "
              << f.triangles << " triangles, " << f.coarse_units << " meta-cells\n";
    return f;
}

TEST(AdaptiveError, ThinStructuresStayWhereTheSizeRuleAloneLosesThem) {
    const Volume v = test::make_thin_structures();
    const FrameView fv = test::make_view(v, 200, 150, test::kThinIso);
    std::cout << "thin structures 96^3, 200x150, meta-cells up to 4 px:\n";
    const ErrorFigures size_only = run_at_error(v, fv, std::numeric_limits<float>::infinity());
    const ErrorFigures bounded = run_at_error(v, fv, 0.5f);
    EXPECT_LT(size_only.c, 0.97);  // tubes and sheet broken or gone
    EXPECT_GE(bounded.c, 0.99);
    EXPECT_GT(bounded.coarse_units, 0u);  // the ball's smooth surface still coarse
}

TEST(AdaptiveError, ThreadedRunsEndOnTheSameImage) {
    const Volume v = test::make_thin_structures(64);
    const FrameView fv = test::make_view(v, 160, 120, test::kThinIso);
    auto ex = make_surface_extractor(v, {}, nullptr, ThreadBudget{2});
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.adaptive = true;
    opt.adaptive_pixels = 4.0f;
    opt.adaptive_error_px = 0.5f;
    const Image one = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer).final_image;
    opt.threads = 2;
    for (int i = 0; i < 3; ++i) {
        const Image two = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer).final_image;
        EXPECT_EQ(measure_correctness(two, one).c, 1.0) << "run " << i;
    }
}

}  // namespace
}  // namespace isowall
