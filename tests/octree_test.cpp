// The min/max octree agrees with brute force on every node, for odd sizes and real data.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "tests/test_util.h"
#include "volume/octree.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

template <class T>
void expect_nodes_match_brute_force(const VolumeView<T>& v, const MinMaxOctree<T>& o, int samples,
                                    std::mt19937& rng) {
    const auto& shape = o.shape();
    for (int l = 0; l < o.level_count(); ++l) {
        const auto& L = shape.levels[static_cast<std::size_t>(l)];
        const std::size_t count = std::size_t(L.dims.x) * L.dims.y * L.dims.z;
        const bool all = samples <= 0 || count <= std::size_t(samples);
        for (std::size_t k = 0; k < (all ? count : std::size_t(samples)); ++k) {
            const std::size_t i =
                all ? k : std::uniform_int_distribution<std::size_t>(0, count - 1)(rng);
            const glm::ivec3 n(int(i % L.dims.x), int(i / L.dims.x % L.dims.y),
                               int(i / L.dims.x / L.dims.y));
            const glm::ivec3 b = shape.cell_begin(l, n), e = shape.cell_end(l, n);
            ASSERT_TRUE(b.x < e.x && b.y < e.y && b.z < e.z) << "empty node at level " << l;
            T lo = v.at(b.x, b.y, b.z), hi = lo;
            for (int z = b.z; z <= e.z; ++z)
                for (int y = b.y; y <= e.y; ++y)
                    for (int x = b.x; x <= e.x; ++x) {
                        lo = std::min(lo, v.at(x, y, z));
                        hi = std::max(hi, v.at(x, y, z));
                    }
            ASSERT_EQ(o.min(l, n), lo)
                << "level " << l << " node " << n.x << "," << n.y << "," << n.z;
            ASSERT_EQ(o.max(l, n), hi)
                << "level " << l << " node " << n.x << "," << n.y << "," << n.z;
        }
    }
}

TEST(Octree, DepthIsCeilLog2PlusOne) {
    EXPECT_EQ(OctreeShape::for_cells({1, 1, 1}).depth(), 3);  // leaf brick level + 2 implicit
    EXPECT_EQ(OctreeShape::for_cells({4, 4, 4}).depth(), 3);
    EXPECT_EQ(OctreeShape::for_cells({511, 511, 233}).depth(), 10);  // ceil(log2 511) + 1
    EXPECT_EQ(OctreeShape::for_cells({512, 100, 100}).depth(), 10);
    EXPECT_EQ(OctreeShape::for_cells({513, 100, 100}).depth(), 11);
}

TEST(Octree, RandomVolumesOfOddSizesMatchBruteForce) {
    std::mt19937 rng(7);
    for (glm::ivec3 d : {glm::ivec3(2, 2, 2), glm::ivec3(3, 5, 7), glm::ivec3(17, 33, 9),
                         glm::ivec3(65, 40, 31), glm::ivec3(6, 129, 2)}) {
        std::vector<std::int16_t> data(std::size_t(d.x) * d.y * d.z);
        for (auto& x : data)
            x = static_cast<std::int16_t>(std::uniform_int_distribution<int>(-30000, 30000)(rng));
        VolumeView<std::int16_t> v{data.data(), d, glm::vec3(1)};
        auto o = MinMaxOctree<std::int16_t>::build(v);
        SCOPED_TRACE(::testing::Message() << "dims " << d.x << "x" << d.y << "x" << d.z);
        expect_nodes_match_brute_force(v, o, 0, rng);
        EXPECT_EQ(o.value_min(), *std::min_element(data.begin(), data.end()));
        EXPECT_EQ(o.value_max(), *std::max_element(data.begin(), data.end()));
    }
}

// Random sub-boxes (crops) of a volume, each with its own octree.
template <class T>
void check_random_crops(const VolumeView<T>& v, int crops, std::mt19937& rng) {
    for (int c = 0; c < crops; ++c) {
        glm::ivec3 lo, size;
        for (int a = 0; a < 3; ++a) {
            size[a] = std::uniform_int_distribution<int>(2, std::min(v.dims[a], 90))(rng);
            lo[a] = std::uniform_int_distribution<int>(0, v.dims[a] - size[a])(rng);
        }
        std::vector<T> crop(std::size_t(size.x) * size.y * size.z);
        for (int z = 0; z < size.z; ++z)
            for (int y = 0; y < size.y; ++y)
                for (int x = 0; x < size.x; ++x)
                    crop[(std::size_t(z) * size.y + y) * size.x + x] =
                        v.at(lo.x + x, lo.y + y, lo.z + z);
        VolumeView<T> cv{crop.data(), size, v.spacing};
        auto o = MinMaxOctree<T>::build(cv);
        SCOPED_TRACE(::testing::Message() << "crop at " << lo.x << "," << lo.y << "," << lo.z
                                          << " size " << size.x << "x" << size.y << "x" << size.z);
        expect_nodes_match_brute_force(cv, o, 200, rng);
    }
}

TEST(Octree, PhantomCropsMatchBruteForce) {
    std::mt19937 rng(11);
    const Volume p = make_phantom();
    check_random_crops(p.view<std::uint8_t>(), 8, rng);
    auto o = MinMaxOctree<std::uint8_t>::build(p.view<std::uint8_t>());
    expect_nodes_match_brute_force(p.view<std::uint8_t>(), o, 300, rng);
    // The overhead promise: at most 1/8 of the volume bytes.
    EXPECT_LE(double(o.bytes()), double(p.bytes().size()) / 8.0);
}

TEST(Octree, SharedCtHeadMatchesBruteForce) {
    const auto data = test::shared_data_dir();
    if (!data) GTEST_SKIP() << "../shared/data is absent: skipping the CT head";
    std::mt19937 rng(13);
    const Volume v = load_nrrd(*data / "cthead.nhdr");
    const auto view = v.view<std::uint16_t>();
    auto o = MinMaxOctree<std::uint16_t>::build(view);
    expect_nodes_match_brute_force(view, o, 300, rng);
    EXPECT_EQ(double(o.value_max()), 3272.0);
    check_random_crops(view, 6, rng);
}

TEST(Octree, CacheIsMappedOnTheSecondRunAndRebuiltWhenTheVolumeChanges) {
    const auto dir = test::scratch_dir("octree_cache");
    const glm::ivec3 d(20, 11, 9);
    std::vector<float> data(std::size_t(d.x) * d.y * d.z);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = float(i % 37);
    const auto file = dir / "v.raw";
    {
        std::ofstream out(file, std::ios::binary);
        out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size() * 4));
    }
    VolumeView<float> v{data.data(), d, glm::vec3(1)};
    OctreeSource src{file, dir / "cache"};
    OctreeStats first, second, third;
    auto a = MinMaxOctree<float>::load_or_build(v, src, &first);
    EXPECT_FALSE(first.from_cache) << first.cache_note;
    ASSERT_TRUE(std::filesystem::exists(first.cache_file));
    auto b = MinMaxOctree<float>::load_or_build(v, src, &second);
    EXPECT_TRUE(second.from_cache) << second.cache_note;
    ASSERT_EQ(a.nodes().size(), b.nodes().size());
    EXPECT_TRUE(std::equal(a.nodes().begin(), a.nodes().end(), b.nodes().begin()));
    // A changed file (new size and mtime) must not reuse the old cache.
    {
        std::ofstream out(file, std::ios::binary | std::ios::app);
        out << "x";
    }
    auto c = MinMaxOctree<float>::load_or_build(v, src, &third);
    EXPECT_FALSE(third.from_cache);
}

}  // namespace
}  // namespace isowall
