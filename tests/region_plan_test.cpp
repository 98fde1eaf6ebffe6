// Regions from the work (master/region_plan.h), alone: the work estimate of projected boxes, the
// k-d split, the correction by the last frame's measured costs, and the planner across frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "core/ray.h"
#include "master/region_plan.h"

namespace isowall {
namespace {

// Every pixel of the tile in exactly one region.
void expect_tiling(const std::vector<PixelRect>& regions, int width, int height) {
    std::vector<int> hits(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
    for (const PixelRect& r : regions) {
        ASSERT_GT(r.width, 0);
        ASSERT_GT(r.height, 0);
        ASSERT_GE(r.x, 0);
        ASSERT_GE(r.y, 0);
        ASSERT_LE(r.x + r.width, width);
        ASSERT_LE(r.y + r.height, height);
        for (int y = r.y; y < r.y + r.height; ++y)
            for (int x = r.x; x < r.x + r.width; ++x) ++hits[std::size_t(y) * width + x];
    }
    EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](int h) { return h == 1; }));
}

double area(const PixelRect& r) {
    return double(r.width) * double(r.height);
}

TEST(RegionPlan, RegionsTileTheScreenOnceForAnyWork) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
        const int w = 100 + int(rng() % 900), h = 80 + int(rng() % 700);
        WorkMap m(w, h);
        for (double& v : m.work) v = (rng() % 4 == 0) ? double(rng() % 1000) : 0.0;
        const double target = m.total() / double(1 + rng() % 40);
        const std::vector<PixelRect> regions = plan_regions(m, target);
        expect_tiling(regions, w, h);
        // A region over its target could not be split: too small on both sides.
        for (const PixelRect& r : regions)
            if (m.sum(r) > target) {
                EXPECT_TRUE(r.width < 2 * kMinRegionCells * WorkMap::kCell &&
                            r.height < 2 * kMinRegionCells * WorkMap::kCell)
                    << r.x << "," << r.y << " " << r.width << "x" << r.height;
            }
    }
}

TEST(RegionPlan, SmallRegionsWhereTheWorkIsAndOneLargeWhereNone) {
    // All the work in the top-left 128x128 pixels of a 1024x768 tile.
    WorkMap m(1024, 768);
    for (int r = 0; r < 8; ++r)
        for (int c = 0; c < 8; ++c) m.at(c, r) = 1;
    const std::vector<PixelRect> regions = plan_regions(m, m.total() / 16);
    expect_tiling(regions, 1024, 768);
    double busy_area = 0, largest_empty = 0;
    int busy = 0;
    for (const PixelRect& r : regions) {
        if (m.sum(r) > 0) {
            ++busy;
            busy_area += area(r);
            EXPECT_LE(m.sum(r), m.total() / 16 + 1e-9);
        } else {
            largest_empty = std::max(largest_empty, area(r));
        }
    }
    EXPECT_EQ(busy, 16) << "the work in 16 regions of equal work";
    EXPECT_LE(busy_area, 128.0 * 128.0 * 1.01);
    EXPECT_GE(largest_empty, 1024.0 * 768.0 / 4) << "the empty screen is cut only on the way";
    EXPECT_LE(regions.size(), 16u + 2u * 6u) << "a few halvings reach the corner";
    // No work at all: one region, the tile.
    const std::vector<PixelRect> none = plan_regions(WorkMap(1024, 768), 0);
    ASSERT_EQ(none.size(), 1u);
    EXPECT_EQ(area(none[0]), 1024.0 * 768.0);
}

TEST(RegionPlan, ProjectedWorkIsTheBoxesPixelsAndGrowsWithTheirOverlap) {
    const Box3 unit{{-0.25f, -0.25f, -0.25f}, {0.25f, 0.25f, 0.25f}};
    const Camera cam = front_full_view(unit, glm::mat3(1.0f), 4.0f / 3.0f);
    const Frustum f = cam.frustum(4.0f / 3.0f);
    const PixelRect px = screen_box(unit, cam.view(), f, 640, 480);
    ASSERT_GT(px.width, 0);
    const Box3 one[] = {unit};
    const WorkMap m1 = projected_work(one, cam.view(), f, 640, 480);
    EXPECT_DOUBLE_EQ(m1.total(), area(px));
    EXPECT_DOUBLE_EQ(m1.sum({0, 0, 640, 480}), area(px));
    // A second box over the same pixels doubles their work; one off screen adds nothing.
    const Box3 far{{40, 40, 40}, {41, 41, 41}};
    const Box3 three[] = {unit, unit, far};
    EXPECT_DOUBLE_EQ(projected_work(three, cam.view(), f, 640, 480).total(), 2 * area(px));
}

TEST(RegionPlan, TheLastFramesCostsScaleItsRegionsCells) {
    WorkMap m(64, 32);  // 4 x 2 cells
    for (double& v : m.work) v = 1;
    // The left half cost 4x its estimate, the right half its estimate: against a wall ratio of
    // 1, the left cells scale by 4 and the right ones stay.
    const RegionCost costs[] = {{{0, 0, 32, 32}, 4, 16}, {{32, 0, 32, 32}, 4, 4}};
    const WorkMap c = corrected(m, costs, 1.0);
    EXPECT_DOUBLE_EQ(c.at(0, 0), 4);
    EXPECT_DOUBLE_EQ(c.at(1, 1), 4);
    EXPECT_DOUBLE_EQ(c.at(2, 0), 1);
    // Relative to the wall: a wall ratio of 2 halves both; the clamp holds a wild one at 8.
    EXPECT_DOUBLE_EQ(corrected(m, costs, 2.0).at(0, 0), 2);
    EXPECT_DOUBLE_EQ(corrected(m, costs, 2.0).at(3, 1), 0.5);
    const RegionCost wild[] = {{{0, 0, 64, 32}, 1, 1000}};
    EXPECT_DOUBLE_EQ(corrected(m, wild, 1.0).at(2, 1), 8);
    // No wall ratio (nothing measured): the estimate as it was.
    EXPECT_DOUBLE_EQ(corrected(m, costs, 0).at(0, 0), 1);
}

// Two 640x480 tiles (ranks 1 and 2; rank 0 is the master) of one wall, both seeing `box` whole.
std::vector<FrameView> two_tiles_seeing(const Box3& box) {
    const Camera cam = front_full_view(box, glm::mat3(1.0f), 4.0f / 3.0f);
    const Frustum f = cam.frustum(4.0f / 3.0f);
    std::vector<FrameView> views(3);
    views[1] = {cam, f, 640, 480, 0, {}};
    views[2] = {cam, f, 640, 480, 0, {}};
    return views;
}
const Box3 kUnitBox{{-0.25f, -0.25f, -0.25f}, {0.25f, 0.25f, 0.25f}};

// Two tiles side by side of one wall, both seeing the same box: the costs of a frame in which
// rank 1's regions cost 8x rank 2's move the next frame's regions towards rank 1.
TEST(RegionPlan, AMeasuredFrameMovesTheRegionsToWhereTheCostWas) {
    const Box3 unit = kUnitBox;
    const std::vector<FrameView> views = two_tiles_seeing(unit);
    RegionPlanner planner([&](double) { return std::vector<Box3>{unit}; });
    const FramePlan first = planner.next(views, 0, nullptr, unit, true);
    ASSERT_EQ(first.regions[1].size(), first.regions[2].size()) << "the same view, the same cut";
    EXPECT_TRUE(first.regions[0].empty()) << "the master has no regions";
    EXPECT_EQ(first.regions[1].size(), first.work[1].size());
    // Run the frame on a board: rank 1's jobs cost 8x rank 2's per unit of work.
    JobBoard board(first.regions, first.work, true, 1);
    for (int round = 0; round < 1000 && !board.complete(); ++round)
        for (int rank = 1; rank <= 2; ++rank)
            if (auto id = board.next_for(rank)) {
                const BoardJob& j = board.job(*id);
                board.done(*id, j.rays * (j.owner == 1 ? 8e-6 : 1e-6));
                if (j.worker != j.owner) board.landed(*id);
            }
    ASSERT_TRUE(board.complete());
    const auto costs = region_costs(board, 3);
    // Every region with a job (margins outside the volume's screen box have none) is measured.
    EXPECT_EQ(costs[1].size(),
              static_cast<std::size_t>(std::count_if(first.work[1].begin(), first.work[1].end(),
                                                     [](double w) { return w > 0; })));
    EXPECT_LT(costs[1].size(), first.regions[1].size());
    const FramePlan second = planner.next(views, 0, &board, unit, true);
    EXPECT_GT(second.regions[1].size(), second.regions[2].size())
        << "the expensive tile is cut finer";
    expect_tiling(second.regions[1], 640, 480);
}

// Runs `plan` on a board of ranks 1 and 2 in which every region costs its uncorrected estimate
// (FramePlan::base) times the owner's factor: a fixed truth, whatever the plan's correction.
JobBoard run_board(const FramePlan& plan, double factor1, double factor2) {
    JobBoard board(plan.regions, plan.work, true, 1);
    auto region_of = [&](const BoardJob& j) {
        const auto& regions = plan.regions[std::size_t(j.owner)];
        for (std::size_t i = 0; i < regions.size(); ++i)
            if (regions[i].x == j.rect.x && regions[i].y == j.rect.y) return i;
        ADD_FAILURE() << "a job outside its plan";
        return std::size_t(0);
    };
    for (int round = 0; round < 1000 && !board.complete(); ++round)
        for (int rank = 1; rank <= 2; ++rank)
            if (auto id = board.next_for(rank)) {
                const BoardJob& j = board.job(*id);
                const std::size_t i = region_of(j);
                const auto o = std::size_t(j.owner);
                // The band's part of the region; a fine band on another rank than its coarse
                // band's casts the region again from its first level (region_costs' rule).
                const bool again = j.band == Band::fine && board.job(j.coarse).worker != rank;
                const double share = again ? 1.0 : j.rays / plan.work[o][i];
                board.done(*id, share * plan.base[o][i] * (j.owner == 1 ? factor1 : factor2));
                if (j.worker != j.owner) board.landed(*id);
            }
    EXPECT_TRUE(board.complete());
    return board;
}

// The next frame's correction is measured against the uncorrected estimate: a correction that
// was right stays (the next plan is the same), instead of reading as "no error" and being
// undone, which made every other frame of a turning wall plan from the bare estimate.
TEST(RegionPlan, ARightCorrectionStaysFromFrameToFrame) {
    const Box3 unit = kUnitBox;
    const std::vector<FrameView> views = two_tiles_seeing(unit);
    RegionPlanner planner([&](double) { return std::vector<Box3>{unit}; });
    const FramePlan first = planner.next(views, 0, nullptr, unit, true);
    EXPECT_EQ(first.work, first.base) << "nothing measured yet: nothing corrected";
    const JobBoard b1 = run_board(first, 8e-6, 1e-6);
    const FramePlan second = planner.next(views, 0, &b1, unit, true);
    ASSERT_GT(second.regions[1].size(), second.regions[2].size());
    const JobBoard b2 = run_board(second, 8e-6, 1e-6);
    const FramePlan third = planner.next(views, 0, &b2, unit, true);
    EXPECT_EQ(third.regions[1].size(), second.regions[1].size());
    EXPECT_EQ(third.regions[2].size(), second.regions[2].size());
    EXPECT_GT(third.regions[1].size(), third.regions[2].size()) << "the correction was undone";
}

TEST(RegionPlan, AFixedGridIsTheOldCut) {
    const Box3 unit{{-0.25f, -0.25f, -0.25f}, {0.25f, 0.25f, 0.25f}};
    const Camera cam = front_full_view(unit, glm::mat3(1.0f), 4.0f / 3.0f);
    std::vector<FrameView> views(2);
    views[1] = {cam, cam.frustum(4.0f / 3.0f), 640, 480, 0, {}};
    const FramePlan p = grid_plan(views, 128, 96, unit, true);
    EXPECT_EQ(p.regions[1].size(), 25u);
    EXPECT_EQ(p.work[1], estimated_rays(views[1], p.regions[1], unit, true));
    EXPECT_EQ(grid_plan(views, 0, 0, unit, true).regions[1].size(), 1u) << "one per tile";
}

}  // namespace
}  // namespace isowall
