// The fidelity gate on the engine's defaults: the final image is at least as close to the truth
// (the full surface at 4x4 samples per pixel, box-filtered: what a pixel can show) as the full
// surface drawn at one sample per pixel is, within the gate's margins, on the phantom and on the
// thin-structure volume (tubes and a sheet thinner than a cell), in every ray order.
#include <gtest/gtest.h>

#include <iostream>

#include "app/whole_frame.h"
#include "engine/progressive_engine.h"
#include "extract/surface_extractor.h"
#include "progressive/correctness.h"
#include "render/renderer.h"
#include "tests/engine_util.h"
#include "tests/thin_structures.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

struct GateFigures {
    Fidelity engine, full;
};

GateFigures judge(const Volume& v, const FrameView& fv, const EngineOptions& opt) {
    auto ex = make_surface_extractor(v, {}, nullptr, ThreadBudget{opt.threads});
    auto renderer = make_renderer("osmesa");
    const FrameResult fr = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer);
    EXPECT_TRUE(fr.completed);
    const Mesh mesh = ex->extract_full(fv.iso);
    const Image truth = draw_truth(*renderer, mesh, fv);
    GateFigures g{measure_fidelity(fr.final_image, truth),
                  measure_fidelity(draw_alone(*renderer, mesh, fv), truth)};
    std::cout << "  " << to_string(opt.order) << ": engine C_T " << g.engine.c << " IoU "
              << g.engine.iou << " | full C_T " << g.full.c << " IoU " << g.full.iou << "\n";
    return g;
}

class FidelityGate : public testing::TestWithParam<RayOrderKind> {};

TEST_P(FidelityGate, TheDefaultEngineOnThePhantomPassesAgainstItsTruth) {
    const Volume v = make_phantom();
    EngineOptions opt;
    opt.order = GetParam();
    const GateFigures g = judge(v, test::make_view(v, 200, 150, 50.0, 20, 10), opt);
    EXPECT_TRUE(passes_fidelity_gate(g.engine, g.full));
    EXPECT_GT(g.full.c, 0.8);  // the truth is the same picture, not another one
}

TEST_P(FidelityGate, TheDefaultEngineOnThinStructuresPassesAgainstItsTruth) {
    const Volume v = test::make_thin_structures(64);
    EngineOptions opt;
    opt.order = GetParam();
    const GateFigures g = judge(v, test::make_view(v, 160, 120, test::kThinIso), opt);
    EXPECT_TRUE(passes_fidelity_gate(g.engine, g.full));
    EXPECT_GT(g.full.c, 0.8);
}

INSTANTIATE_TEST_SUITE_P(EveryOrder, FidelityGate,
                         testing::Values(RayOrderKind::refining_grid, RayOrderKind::screen_readback,
                                         RayOrderKind::dynamic_grid, RayOrderKind::dynamic_gaps),
                         [](const auto& info) { return std::string(to_string(info.param)); });

// A picture that is not the surface's fails the gate: the gate can fail.
TEST(FidelityGate, AnEmptyFinalImageFails) {
    const Volume v = make_phantom();
    const FrameView fv = test::make_view(v, 120, 90, 50.0);
    auto ex = make_surface_extractor(v, {}, nullptr, ThreadBudget{1});
    auto renderer = make_renderer("osmesa");
    const Mesh mesh = ex->extract_full(fv.iso);
    const Image truth = draw_truth(*renderer, mesh, fv);
    Image empty;
    empty.resize(fv.width, fv.height);
    EXPECT_FALSE(passes_fidelity_gate(measure_fidelity(empty, truth),
                                      measure_fidelity(draw_alone(*renderer, mesh, fv), truth)));
}

}  // namespace
}  // namespace isowall
