// Read-ahead of a paged store (store/paged_voxels.h) and the bricks it may read
// (volume/surface_bricks.h).
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "extract/marching_cubes.h"
#include "extract/surface_extractor.h"
#include "store/open_store.h"
#include "store/store_writer.h"
#include "tests/store_test_util.h"
#include "tests/test_util.h"
#include "volume/phantom.h"
#include "volume/surface_bricks.h"

namespace isowall::store {
namespace {
namespace fs = std::filesystem;

using test::import_to;

// Waits (at most 20 s: a loaded machine) until the pager has hinted `n` chunks. The faults are
// counted just after the brick wakes its reader, so they are waited for too.
std::uint64_t wait_for_hints(const PagedVoxels& p, std::uint64_t n) {
    for (int i = 0; i < 2000 && p.stats().hinted < n; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return p.stats().hinted;
}
std::uint64_t wait_for_faults(const PagedVoxels& p, std::uint64_t n) {
    for (int i = 0; i < 2000 && p.stats().faults < n; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return p.stats().faults;
}

TEST(SurfaceBricks, HoldEveryBrickThatACrossedCellReadsAndFewOthers) {
    const Volume v = make_phantom({{150, 140, 130}, glm::vec3(1.0f)});
    const auto view = v.view<std::uint8_t>();
    const auto octree = MinMaxOctree<std::uint8_t>::build(view);
    constexpr int kLog2 = 4;  // bricks of 16
    const glm::ivec3 grid = (v.dims() + 15) / 16;
    for (const double iso : {kPhantomSkinIso, kPhantomBoneIso}) {
        const std::vector<std::uint8_t> want = surface_bricks(octree, kLog2, grid, iso);
        ASSERT_EQ(want.size(), std::size_t(grid.x) * grid.y * grid.z);
        std::vector<std::uint8_t> read(want.size(), 0);
        const InsideTest<std::uint8_t> inside(iso);
        for (int z = 0; z + 1 < v.dims().z; ++z)
            for (int y = 0; y + 1 < v.dims().y; ++y)
                for (int x = 0; x + 1 < v.dims().x; ++x) {
                    const int c = meta_cell_case(view, {x, y, z}, 0, inside);
                    if (c == 0 || c == 255) continue;
                    for (int k = 0; k < 8; ++k) {
                        const glm::ivec3 b =
                            glm::ivec3(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2)) >> kLog2;
                        read[(std::size_t(b.z) * grid.y + b.y) * grid.x + b.x] = 1;
                    }
                }
        std::size_t missed = 0, marked = 0, used = 0;
        for (std::size_t i = 0; i < want.size(); ++i) {
            missed += read[i] && !want[i];
            marked += want[i];
            used += read[i];
        }
        EXPECT_EQ(missed, 0u) << "iso " << iso;
        EXPECT_GT(used, 0u);
        // The extra bricks are the far corners' neighbours of active nodes, not the volume.
        EXPECT_LE(marked, used * 2) << "iso " << iso;
        EXPECT_LT(marked, want.size()) << "iso " << iso;
    }
}

TEST(StoreReadAhead, ATouchedBrickHintsOnlyItsWantedNeighbours) {
    if (const std::string why = paging_unavailable(); !why.empty())
        GTEST_SKIP() << "no paging here (" << why << "): a store is read whole";
    const Volume v = test::pattern_volume({300, 260, 200});  // bricks of 32: a 10x9x7 grid
    const fs::path store = import_to(v, "store_read_ahead");
    const StoreReader reader(store);
    const StoreLayout& l = reader.layout();
    ASSERT_EQ(l.grid(), glm::ivec3(10, 9, 7));
    {
        OpenedStore opened = open_store(store, 64 << 20);
        ASSERT_TRUE(opened.pager) << opened.how;
        std::vector<std::uint8_t> want(l.chunk_count(), 0);
        want[l.brick_index({6, 5, 3})] = 1;  // +x of the touched brick
        want[l.brick_index({5, 4, 3})] = 1;  // -y
        want[l.brick_index({0, 0, 0})] = 1;  // wanted, but no neighbour of it
        opened.pager->want(std::move(want));
        const auto pv = opened.volume.view<std::uint16_t>();
        EXPECT_EQ(pv.at(5 * 32 + 3, 5 * 32 + 3, 3 * 32 + 3),
                  v.view<std::uint16_t>().at(163, 163, 99));
        EXPECT_EQ(wait_for_hints(*opened.pager, 2), 2u);
        // Their faults still read and count them: a hint is not a brick in memory.
        EXPECT_EQ(pv.at(6 * 32, 5 * 32, 3 * 32), v.view<std::uint16_t>().at(192, 160, 96));
        EXPECT_EQ(wait_for_faults(*opened.pager, 2), 2u);
        EXPECT_EQ(wait_for_hints(*opened.pager, 2), 2u);
    }
    {
        // Nothing wanted: nothing read ahead.
        OpenedStore opened = open_store(store, 64 << 20);
        const auto pv = opened.volume.view<std::uint16_t>();
        volatile std::uint16_t sink = 0;
        for (int i = 0; i < 4; ++i) sink = pv.at(32 * i + 1, 40, 40);
        (void)sink;
        EXPECT_EQ(wait_for_faults(*opened.pager, 4), 4u);
        EXPECT_EQ(opened.pager->stats().hinted, 0u);
    }
}

TEST(StoreReadAhead, TheExtractorTellsThePagerWhereTheSurfaceIs) {
    if (const std::string why = paging_unavailable(); !why.empty())
        GTEST_SKIP() << "no paging here (" << why << "): a store is read whole";
    const Volume v = make_phantom({{260, 230, 210}, glm::vec3(1.0f)});
    const fs::path store = import_to(v, "store_read_ahead_phantom");
    OpenedStore opened = open_store(store, 256 << 20);
    ASSERT_TRUE(opened.pager);
    auto extractor = make_surface_extractor(opened.volume);
    ASSERT_EQ(opened.pager->stats().faults, 0u) << "the store's own octree is mapped, not built";
    extractor->begin_frame(kPhantomSkinIso);
    // A brick of the surface with a neighbour on it, touched alone: its neighbours are hinted.
    const glm::ivec3 g = opened.volume.brick_grid();
    const std::vector<std::uint8_t> want =
        surface_bricks(MinMaxOctree<std::uint8_t>::build(v.view<std::uint8_t>()),
                       opened.volume.bricks(), g, kPhantomSkinIso);
    const StoreLayout& l = opened.pager->reader().layout();
    std::size_t pick = want.size(), neighbours = 0;
    for (std::size_t i = 0; i < want.size() && pick == want.size(); ++i) {
        const glm::ivec3 b = l.brick_at(i);
        if (!want[i] || b.x + 1 >= g.x || !want[l.brick_index(b + glm::ivec3(1, 0, 0))]) continue;
        pick = i;
        for (const glm::ivec3 d :
             {glm::ivec3(1, 0, 0), glm::ivec3(-1, 0, 0), glm::ivec3(0, 1, 0), glm::ivec3(0, -1, 0),
              glm::ivec3(0, 0, 1), glm::ivec3(0, 0, -1)}) {
            const glm::ivec3 n = b + d;
            if (glm::all(glm::greaterThanEqual(n, glm::ivec3(0))) && glm::all(glm::lessThan(n, g)))
                neighbours += want[l.brick_index(n)];
        }
    }
    ASSERT_LT(pick, want.size());
    const glm::ivec3 at = l.brick_at(pick) * l.brick();
    EXPECT_EQ(opened.volume.view<std::uint8_t>().at(at.x, at.y, at.z),
              v.view<std::uint8_t>().at(at.x, at.y, at.z));
    EXPECT_EQ(wait_for_hints(*opened.pager, neighbours), neighbours);
    EXPECT_EQ(wait_for_faults(*opened.pager, 1), 1u);
}

}  // namespace
}  // namespace isowall::store
