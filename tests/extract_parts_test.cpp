// The extractor's parts: the group key caches find groups by, uniform levels at the volume's
// border, and the thread budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <unordered_set>

#include <glm/gtc/matrix_transform.hpp>

#include "extract/group.h"
#include "extract/propagator.h"
#include "extract/surface_extractor.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

TEST(GroupKey, EqualKeysHashAlikeAndPrint) {
    const GroupKey a{{1, 2, 3}, 1, 40.0};
    GroupKey b = a;
    EXPECT_EQ(a, b);
    EXPECT_EQ(std::hash<GroupKey>{}(a), std::hash<GroupKey>{}(b));
    // -0.0 == 0.0, so they must hash alike.
    const GroupKey z0{{0, 0, 0}, 0, 0.0}, z1{{0, 0, 0}, 0, -0.0};
    EXPECT_EQ(z0, z1);
    EXPECT_EQ(std::hash<GroupKey>{}(z0), std::hash<GroupKey>{}(z1));
    b.refinement = true;
    EXPECT_FALSE(a == b) << a << " vs " << b;
    std::ostringstream os;
    os << a;
    EXPECT_EQ(os.str(), "GroupKey{seed=(1,2,3) level=1 iso=40}");
}

// A cache holds the groups of one view: seeds a cell apart, at a few levels. Their hashes must
// differ (a hash of x + y + z gives 22 values for these 512 seeds) and fill a table's buckets
// about as a random hash would (about 63% of 1 bucket per key, none holding many).
TEST(GroupKey, NeighbouringSeedsSpreadOverBuckets) {
    std::unordered_set<GroupKey> keys;
    keys.reserve(3 * 512);
    std::unordered_set<std::size_t> hashes;
    for (int level = 0; level < 3; ++level)
        for (int z = 0; z < 8; ++z)
            for (int y = 0; y < 8; ++y)
                for (int x = 0; x < 8; ++x) {
                    const GroupKey k{{x << level, y << level, z << level}, level, 40.0};
                    keys.insert(k);
                    hashes.insert(std::hash<GroupKey>{}(k));
                }
    ASSERT_EQ(keys.size(), 3u * 512u);
    EXPECT_GE(hashes.size(), keys.size() - 2) << "distinct hashes of " << keys.size() << " keys";
    std::size_t occupied = 0, fullest = 0;
    for (std::size_t b = 0; b < keys.bucket_count(); ++b) {
        occupied += keys.bucket_size(b) > 0;
        fullest = std::max(fullest, keys.bucket_size(b));
    }
    const double expected = std::min(keys.size(), keys.bucket_count()) * 0.63;
    EXPECT_GE(double(occupied), 0.8 * expected)
        << occupied << " of " << keys.bucket_count() << " buckets hold keys";
    EXPECT_LE(fullest, 8u) << "the fullest bucket";
    std::printf("group keys: %zu keys, %zu distinct hashes, %zu of %zu buckets used, fullest %zu\n",
                keys.size(), hashes.size(), occupied, keys.bucket_count(), fullest);
}

TEST(GroupKey, PropagatedGroupRecordsItsIsovalue) {
    const Volume p = make_phantom();
    auto ex = make_surface_extractor(p);
    EXPECT_EQ(ex->threads(), 1);
    ex->begin_frame(kPhantomSkinIso);
    const glm::vec3 c = p.bounds().center();
    const Ray ray{c - glm::vec3(0, 0, 1000), glm::vec3(0, 0, 1)};
    const RayHit hit = ex->cast(ray, IntersectMode::exact);
    ASSERT_TRUE(hit.found);
    const Group g = ex->propagate(hit.cell, 7, PropagationParams{}, ray);
    EXPECT_EQ(g.iso, kPhantomSkinIso);
    EXPECT_EQ(g.key(), (GroupKey{g.seed, g.level, kPhantomSkinIso}));
}

// A coarse level of progressive LOD sends groups of its own level only: a group seeded at the
// border's cells (past the last whole meta-cell) was a level-0 group, which the client took for
// the start of the full resolution, dropping every coarse group after it (the shared CT head's
// coarse picture reached C = 0.875 instead of 0.925).
TEST(UniformLevels, ACoarseLevelLeavesTheBordersCellsToTheFullResolution) {
    // A plane x = 9.5 through every cell row; 20x19x18 cells: whole meta-cells of 4 end at 16.
    const glm::ivec3 dims(21, 20, 19);
    std::vector<std::byte> bytes(std::size_t(dims.x) * dims.y * dims.z);
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x)
                bytes[(std::size_t(z) * dims.y + y) * dims.x + x] = std::byte(x * 10);
    const Volume v(dims, VoxelType::u8, glm::vec3(1), std::move(bytes), "ramp");
    auto ex = make_surface_extractor(v);
    const Ray ray{glm::vec3(-5, 18.5f, 17.5f), glm::vec3(1, 0, 0)};  // past y, z = 16
    ex->begin_frame(95, uniform_levels(2));
    const RayHit border = ex->cast(ray, IntersectMode::exact);
    ASSERT_TRUE(border.found);
    EXPECT_EQ(border.level, 0) << "the ray meets a border cell";
    const Group none = ex->propagate(border.cell, 0, PropagationParams{}, ray);
    EXPECT_TRUE(none.cells.empty());
    EXPECT_TRUE(none.mesh.empty());
    EXPECT_FALSE(ex->visited(border.cell)) << "left for the full resolution";
    const Ray inner{glm::vec3(-5, 6.5f, 6.5f), glm::vec3(1, 0, 0)};
    const RayHit hit = ex->cast(inner, IntersectMode::exact);
    ASSERT_TRUE(hit.found);
    const Group g = ex->propagate(hit.cell, 0, PropagationParams{}, inner);
    EXPECT_EQ(g.level, 2);
    EXPECT_FALSE(g.cells.empty());
    EXPECT_TRUE(g.cell_levels.empty()) << "one level";
    for (const glm::ivec3 c : g.cells) EXPECT_LE(c.y + 4, 19) << "a whole meta-cell";
    // At full resolution the border's cells are cells, as ever.
    ex->begin_frame(95);
    const Group fine = ex->propagate(border.cell, 0, PropagationParams{}, ray);
    EXPECT_EQ(fine.level, 0);
    EXPECT_FALSE(fine.cells.empty());
}

TEST(ThreadBudget, ZeroIsReadAsOneAndSetsTheWorkers) {
    EXPECT_EQ(ThreadBudget{0}.usable(), 1);
    EXPECT_GE(ThreadBudget::hardware().threads, 1);
    const Volume p = make_phantom();
    EXPECT_EQ(make_surface_extractor(p, {}, nullptr, ThreadBudget{3})->threads(), 3);
    EXPECT_EQ(make_surface_extractor(p, {}, nullptr, ThreadBudget{0})->threads(), 1);
}

TEST(ThreadBudget, ARankTakesItsShareOfTheNode) {
    // A wall emulated on 2 cores: 5 ranks, 1 each (never 0).
    EXPECT_EQ(node_share(2, 2, 5), ThreadBudget{1});
    // One rank per 16-core display node: every core; two ranks: half each.
    EXPECT_EQ(node_share(16, 16, 1), ThreadBudget{16});
    EXPECT_EQ(node_share(16, 16, 2), ThreadBudget{8});
    // mpirun bound the rank to 4 cores: no more than those.
    EXPECT_EQ(node_share(4, 16, 1), ThreadBudget{4});
    // Nonsense counts still give one thread.
    EXPECT_EQ(node_share(0, 0, 0), ThreadBudget{1});
}

TEST(ThreadBudget, OctreeIsTheSameOnAnyNumberOfThreads) {
    const Volume p = make_phantom();
    const auto v = p.view<std::uint8_t>();
    const auto one = MinMaxOctree<std::uint8_t>::build(v, ThreadBudget{1});
    for (int t : {0, 2, 5, 1000}) {
        const auto many = MinMaxOctree<std::uint8_t>::build(v, ThreadBudget{t});
        ASSERT_EQ(one.nodes().size(), many.nodes().size()) << ThreadBudget{t};
        EXPECT_TRUE(std::equal(one.nodes().begin(), one.nodes().end(), many.nodes().begin()))
            << ThreadBudget{t};
    }
}

// Which units a pass triangulates (SampleGrid): those whose projected box holds a pixel centre,
// and every unit that reaches past the frame (another frame of the screen may need it).
TEST(SampleGrid, JudgesOnlyUnitsInsideTheFrameByTheirCentres) {
    SampleGrid g;
    g.active = true;
    g.width = g.height = 10;
    // Voxel (x, y) maps to window (x, y) / 4: a cell is a quarter of a pixel.
    g.clip_from_voxel = glm::ortho(0.0f, 40.0f, 0.0f, 40.0f, -100.0f, 100.0f);
    EXPECT_TRUE(g.may_cover_a_centre({9, 9, 0}, 1));     // [2.25, 2.5]: holds 2.5
    EXPECT_FALSE(g.may_cover_a_centre({11, 11, 0}, 1));  // [2.75, 3]: no centre
    EXPECT_TRUE(g.may_cover_a_centre({8, 8, 0}, 4));     // a meta-cell of 4: [2, 3]
    EXPECT_FALSE(g.may_cover_a_centre({39, 21, 0}, 1));  // [9.75, 10] x [5.25, 5.5]: judged
    EXPECT_TRUE(g.may_cover_a_centre({39, 21, 0}, 2));   // [9.75, 10.25]: reaches past
    EXPECT_TRUE(g.may_cover_a_centre({40, 20, 0}, 1));   // past the frame
    EXPECT_TRUE(g.may_cover_a_centre({-1, 20, 0}, 1));
}

}  // namespace
}  // namespace isowall
