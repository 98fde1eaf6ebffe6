// Footprint units in the engine: where cells project below a pixel the default engine propagates
// over units of about a pixel and draws, at each pixel centre, the full-resolution surface its ray
// meets, so its final image is the one every full-resolution triangle gives, on one thread or
// two, with the frame cutting through units or not, and with fewer triangles.
#include <gtest/gtest.h>

#include <iostream>
#include <set>
#include <tuple>

#include "app/whole_frame.h"
#include "engine/progressive_engine.h"
#include "extract/footprint.h"
#include "extract/surface_extractor.h"
#include "render/renderer.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "tests/thin_structures.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

struct Outcome {
    FrameResult frame;
    Image full;
    std::size_t full_triangles = 0;
    std::size_t footprint_units = 0;  // units of a level above 0 the passes took
};

Outcome run(const Volume& v, const FrameView& fv, EngineOptions opt) {
    auto ex = make_surface_extractor(v, {}, nullptr, ThreadBudget{opt.threads});
    auto renderer = make_renderer("osmesa");
    Outcome o;
    o.frame = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer);
    for (const Group& g : o.frame.groups)
        for (std::size_t i = 0; i < g.cells.size(); ++i)
            o.footprint_units += g.level_of_cell(i) > 0 ? 1 : 0;
    const Mesh mesh = ex->extract_full(fv.iso);
    o.full_triangles = mesh.triangle_count();
    o.full = draw_alone(*renderer, mesh, fv);
    return o;
}

// What the footprint engine's image may differ from every triangle's by: ties on the shared
// edges of triangles, which a ray and the rasteriser break differently (a pixel or two).
void expect_the_full_picture(const Outcome& o, const char* what) {
    ASSERT_TRUE(o.frame.completed);
    const test::ImageComparison c = test::compare_images(o.frame.final_image, o.full);
    std::cout << "  " << what << ": " << o.footprint_units << " footprint units, "
              << o.frame.triangles_drawn << " triangles drawn against " << o.full_triangles
              << " of the full surface; " << c << "\n";
    EXPECT_GT(c.mask_iou, 0.999);
    EXPECT_LT(c.differing_share(), 0.001);
}

TEST(FootprintEngine, ThePhantomSmallerThanItsCellsShowsEveryTriangleWithFewer) {
    const Volume v = make_phantom();
    // 200 x 184 x 168 cells on 120 x 90 pixels: about two cells a pixel.
    const FrameView fv = test::make_view(v, 120, 90, kPhantomSkinIso, 20, 10);
    const Outcome o = run(v, fv, EngineOptions{});
    EXPECT_GT(o.footprint_units, 1000u);
    expect_the_full_picture(o, "phantom");
    EXPECT_LT(o.frame.triangles_drawn * 4, o.full_triangles);
}

TEST(FootprintEngine, OffTheEngineWalksCellsAlone) {
    const Volume v = make_phantom();
    const FrameView fv = test::make_view(v, 120, 90, kPhantomSkinIso, 20, 10);
    EngineOptions opt;
    opt.footprint_pixels = 0;
    const Outcome o = run(v, fv, opt);
    EXPECT_EQ(o.footprint_units, 0u);
    expect_the_full_picture(o, "cells");
}

TEST(FootprintEngine, UnitsTheFrameCutsThroughShowTheirTriangles) {
    const Volume v = make_phantom();
    // Zoomed in: the frame's edges cut through the surface's units.
    const FrameView fv = test::make_view(v, 80, 60, kPhantomSkinIso, 35, -15, 2.5f);
    const Outcome o = run(v, fv, EngineOptions{});
    EXPECT_GT(o.footprint_units, 100u);
    expect_the_full_picture(o, "zoomed");
}

TEST(FootprintEngine, ThinStructuresBelowAPixelStayWhole) {
    const Volume v = test::make_thin_structures(64);
    // 64^3 on 40 x 30 pixels: tubes and a sheet thinner than a cell, cells well below a pixel.
    const FrameView fv = test::make_view(v, 40, 30, test::kThinIso);
    const Outcome o = run(v, fv, EngineOptions{});
    EXPECT_GT(o.footprint_units, 0u);
    expect_the_full_picture(o, "thin");
}

// Every unit a pass takes holds the full-resolution surface (it was entered across a crossed face,
// or seeded by a ray's hit in it) and belongs to one group alone.
TEST(FootprintEngine, UnitsHoldSurfaceEachInOneGroup) {
    const Volume v = make_phantom();
    auto ex = make_surface_extractor(v);
    auto renderer = make_renderer("osmesa");
    EngineOptions opt;
    opt.propagation.max_count = 200;  // many groups
    const FrameView fv = test::make_view(v, 120, 90, kPhantomBoneIso, 30, 20);
    const FrameResult fr = draw_frame(ProgressiveEngine(*ex, opt), fv, *renderer);
    ASSERT_TRUE(fr.completed);
    const auto view = v.view<std::uint8_t>();
    const InsideTest<std::uint8_t> inside(fv.iso);
    std::set<std::tuple<int, int, int, int>> seen;
    std::size_t units = 0, empty = 0, twice = 0, wrong_group = 0;
    for (const Group& g : fr.groups)
        for (std::size_t i = 0; i < g.cells.size(); ++i) {
            const int level = g.level_of_cell(i);
            const glm::ivec3 c = g.cells[i];
            if (level > 0) {
                ++units;
                empty += !UnitBlock<std::uint8_t>(view, c, level, inside).straddles();
            }
            twice += !seen.insert({c.x, c.y, c.z, level}).second;
            wrong_group += ex->group_of(c) != g.id;
        }
    std::cout << "  " << units << " footprint units in " << fr.groups.size() << " groups\n";
    EXPECT_GT(units, 500u);
    EXPECT_EQ(empty, 0u);
    EXPECT_EQ(twice, 0u);
    EXPECT_EQ(wrong_group, 0u);
}

TEST(FootprintEngine, TwoThreadsEndOnTheImageOfOne) {
    const Volume v = make_phantom();
    const FrameView fv = test::make_view(v, 120, 90, kPhantomBoneIso, -30, 20);
    EngineOptions one, two;
    two.threads = 2;
    const Outcome a = run(v, fv, one), b = run(v, fv, two);
    ASSERT_TRUE(a.frame.completed && b.frame.completed);
    EXPECT_GT(a.footprint_units, 0u);
    const test::ImageComparison c = test::compare_images(a.frame.final_image, b.frame.final_image);
    std::cout << "  one thread against two: " << c << "\n";
    EXPECT_EQ(c.differing_pixels, 0u);
    EXPECT_EQ(c.mask_iou, 1.0);
}

}  // namespace
}  // namespace isowall
