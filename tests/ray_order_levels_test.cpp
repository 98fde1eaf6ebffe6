// Ray-casting orders, the levels of each kind: the refining grid doubling, read-back putting
// uncovered pixels first, the dynamic grid sized from the first surface piece and refining on from
// there, and the surface piece size itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "progressive/ray_order.h"
#include "tests/ray_order_test_util.h"

namespace isowall {
namespace {

using namespace ray_order_testing;

TEST(RayOrder, RefiningLevelsDoubleTheGrid) {
    for (const ScreenCase& c : kCases) {
        auto order = make_ray_order(RayOrderKind::refining_grid, c.screen_w, c.screen_h, c.rect);
        EXPECT_FALSE(order->wants_coverage());
        const auto levels = run_order(*order, nullptr);
        ASSERT_FALSE(levels.empty()) << rect_str(c.rect);
        // Level 0: the one pixel at the centre of the rect.
        ASSERT_EQ(levels[0].size(), 1u) << rect_str(c.rect);
        EXPECT_EQ(levels[0][0],
                  glm::ivec2(c.rect.x + c.rect.width / 2, c.rect.y + c.rect.height / 2))
            << rect_str(c.rect);
        // Grid levels until a cell would be under 2 px on the larger side, then one fill level.
        const int max_side = std::max(c.rect.width, c.rect.height);
        int grid_levels = 1;
        while (max_side >= (4 << (grid_levels - 1))) ++grid_levels;
        const std::size_t area = std::size_t(c.rect.width) * c.rect.height;
        EXPECT_EQ(levels.size(), std::size_t(grid_levels) + (area > 1 ? 1 : 0)) << rect_str(c.rect);
        for (std::size_t k = 0; k < levels.size(); ++k) {
            if (int(k) < grid_levels) {
                EXPECT_LE(levels[k].size(), std::size_t(1) << (2 * k)) << rect_str(c.rect);
            }
            // Row-major within a level (by grid cell, which is row-major by pixel too).
            EXPECT_TRUE(std::is_sorted(
                levels[k].begin(), levels[k].end(),
                [](glm::ivec2 a, glm::ivec2 b) { return a.y != b.y ? a.y < b.y : a.x < b.x; }))
                << rect_str(c.rect) << " level " << k;
        }
    }
    // A 64x48 rect: the cell centres never coincide, so the levels are full quad-tree levels.
    auto order = make_ray_order(RayOrderKind::refining_grid, 64, 48, {0, 0, 64, 48});
    const auto levels = run_order(*order, nullptr);
    const std::vector<std::size_t> expected = {1, 4, 16, 64, 256, 1024, 64 * 48 - 1365};
    ASSERT_EQ(levels.size(), expected.size());
    for (std::size_t k = 0; k < levels.size(); ++k)
        EXPECT_EQ(levels[k].size(), expected[k]) << "level " << k;
    // Level 1 is the centres of the four quadrants.
    EXPECT_EQ(levels[1], (std::vector<glm::ivec2>{{16, 12}, {48, 12}, {16, 36}, {48, 36}}));
}

TEST(RayOrder, ReadbackPutsUncoveredPixelsFirst) {
    for (const ScreenCase& c : kCases) {
        DiskScene scene = scene_for(c.screen_w, c.screen_h, c.rect);
        auto readback =
            make_ray_order(RayOrderKind::screen_readback, c.screen_w, c.screen_h, c.rect);
        auto grid = make_ray_order(RayOrderKind::refining_grid, c.screen_w, c.screen_h, c.rect);
        EXPECT_FALSE(readback->wants_coverage()) << "nothing drawn before the first level";
        std::vector<glm::ivec2> rays, grid_rays;
        std::vector<std::uint8_t> covered;
        int covered_rays = 0;
        while (readback->next_level(rays)) {
            ASSERT_TRUE(grid->next_level(grid_rays)) << rect_str(c.rect);
            // The same pixels as the refining grid's level; uncovered first, each group stable.
            std::vector<glm::ivec2> expected;
            for (bool want_covered : {false, true})
                for (glm::ivec2 p : grid_rays) {
                    const bool is_covered =
                        !covered.empty() && covered[std::size_t(p.y) * c.screen_w + p.x] != 0;
                    if (is_covered == want_covered) expected.push_back(p);
                    covered_rays += is_covered && want_covered;
                }
            EXPECT_EQ(rays, expected) << rect_str(c.rect) << " level " << readback->level();
            scene.cast(rays);
            if (readback->wants_coverage()) {
                covered = scene.coverage();
                readback->set_coverage(covered);
            } else {
                EXPECT_FALSE(grid->next_level(grid_rays)) << "read-back stopped asking early";
            }
        }
        EXPECT_FALSE(grid->next_level(grid_rays)) << rect_str(c.rect);
        if (c.rect.width > 8) {
            EXPECT_GT(covered_rays, 0) << rect_str(c.rect) << ": the test saw no ordering";
        }
    }
}

// Runs a dynamic grid on one disk at the screen centre; returns the dynamic level's pixels and
// checks it against the coverage that sized it.
std::vector<glm::ivec2> dynamic_level_for_disk(int w, int h, double radius) {
    DiskScene scene(w, h, {{w * 0.5, h * 0.5, radius}});
    auto order = make_ray_order(RayOrderKind::dynamic_grid, w, h, {0, 0, w, h});
    std::vector<glm::ivec2> rays;
    EXPECT_TRUE(order->next_level(rays));
    scene.cast(rays);
    EXPECT_TRUE(order->wants_coverage()) << "searching for the first surface piece";
    const std::vector<std::uint8_t> covered = scene.coverage();
    order->set_coverage(covered);
    EXPECT_FALSE(order->wants_coverage()) << "the surface has been sized";
    EXPECT_TRUE(order->next_level(rays));
    for (glm::ivec2 p : rays)
        EXPECT_EQ(covered[std::size_t(p.y) * w + p.x], 0) << "a ray on drawn surface " << p.x;
    return rays;
}

TEST(RayOrder, DynamicGridSpacingFollowsTheDiskSize) {
    for (double radius : {10.0, 30.0, 60.0}) {
        const std::vector<glm::ivec2> rays = dynamic_level_for_disk(400, 300, radius);
        // Spacing between neighbouring grid columns (the last, clipped column aside).
        std::vector<int> xs;
        for (glm::ivec2 p : rays) xs.push_back(p.x);
        std::sort(xs.begin(), xs.end());
        xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
        ASSERT_GE(xs.size(), 3u) << "radius " << radius;
        std::vector<int> gaps;
        for (std::size_t i = 1; i + 1 < xs.size(); ++i) gaps.push_back(xs[i] - xs[i - 1]);
        std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
        const double expected = std::sqrt(std::numbers::pi) * radius / 2;
        EXPECT_NEAR(gaps[gaps.size() / 2], expected, 1.5) << "radius " << radius;
        // One ray per cell, less those on the drawn disk.
        const double cells = std::ceil(400 / expected) * std::ceil(300 / expected);
        EXPECT_LE(double(rays.size()), cells * 1.15) << "radius " << radius;
        EXPECT_GE(double(rays.size()),
                  cells * 0.7 - std::numbers::pi * radius * radius / (expected * expected))
            << "radius " << radius;
    }
}

TEST(RayOrder, DynamicGridContinuesWithFinerRefiningLevels) {
    // Disk radius 30: size ~53 px, so refining goes on with cells under ~26.6 px: 400 / 2^4.
    const int w = 400, h = 300;
    DiskScene scene(w, h, {{w * 0.5, h * 0.5, 30.0}, {40, 40, 12.0}});
    auto order = make_ray_order(RayOrderKind::dynamic_grid, w, h, {0, 0, w, h});
    const auto levels = run_order(*order, &scene);
    ASSERT_GE(levels.size(), 4u);
    auto grid = make_ray_order(RayOrderKind::refining_grid, w, h, {0, 0, w, h});
    std::vector<std::vector<glm::ivec2>> grid_levels;
    for (std::vector<glm::ivec2> r; grid->next_level(r);) grid_levels.push_back(r);
    // levels: 0 = centre (hits the disk), 1 = dynamic grid, 2 = refining level 4, ...
    EXPECT_EQ(levels[0], grid_levels[0]);
    // The last two levels are the fill level's two parts (DynamicFillLevel... below).
    for (std::size_t k = 2; k + 2 < levels.size(); ++k) {
        std::vector<glm::ivec2> sorted = levels[k];
        std::sort(sorted.begin(), sorted.end(),
                  [](glm::ivec2 a, glm::ivec2 b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
        const auto& refining = grid_levels[k + 2];
        EXPECT_TRUE(std::includes(
            refining.begin(), refining.end(), sorted.begin(), sorted.end(),
            [](glm::ivec2 a, glm::ivec2 b) { return a.y != b.y ? a.y < b.y : a.x < b.x; }))
            << "level " << k << " is not inside refining level " << k + 2;
    }
    EXPECT_EQ(levels.size(), grid_levels.size() - 3 + 1 + 1)
        << "levels 1-3 replaced by one grid, and the fill level in two parts";
}

TEST(RayOrder, GapsOrderCastsTheGapsThenFinerRefiningLevels) {
    // Disk radius 30: size ~53 px, so refining goes on with cells under ~26.6 px: 400 / 2^4.
    const int w = 400, h = 300;
    DiskScene scene(w, h, {{w * 0.5, h * 0.5, 30.0}, {40, 40, 12.0}});
    auto order = make_ray_order(RayOrderKind::dynamic_gaps, w, h, {0, 0, w, h});
    std::vector<std::uint8_t> after_grid;  // what shows once the sized grid is cast
    std::vector<std::vector<glm::ivec2>> levels;
    for (std::vector<glm::ivec2> rays;;) {
        if (order->wants_coverage()) order->set_coverage(scene.coverage());
        if (!order->next_level(rays)) break;
        scene.cast(rays);
        levels.push_back(rays);
        if (levels.size() == 2) after_grid = scene.coverage();
    }
    ASSERT_GE(levels.size(), 4u);
    auto grid = make_ray_order(RayOrderKind::refining_grid, w, h, {0, 0, w, h});
    std::vector<std::vector<glm::ivec2>> grid_levels;
    for (std::vector<glm::ivec2> r; grid->next_level(r);) grid_levels.push_back(r);
    // levels: 0 = centre (hits the disk), 1 = dynamic grid, 2 = the gaps, 3 = refining level 4...
    EXPECT_EQ(levels[0], grid_levels[0]);
    // The gaps: every pixel not cast yet that showed nothing after the grid, each once, the
    // refining grids' coarser points first.
    std::vector<std::uint8_t> gaps = after_grid;  // 0: a gap not cast yet
    for (std::size_t k = 0; k < 2; ++k)
        for (glm::ivec2 p : levels[k]) gaps[std::size_t(p.y) * w + p.x] = 1;
    EXPECT_EQ(levels[2].size(), std::size_t(std::count(gaps.begin(), gaps.end(), 0)));
    for (glm::ivec2 p : levels[2]) EXPECT_EQ(after_grid[std::size_t(p.y) * w + p.x], 0);
    EXPECT_EQ(levels[2].front(), grid_levels[4].front());
    // Then the refining levels, on what showed the surface only.
    for (std::size_t k = 3; k + 1 < levels.size(); ++k) {
        std::vector<glm::ivec2> sorted = levels[k];
        std::sort(sorted.begin(), sorted.end(),
                  [](glm::ivec2 a, glm::ivec2 b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
        const auto& refining = grid_levels[k + 1];
        EXPECT_TRUE(std::includes(
            refining.begin(), refining.end(), sorted.begin(), sorted.end(),
            [](glm::ivec2 a, glm::ivec2 b) { return a.y != b.y ? a.y < b.y : a.x < b.x; }))
            << "level " << k << " is not inside refining level " << k + 1;
        for (glm::ivec2 p : levels[k]) EXPECT_NE(after_grid[std::size_t(p.y) * w + p.x], 0);
    }
    std::size_t total = 0;
    for (const auto& l : levels) total += l.size();
    EXPECT_EQ(total, std::size_t(w) * h);  // every pixel once
}

TEST(RayOrder, DynamicFillLevelHandsOutWhatShowsNothingFirst) {
    // Before the fill level (every pixel left) the dynamic orders ask once more what shows, and
    // the fill level comes in two: the pixels that showed nothing, then (after one more ask) the
    // others. C = 1 - E counts a missing pixel as wholly wrong, so the last holes, not the pixels
    // already drawn, decide it.
    const int w = 400, h = 300;
    // (The gaps order hands out every pixel that shows nothing before its refining levels, so
    // its fill level has only the second part.)
    for (RayOrderKind kind : {RayOrderKind::dynamic_grid}) {
        DiskScene scene(w, h, {{w * 0.5, h * 0.5, 30.0}, {40, 40, 12.0}, {300, 200, 50.0}});
        auto order = make_ray_order(kind, w, h, {0, 0, w, h});
        std::vector<std::vector<std::uint8_t>> given;  // the coverage given before each level
        std::vector<std::vector<glm::ivec2>> levels;
        std::size_t total = 0;
        for (std::vector<glm::ivec2> rays;;) {
            const bool asks = order->wants_coverage();
            if (asks) order->set_coverage(scene.coverage());
            if (!order->next_level(rays)) break;
            given.push_back(asks ? scene.coverage() : std::vector<std::uint8_t>{});
            levels.push_back(rays);
            total += rays.size();
            scene.cast(rays);
        }
        EXPECT_EQ(total, std::size_t(w) * h) << to_string(kind) << ": every pixel once";
        ASSERT_GE(levels.size(), 3u);
        const std::size_t first = levels.size() - 2, second = levels.size() - 1;
        ASSERT_FALSE(given[first].empty()) << to_string(kind) << ": no ask before the fill level";
        ASSERT_FALSE(given[second].empty()) << to_string(kind) << ": no ask between its parts";
        auto shows = [&](std::size_t k, glm::ivec2 p) {
            return given[k][std::size_t(p.y) * w + p.x] != 0;
        };
        for (glm::ivec2 p : levels[first]) ASSERT_FALSE(shows(first, p)) << to_string(kind);
        for (glm::ivec2 p : levels[second]) ASSERT_TRUE(shows(first, p)) << to_string(kind);
        EXPECT_FALSE(levels[first].empty());
        EXPECT_FALSE(levels[second].empty());
    }
}

TEST(RayOrder, DynamicGridWithoutSurfaceIsTheRefiningGrid) {
    const PixelRect r{10, 5, 120, 70};
    auto dynamic = make_ray_order(RayOrderKind::dynamic_grid, 200, 100, r);
    auto grid = make_ray_order(RayOrderKind::refining_grid, 200, 100, r);
    // Surface outside the rect does not count.
    std::vector<std::uint8_t> covered(200 * 100, 0);
    for (int y = 0; y < 100; ++y) covered[std::size_t(y) * 200 + 150] = 1;
    std::vector<glm::ivec2> a, b;
    while (true) {
        if (dynamic->wants_coverage()) dynamic->set_coverage(covered);
        const bool more = dynamic->next_level(a);
        ASSERT_EQ(more, grid->next_level(b));
        if (!more) break;
        EXPECT_EQ(a, b) << "level " << dynamic->level();
    }
}

TEST(RayOrder, SurfacePieceSize) {
    const int w = 200, h = 150;
    std::vector<std::uint8_t> covered(std::size_t(w) * h, 0);
    EXPECT_EQ(surface_piece_size(covered, w, {0, 0, w, h}), 0.0);
    EXPECT_EQ(surface_piece_size(covered, w, {0, 0, 0, 0}), 0.0);
    covered[std::size_t(70) * w + 100] = 1;  // one pixel: clamped up to 4
    EXPECT_EQ(surface_piece_size(covered, w, {0, 0, w, h}), 4.0);
    EXPECT_EQ(surface_piece_size(covered, w, {0, 0, 3, 2}), 0.0) << "outside the rect";
    // Two squares; the first in row-major order is the 10x10 one. A diagonal neighbour is not
    // 4-connected.
    std::fill(covered.begin(), covered.end(), 0);
    for (int y = 20; y < 30; ++y)
        for (int x = 150; x < 160; ++x) covered[std::size_t(y) * w + x] = 1;
    for (int y = 50; y < 90; ++y)
        for (int x = 10; x < 50; ++x) covered[std::size_t(y) * w + x] = 1;
    covered[std::size_t(30) * w + 160] = 1;
    EXPECT_DOUBLE_EQ(surface_piece_size(covered, w, {0, 0, w, h}), 10.0);
    // Only the part inside the rect counts: the big square from row 60 is 40x30.
    EXPECT_DOUBLE_EQ(surface_piece_size(covered, w, {0, 60, 100, 90}), std::sqrt(1200.0));
    // The floor of 4 gives way to the rect's larger side when the rect is smaller than that.
    EXPECT_DOUBLE_EQ(surface_piece_size(covered, w, {10, 50, 3, 2}), 3.0);
    EXPECT_THROW(surface_piece_size(covered, w, {0, 0, w, h + 1}), std::invalid_argument);
}

}  // namespace
}  // namespace isowall
