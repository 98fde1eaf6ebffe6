// The meta-cell errors of adaptive resolution (volume/lod_error.h): the byte code, the
// row-by-row table against the plain voxel-by-voxel statement, and what the bound says about
// smooth fields, spikes and NaN.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "extract/adaptive.h"
#include "volume/lod_error.h"
#include "volume/volume.h"

namespace isowall {
namespace {

template <class T>
VolumeView<T> view_of(const std::vector<T>& data, glm::ivec3 dims) {
    VolumeView<T> v;
    v.data = data.data();
    v.dims = dims;
    return v;
}

TEST(LodCode, IsACeilingWithinFivePercent) {
    EXPECT_EQ(lod_code::encode(0), lod_code::kExact);
    EXPECT_EQ(lod_code::decode(lod_code::kExact), 0.0f);
    EXPECT_EQ(lod_code::encode(std::numeric_limits<double>::infinity()), lod_code::kNever);
    EXPECT_EQ(lod_code::encode(std::nan("")), lod_code::kNever);
    EXPECT_EQ(lod_code::decode(lod_code::kNever), std::numeric_limits<float>::infinity());
    for (double e = 0.004; e < 200; e *= 1.37) {
        const float back = lod_code::decode(lod_code::encode(e));
        EXPECT_GE(back, e * (1 - 1e-6)) << e;
        EXPECT_LT(back, e * 1.05) << e;
    }
    EXPECT_EQ(lod_code::encode(1e9), lod_code::kNever);  // past the scale: never coarse
}

TEST(LodErrors, RowByRowTableEqualsTheVoxelByVoxelStatement) {
    // Noise over a ramp, in a volume whose sides are no multiple of 8: every complete meta-cell's
    // code equals the plain one (within one step of float rounding); incomplete ones are never.
    const glm::ivec3 dims(21, 18, 27), cells = dims - 1;
    std::vector<float> data(std::size_t(dims.x) * dims.y * dims.z);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> noise(-3.0f, 3.0f);
    for (int z = 0, i = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x, ++i) data[std::size_t(i)] = 4.0f * x + y + noise(rng);
    const auto v = view_of(data, dims);
    const std::vector<std::uint8_t> codes = build_lod_codes(v, ThreadBudget{2});
    ASSERT_EQ(codes.size(), LodErrors::byte_count(cells));
    const LodErrors table(cells, codes);
    int compared = 0;
    for (int level = 1; level <= 3; ++level) {
        const int s = 1 << level;
        for (int z = 0; z + s <= cells.z; z += s)
            for (int y = 0; y + s <= cells.y; y += s)
                for (int x = 0; x + s <= cells.x; x += s) {
                    const glm::ivec3 b(x, y, z);
                    if (level == 1) {
                        // The leaf's byte is the worst of its eight: at least this one's.
                        const glm::ivec3 leaf = b & ~3;
                        if (leaf.x + 4 > cells.x || leaf.y + 4 > cells.y || leaf.z + 4 > cells.z) {
                            EXPECT_EQ(table.code(1, b), lod_code::kNever);
                            continue;
                        }
                        EXPECT_GE(int(table.code(1, b)) + 1, int(meta_cell_code(v, b, 1)))
                            << x << "," << y << "," << z;
                    } else {
                        EXPECT_NEAR(int(table.code(level, b)), int(meta_cell_code(v, b, level)), 1)
                            << "level " << level << " at " << x << "," << y << "," << z;
                    }
                    ++compared;
                }
    }
    EXPECT_GT(compared, 100);
    // The ramp's slope is 4 per cell and the noise at most 3: every error is finite and under the
    // level's size.
    EXPECT_LT(table.cells(3, {8, 8, 8}), 8.0f);
    // A meta-cell past the upper faces is never a unit.
    EXPECT_EQ(table.code(3, {16, 8, 16}), lod_code::kNever);  // x 16 + 8 > 20 cells
}

TEST(LodErrors, ALinearFieldIsExactAndASpikeIsNeverCoarse) {
    const glm::ivec3 dims(17, 17, 17), cells = dims - 1;
    std::vector<std::uint8_t> data(std::size_t(dims.x) * dims.y * dims.z);
    for (int z = 0, i = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x, ++i)
                data[std::size_t(i)] = std::uint8_t(2 * x + 3 * y + 5 * z);
    std::vector<std::uint8_t> codes = build_lod_codes(view_of(data, dims), ThreadBudget{1});
    LodErrors linear(cells, codes);
    for (int level = 1; level <= 3; ++level)
        EXPECT_EQ(linear.code(level, {8, 0, 8}), lod_code::kExact) << level;
    // One voxel of 255 inside a flat meta-cell of zeros (a tube seen across): the corners are
    // flat, the spike is all T misses, at every level that holds it.
    std::fill(data.begin(), data.end(), std::uint8_t{0});
    data[(std::size_t(5) * dims.y + 5) * dims.x + 5] = 255;
    codes = build_lod_codes(view_of(data, dims), ThreadBudget{1});
    LodErrors spike(cells, codes);
    EXPECT_EQ(spike.code(1, {4, 4, 4}), lod_code::kNever);
    EXPECT_EQ(spike.code(2, {4, 4, 4}), lod_code::kNever);
    EXPECT_EQ(spike.code(3, {0, 0, 0}), lod_code::kNever);
    EXPECT_EQ(spike.code(3, {8, 8, 8}), lod_code::kExact);  // far from it: still flat
}

TEST(LodErrors, NanIsNeverCoarse) {
    const glm::ivec3 dims(9, 9, 9), cells = dims - 1;
    std::vector<float> data(std::size_t(dims.x) * dims.y * dims.z, 1.0f);
    data[(std::size_t(6) * dims.y + 2) * dims.x + 3] = std::nanf("");
    const std::vector<std::uint8_t> codes = build_lod_codes(view_of(data, dims), ThreadBudget{1});
    const LodErrors t(cells, codes);
    EXPECT_EQ(t.code(3, {0, 0, 0}), lod_code::kNever);
    EXPECT_EQ(t.code(2, {0, 0, 4}), lod_code::kNever);
    EXPECT_EQ(t.code(2, {4, 4, 0}), lod_code::kExact);
}

TEST(LodErrors, TheMapTakesAMetaCellOnlyWhereItsErrorProjectsUnderTheBound) {
    // Orthographic, one pixel = 2 cells: level 1 (2 cells) passes the size rule at 2 px.
    const glm::ivec3 dims(17, 17, 17), cells = dims - 1;
    std::vector<std::uint8_t> codes(LodErrors::byte_count(cells), lod_code::kExact);
    const LodErrors t(cells, codes);
    ResolutionLevels levels = uniform_levels(1);
    levels.error_px = 0.5f;
    levels.pixel_size = 2.0f;
    codes[0] = lod_code::encode(0.9);  // leaf 0's level-1 error: 0.45 px, under 0.5
    EXPECT_TRUE(ResolutionMap(levels, glm::vec3(1), cells, &t).coarse_enough({0, 0, 0}, 1));
    codes[0] = lod_code::encode(1.2);  // 0.6 px: over
    EXPECT_FALSE(ResolutionMap(levels, glm::vec3(1), cells, &t).coarse_enough({0, 0, 0}, 1));
    // Without the table, or with no bound, the size rule decides alone.
    EXPECT_TRUE(ResolutionMap(levels, glm::vec3(1), cells).coarse_enough({0, 0, 0}, 1));
    levels.error_px = std::numeric_limits<float>::infinity();
    EXPECT_TRUE(ResolutionMap(levels, glm::vec3(1), cells, &t).coarse_enough({0, 0, 0}, 1));
}

}  // namespace
}  // namespace isowall

namespace isowall {
namespace {

// The table is cached beside the octree (same key, `.lod`): built once, then mapped; a damaged
// file is rebuilt with a note, never served.
TEST(LodErrors, CacheMapsTheTableAndRebuildsADamagedOne) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("isowall_lod_cache_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto volume_file = dir / "v.raw";
    std::ofstream(volume_file) << "voxels";  // the key stats the file; its bytes are not read
    OctreeSource src{volume_file, dir / "cache"};
    const glm::ivec3 dims(17, 9, 9);
    const std::vector<std::uint8_t> want(LodErrors::byte_count(dims - 1), 7);
    int builds = 0;
    auto build = [&] {
        ++builds;
        return want;
    };
    const LodTable first = load_or_build_lod(src, VoxelType::u8, dims, build);
    EXPECT_FALSE(first.from_cache);
    const LodTable second = load_or_build_lod(src, VoxelType::u8, dims, build);
    EXPECT_TRUE(second.from_cache) << second.cache_note;
    EXPECT_EQ(builds, 1);
    ASSERT_EQ(second.errors.codes().size(), want.size());
    EXPECT_TRUE(std::equal(want.begin(), want.end(), second.errors.codes().begin()));
    // Flip a code byte in the file: rebuilt, with a note.
    std::filesystem::path file;
    for (const auto& e : std::filesystem::directory_iterator(dir / "cache"))
        if (e.path().extension() == ".lod") file = e.path();
    ASSERT_FALSE(file.empty());
    {
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(-1, std::ios::end);
        f.put(char(8));
    }
    const LodTable third = load_or_build_lod(src, VoxelType::u8, dims, build);
    EXPECT_FALSE(third.from_cache);
    EXPECT_EQ(builds, 2);
    EXPECT_NE(third.cache_note.find("damaged"), std::string::npos) << third.cache_note;
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace isowall
