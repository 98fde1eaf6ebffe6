// VisitedCells: units of every level recorded at their first cell, group ids without a hash, and
// a new frame that forgets exactly what the last one took.
#include <gtest/gtest.h>

#include "common/extract/visited.h"

namespace isowall {
namespace {

TEST(Visited, UnitsOfEachLevelAreTakenOnceAndCountTheirCells) {
    VisitedCells v({100, 60, 37});
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

TEST(Visited, ResetForgetsEveryUnitAndPagesAreReused) {
    VisitedCells v({64, 64, 64});
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
        v.reset({64, 64, 64});
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

}  // namespace
}  // namespace isowall
