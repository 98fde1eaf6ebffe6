// VisitedCells: units of every level recorded at their first cell, group ids without a hash, and
// a new frame that forgets exactly what the last one took.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <thread>
#include <vector>

#include "extract/visited.h"

namespace isowall {
namespace {

TEST(Visited, UnitsOfEachLevelAreTakenOnceAndCountTheirCells) {
    VisitedCells v({100, 60, 37}, 3);
    EXPECT_FALSE(v.contains({0, 0, 0}));
    EXPECT_TRUE(v.insert({3, 4, 5}, 7));
    EXPECT_FALSE(v.insert({3, 4, 5}, 8));  // taken already: the first group keeps it
    EXPECT_EQ(v.group_of({3, 4, 5}), 7u);
    EXPECT_TRUE(v.insert({8, 16, 4}, 9, 2));  // a meta-cell of 4^3 cells
    EXPECT_TRUE(v.contains({8, 16, 4}, 2));
    EXPECT_FALSE(v.contains({8, 16, 4}, 0));  // levels are separate grids
    EXPECT_FALSE(v.contains({8, 16, 4}, 1));
    EXPECT_EQ(v.group_of({8, 16, 4}, 2), 9u);
    EXPECT_TRUE(v.insert({96, 56, 32}, 10, 2));  // the last full 4^3 block
    EXPECT_TRUE(v.insert({99, 59, 36}, 11));     // the last cell
    EXPECT_EQ(v.size(), 1u + 64u + 64u + 1u);
    // Neighbours within one page stay free.
    EXPECT_FALSE(v.contains({3, 4, 4}));
    EXPECT_FALSE(v.contains({2, 4, 5}));
    EXPECT_EQ(v.group_of({2, 4, 5}), VisitedCells::kFree);
}

// A propagation pass claims units without counting them and adds its cells once at its end: the
// units are taken at once, the count follows add_count.
TEST(Visited, ClaimTakesAUnitAndTheCountFollowsAddCount) {
    VisitedCells v({64, 64, 64}, 1);
    EXPECT_TRUE(v.claim({5, 6, 7}, 3));
    EXPECT_TRUE(v.claim({8, 8, 8}, 3, 1));
    EXPECT_FALSE(v.claim({5, 6, 7}, 4));      // taken already
    EXPECT_FALSE(v.insert({8, 8, 8}, 4, 1));  // insert and claim take from one set of units
    EXPECT_TRUE(v.contains({5, 6, 7}));
    EXPECT_EQ(v.group_of({8, 8, 8}, 1), 3u);
    EXPECT_EQ(v.size(), 0u);
    v.add_count(1 + 8);
    EXPECT_EQ(v.size(), 9u);
    EXPECT_TRUE(v.insert({0, 0, 0}, 5));  // insert counts its own unit
    EXPECT_EQ(v.size(), 10u);
}

TEST(Visited, ResetForgetsEveryUnitAndPagesAreReused) {
    VisitedCells v({64, 64, 64}, 3);
    for (int round = 0; round < 3; ++round) {
        // Different units each round; nothing of the last round may show through.
        for (int i = 0; i < 64; ++i) {
            const glm::ivec3 c(i, (i * 7 + round) % 64, (i * 13 + 3 * round) % 64);
            EXPECT_FALSE(v.contains(c)) << "round " << round << " cell " << i;
            EXPECT_TRUE(v.insert(c, std::uint32_t(1000 * round + i)));
            EXPECT_EQ(v.group_of(c), std::uint32_t(1000 * round + i));
        }
        EXPECT_TRUE(v.insert({8 * round, 0, 0}, 5, 3));
        EXPECT_EQ(v.size(), 64u + 512u);
        v.reset({64, 64, 64}, 3);
        EXPECT_EQ(v.size(), 0u);
        for (int i = 0; i < 64; ++i)
            EXPECT_FALSE(v.contains({i, (i * 7 + round) % 64, (i * 13 + 3 * round) % 64}));
        EXPECT_FALSE(v.contains({8 * round, 0, 0}, 3));
    }
    // New dimensions: a fresh grid of the new size.
    v.reset({9, 9, 9});
    EXPECT_EQ(v.dims(), glm::ivec3(9, 9, 9));
    EXPECT_TRUE(v.insert({8, 8, 8}, 1));
    EXPECT_TRUE(v.contains({8, 8, 8}));
    EXPECT_EQ(v.index({8, 8, 8}), 8u * 81u + 8u * 9u + 8u);
}

TEST(Visited, ThreadsClaimEachUnitExactlyOnce) {
    // Four threads claim every unit of levels 0 and 1 of a 40^3 grid, each in its own order:
    // every unit goes to exactly one of them, and the count is the cells.
    const glm::ivec3 dims(40, 40, 40);
    VisitedCells v(dims, 1);
    constexpr int kThreads = 4;
    std::vector<std::size_t> won(kThreads, 0);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            for (int level = 0; level <= 1; ++level) {
                const int n = 40 >> level;
                for (int k = 0; k < n * n * n; ++k) {
                    const int i = (t % 2 == 0) ? k : n * n * n - 1 - k;  // two orders meet midway
                    const glm::ivec3 u(i % n, (i / n) % n, i / (n * n));
                    // Level 1 units sit in the other half of the volume in z, clear of level 0's.
                    if (level == 1 && u.z < 10) continue;
                    if (level == 0 && u.z >= 20) continue;
                    won[std::size_t(t)] += v.insert(u << level, std::uint32_t(t), level);
                }
            }
        });
    for (std::thread& t : threads) t.join();
    std::size_t total = 0;
    for (const std::size_t w : won) total += w;
    EXPECT_EQ(total, 40u * 40u * 20u + 20u * 20u * 10u);
    EXPECT_EQ(v.size(), 40u * 40u * 20u + 20u * 20u * 10u * 8u);
    for (int z = 0; z < 20; ++z) EXPECT_LT(v.group_of({3, 5, z}), std::uint32_t(kThreads));
}

// Resident memory of this process, in bytes (/proc/self/statm's second field, in pages).
std::size_t resident_bytes() {
    std::ifstream in("/proc/self/statm");
    std::size_t size = 0, resident = 0;
    in >> size >> resident;
    return resident * 4096;
}

// The 8x CT head's cells: the level-0 table is 245 MB of page numbers. It is not written when
// made (filling it held the first picture back by about a second), only the pages of
// the bricks a frame takes become resident, and a new frame still forgets every unit.
TEST(Visited, AHugeTableCostsOnlyThePagesItsFrameWrites) {
#ifdef __SANITIZE_ADDRESS__
    GTEST_SKIP() << "AddressSanitizer's allocator and shadow memory change what is resident";
#endif
    const std::size_t before = resident_bytes();
    VisitedCells v({4095, 4095, 1871});
    EXPECT_LT(resident_bytes(), before + (32u << 20)) << "the table was written when made";
    for (int i = 0; i < 100; ++i) EXPECT_TRUE(v.insert({40 * i, 40 * i, 18 * i}, 7));
    EXPECT_EQ(v.group_of({40 * 99, 40 * 99, 18 * 99}), 7u);
    EXPECT_FALSE(v.contains({1, 2, 3}));
    EXPECT_FALSE(v.contains({4094, 4094, 1870}));
    EXPECT_LT(resident_bytes(), before + (32u << 20));
    v.reset({4095, 4095, 1871});
    for (int i = 0; i < 100; ++i) EXPECT_FALSE(v.contains({40 * i, 40 * i, 18 * i}));
    EXPECT_EQ(v.size(), 0u);
}

}  // namespace
}  // namespace isowall
