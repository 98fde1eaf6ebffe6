// The screen-region scheduler's policy (master/job_board.h), alone: regions, the order of jobs,
// migration, landing, and what the master is told when a rank reports out of turn.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <vector>

#include "master/job_board.h"

namespace isowall {
namespace {

// Ranks 0..n-1; rank 0 (the master) has no regions; `per_rank[r]` regions of 100 rays each.
JobBoard board_of(const std::vector<int>& per_rank, bool balance, int depth = 2) {
    std::vector<std::vector<PixelRect>> regions(per_rank.size());
    std::vector<std::vector<double>> rays(per_rank.size());
    for (std::size_t r = 0; r < per_rank.size(); ++r)
        for (int i = 0; i < per_rank[r]; ++i) {
            regions[r].push_back({i * 10, 0, 10, 10});
            rays[r].push_back(100);
        }
    return JobBoard(regions, rays, balance, depth);
}

TEST(JobBoard, RegionsCoverTheTileOnce) {
    const auto regions = cut_into_regions(100, 50, 64, 48);
    ASSERT_EQ(regions.size(), 4u);
    std::vector<int> hits(100 * 50, 0);
    for (const PixelRect& r : regions)
        for (int y = r.y; y < r.y + r.height; ++y)
            for (int x = r.x; x < r.x + r.width; ++x) ++hits[static_cast<std::size_t>(y * 100 + x)];
    for (int h : hits) EXPECT_EQ(h, 1);
    EXPECT_EQ(regions[3].width, 36);
    EXPECT_EQ(regions[3].height, 2);
    EXPECT_EQ(cut_into_regions(1024, 768, 256, 192).size(), 16u);
    ASSERT_EQ(cut_into_regions(1024, 768, 0, 0).size(), 1u);            // "tile"
    EXPECT_EQ(cut_into_regions(1024, 768, 4096, 4096)[0].width, 1024);  // larger than the tile
}

TEST(JobBoard, RegionsOutsideTheScreenBoxGetNoJob) {
    FrameView v;
    v.camera = front_full_view(Box3{{0, 0, 0}, {10, 10, 10}}, 2.0f);
    v.frustum = v.camera.frustum(2.0f);
    v.width = 200;
    v.height = 100;
    // A box far to the left of the view projects onto the left part of the screen only.
    const auto rays = estimated_rays(v, {{0, 0, 100, 100}, {100, 0, 100, 100}},
                                     Box3{{-30, 4, 4}, {-29, 5, 5}}, true);
    EXPECT_EQ(rays[1], 0.0);
    const auto all = estimated_rays(v, {{0, 0, 100, 100}}, Box3{{-30, 4, 4}, {-29, 5, 5}}, false);
    EXPECT_EQ(all[0], 100.0 * 100.0);
    const JobBoard board({{}, {{0, 0, 1, 1}, {1, 0, 1, 1}}}, {{}, {0.0, 5.0}}, true);
    EXPECT_EQ(board.size(), 2u) << "one region with rays: its coarse and its fine job";
}

TEST(JobBoard, RanksHelpOnlyOwnersOfTheirPool) {
    // Ranks 1 and 3 are one eye, 2 and 4 the other; ranks 1 and 2 hold all the work.
    std::vector<std::vector<PixelRect>> regions(5);
    std::vector<std::vector<double>> rays(5);
    for (int r : {1, 2})
        for (int i = 0; i < 6; ++i) {
            regions[r].push_back({i * 10, 0, 10, 10});
            rays[r].push_back(100);
        }
    JobBoard b(regions, rays, true, 1, {0, 1, 2, 1, 2});
    std::set<int> owners3, owners4;
    while (auto id = b.next_for(3)) {
        owners3.insert(b.job(*id).owner);
        b.done(*id, 0.01);
    }
    while (auto id = b.next_for(4)) {
        owners4.insert(b.job(*id).owner);
        b.done(*id, 0.01);
    }
    EXPECT_EQ(owners3, std::set<int>{1});
    EXPECT_EQ(owners4, std::set<int>{2});
    EXPECT_THROW(JobBoard(regions, rays, true, 1, {0, 1}), std::invalid_argument);
}

TEST(JobBoard, StaticHandsEachRankItsOwnJobsCoarseFirst) {
    JobBoard b = board_of({0, 3, 0}, false, 10);
    std::vector<Band> bands;
    while (auto id = b.next_for(1)) {
        EXPECT_EQ(b.job(*id).owner, 1);
        bands.push_back(b.job(*id).band);
    }
    ASSERT_EQ(bands.size(), 6u);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(bands[static_cast<std::size_t>(i)], Band::coarse);
    for (int i = 3; i < 6; ++i) EXPECT_EQ(bands[static_cast<std::size_t>(i)], Band::fine);
    EXPECT_FALSE(b.next_for(2)) << "an idle rank takes nothing when balancing is off";
    EXPECT_EQ(b.migrated(), 0u);
}

TEST(JobBoard, IdleRanksTakeCoarseJobsOfTheBusyTileFirst) {
    JobBoard b = board_of({0, 4, 0, 0}, true, 1);
    const auto own = b.next_for(1);  // the owner starts at the front
    ASSERT_TRUE(own);
    EXPECT_EQ(b.job(*own).rect.x, 0);
    EXPECT_FALSE(b.next_for(1)) << "depth 1: one job in hand";
    const auto stolen = b.next_for(2);  // a helper steals from the back
    ASSERT_TRUE(stolen);
    EXPECT_EQ(b.job(*stolen).band, Band::coarse);
    EXPECT_EQ(b.job(*stolen).rect.x, 30);
    const auto third = b.next_for(3);
    ASSERT_TRUE(third);
    EXPECT_EQ(b.job(*third).band, Band::coarse) << "coarse jobs anywhere before fine ones";
    EXPECT_EQ(b.migrated(), 2u);
    // The helper's next job is the fine band of the region whose coarse band it cast.
    b.done(*stolen, 0.01);
    const auto next = b.next_for(2);
    ASSERT_TRUE(next);
    // One coarse job is still queued (region 1 or 2): it goes before any fine job.
    EXPECT_EQ(b.job(*next).band, Band::coarse);
    b.done(*next, 0.01);
    const auto fine = b.next_for(2);
    ASSERT_TRUE(fine);
    EXPECT_EQ(b.job(*fine).band, Band::fine);
    EXPECT_EQ(b.job(*fine).holder, 2) << "a region whose coarse band it cast itself";
    EXPECT_TRUE(b.job(*fine).rect.x == b.job(*stolen).rect.x ||
                b.job(*fine).rect.x == b.job(*next).rect.x);
}

TEST(JobBoard, AJobLandsWhenDoneAndDeliveredInEitherOrder) {
    JobBoard b = board_of({0, 1, 0}, true, 1);
    const auto a = b.next_for(2);  // the helper takes the coarse job
    ASSERT_TRUE(a);
    EXPECT_EQ(b.job(*a).worker, 2);
    // The fine band is the helper's: the owner would have to cast the whole region again, which
    // is worth it only if the helper had more work queued than that.
    EXPECT_FALSE(b.next_for(1));
    b.landed(*a);  // the owner's word can come before the helper's
    EXPECT_FALSE(b.complete());
    b.done(*a, 0.001);
    const auto c = b.next_for(2);
    ASSERT_TRUE(c);
    EXPECT_EQ(b.job(*c).band, Band::fine);
    b.done(*c, 0.002);
    EXPECT_FALSE(b.complete()) << "the helper's fine band has not landed";
    b.landed(*c);
    EXPECT_TRUE(b.complete());
}

TEST(JobBoard, ARankHelpsTheBusiestTileBeforeItsOwnCheapJobs) {
    JobBoard b = board_of({0, 4, 4}, true, 1);
    // Tile 1 turns out expensive, tile 2 cheap: rank 2 helps tile 1 before its own queue.
    const auto one = b.next_for(1);
    const auto two = b.next_for(2);
    ASSERT_TRUE(one && two);
    b.done(*one, 0.5);
    b.done(*two, 0.001);
    const auto next = b.next_for(2);
    ASSERT_TRUE(next);
    EXPECT_EQ(b.job(*next).owner, 1);
    EXPECT_EQ(b.job(*next).band, Band::coarse);
}

TEST(JobBoard, ReportsOutOfTurnThrow) {
    JobBoard b = board_of({0, 1, 0}, true, 2);
    EXPECT_THROW(b.done(0, 0.1), std::runtime_error) << "not handed out";
    const auto own = b.next_for(1);
    ASSERT_TRUE(own);
    EXPECT_THROW(b.landed(*own), std::runtime_error) << "the owner's own job has no helper";
    b.done(*own, 0.1);
    EXPECT_THROW(b.done(*own, 0.1), std::runtime_error) << "done twice";
    EXPECT_THROW(b.next_for(7), std::out_of_range);
}

TEST(JobBoard, StealsFromTheTileWithTheMostWorkLeft) {
    // Tile 1 has 2 regions, tile 2 has 6: an idle rank 3 takes from tile 2.
    JobBoard b = board_of({0, 2, 6, 0}, true, 1);
    const auto id = b.next_for(3);
    ASSERT_TRUE(id);
    EXPECT_EQ(b.job(*id).owner, 2);
    b.done(*id, 0.01);
    b.landed(*id);
    // Every job is handed out exactly once.
    std::set<std::uint32_t> seen{*id};
    for (int round = 0; round < 20; ++round)
        for (int rank = 1; rank <= 3; ++rank)
            if (auto j = b.next_for(rank)) {
                EXPECT_TRUE(seen.insert(*j).second);
                b.done(*j, 0.01);
                if (b.job(*j).worker != b.job(*j).owner) b.landed(*j);
            }
    EXPECT_EQ(seen.size(), b.size());
    EXPECT_TRUE(b.complete());
}

}  // namespace
}  // namespace isowall
