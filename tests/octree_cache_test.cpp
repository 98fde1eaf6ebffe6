// The octree cache is never trusted blindly (a key over every file the voxels come from, a
// checksum over the nodes), and the octree orders NaN voxels as outside for every isovalue.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>

#include "tests/test_util.h"
#include "volume/mapped_file.h"
#include "volume/octree.h"
#include "volume/volume.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;

constexpr glm::ivec3 kCacheDims{9, 6, 7};

void write_floats(const fs::path& p, const std::vector<float>& v) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
}

std::vector<float> ramp(float scale) {
    std::vector<float> v(std::size_t(kCacheDims.x) * kCacheDims.y * kCacheDims.z);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = scale * float(i % 50);
    return v;
}

// A detached header over v.raw and a cache folder: what `isowall` builds for a .nhdr.
struct CacheScene {
    fs::path dir, header, data, cache;
};

CacheScene make_cache_scene(const std::string& name) {
    CacheScene s;
    s.dir = test::scratch_dir(name);
    s.header = s.dir / "v.nhdr";
    s.data = s.dir / "v.raw";
    s.cache = s.dir / "cache";
    std::ofstream(s.header) << "NRRD0004\ntype: float\ndimension: 3\nsizes: 9 6 7\n"
                               "endian: little\nencoding: raw\ndata file: v.raw\n";
    write_floats(s.data, ramp(1.0f));
    return s;
}

struct Loaded {
    Volume volume;
    MinMaxOctree<float> octree;
    OctreeStats stats;
};

// Loads the header and maps or builds its octree, as ExtractionData does.
std::unique_ptr<Loaded> load(const CacheScene& s) {
    auto out = std::make_unique<Loaded>();
    out->volume = load_nrrd(s.header);
    OctreeSource src{s.header, s.cache};
    for (const auto& f : out->volume.files())
        if (f != s.header) src.data_files.push_back(f);
    out->octree = MinMaxOctree<float>::load_or_build(out->volume.view<float>(), src, &out->stats);
    return out;
}

// What may happen to the files behind a cache, and what the next load must say.
struct CacheCase {
    const char* name;
    void (*change)(const CacheScene& s, const fs::path& cache_file);
    const char* note;  // part of the cache note; "" for a hit
    float value_max;   // the range the next load must report
};

void replace_data_by_rename(const CacheScene& s, const fs::path&) {
    write_floats(s.dir / "new.raw", ramp(2.0f));
    fs::rename(s.dir / "new.raw", s.data);
}

void rewrite_data_same_mtime(const CacheScene& s, const fs::path&) {
    // Same size, same inode, same modification time: only the change time tells.
    const auto mtime = fs::last_write_time(s.data);
    write_floats(s.data, ramp(3.0f));
    fs::last_write_time(s.data, mtime);
}

void flip_node_byte(const CacheScene&, const fs::path& cache_file) {
    std::fstream f(cache_file, std::ios::binary | std::ios::in | std::ios::out);
    f.seekg(-5, std::ios::end);
    const char c = static_cast<char>(f.get() ^ 0x10);
    f.seekp(-5, std::ios::end);
    f.put(c);
}

// A bit of the header's value range (the range lay outside the checksum, so a flipped
// bit was served as the volume's range). `offset`: a byte of finite_min (56..63) or finite_max
// (64..71) in the header.
void flip_header_byte(const fs::path& cache_file, std::streamoff offset) {
    std::fstream f(cache_file, std::ios::binary | std::ios::in | std::ios::out);
    f.seekg(offset);
    const char c = static_cast<char>(f.get() ^ 0x10);
    f.seekp(offset);
    f.put(c);
}

void flip_range_max(const CacheScene&, const fs::path& cache_file) {
    flip_header_byte(cache_file, 70);  // 49.0 becomes 98.0
}

void flip_range_min(const CacheScene&, const fs::path& cache_file) {
    flip_header_byte(cache_file, 63);
}

void truncate_cache(const CacheScene&, const fs::path& cache_file) {
    fs::resize_file(cache_file, fs::file_size(cache_file) - 8);
}

void empty_cache(const CacheScene&, const fs::path& cache_file) {
    fs::resize_file(cache_file, 0);
}

void nothing(const CacheScene&, const fs::path&) {}

TEST(OctreeCache, NeverServesNodesThatDoNotMatchTheirFilesOrChecksum) {
    const CacheCase cases[] = {
        {"unchanged", nothing, "", 49.0f},
        {"data replaced behind the header", replace_data_by_rename, "stale", 98.0f},
        {"data rewritten, mtime restored", rewrite_data_same_mtime, "stale", 147.0f},
        {"a node byte flipped", flip_node_byte, "damaged", 49.0f},
        {"the range's maximum flipped", flip_range_max, "damaged", 49.0f},
        {"the range's minimum flipped", flip_range_min, "damaged", 49.0f},
        {"cache truncated", truncate_cache, "truncated", 49.0f},
        {"cache emptied", empty_cache, "stale", 49.0f},
    };
    for (const CacheCase& c : cases) {
        SCOPED_TRACE(c.name);
        const CacheScene s = make_cache_scene("octree_cache_trust");
        const auto first = load(s);
        ASSERT_FALSE(first->stats.from_cache);
        ASSERT_TRUE(fs::exists(first->stats.cache_file)) << first->stats.cache_note;
        c.change(s, first->stats.cache_file);
        const auto next = load(s);
        const bool hit = std::string(c.note).empty();
        EXPECT_EQ(next->stats.from_cache, hit) << next->stats.cache_note;
        EXPECT_NE(next->stats.cache_note.find(c.note), std::string::npos) << next->stats.cache_note;
        EXPECT_EQ(next->octree.finite_range().max, c.value_max);
        EXPECT_EQ(next->octree.value_max(), c.value_max);
        // Whatever happened, the nodes equal a fresh build, and the rebuilt file is a hit again.
        const auto fresh = MinMaxOctree<float>::build(next->volume.view<float>());
        ASSERT_EQ(fresh.nodes().size(), next->octree.nodes().size());
        EXPECT_TRUE(
            std::equal(fresh.nodes().begin(), fresh.nodes().end(), next->octree.nodes().begin()));
        EXPECT_TRUE(load(s)->stats.from_cache);
    }
}

TEST(OctreeCache, ChecksumSeesEveryWordChange) {
    std::vector<std::byte> bytes(77);
    std::mt19937 rng(5);
    for (auto& b : bytes) b = std::byte(rng() & 0xff);
    const std::uint64_t base = octree_cache::checksum(bytes);
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        for (int bit = 0; bit < 8; ++bit) {
            bytes[i] ^= std::byte(1 << bit);
            EXPECT_NE(octree_cache::checksum(bytes), base) << "byte " << i << " bit " << bit;
            bytes[i] ^= std::byte(1 << bit);
        }
    }
    EXPECT_NE(octree_cache::checksum(std::span(bytes).first(76)), base);  // length counts too
}

// Volumes with NaN and infinity: the octree orders NaN as -infinity, so a node of only NaN is
// never active, and the finite range leaves both out.
struct NanCase {
    const char* name;
    void (*fill)(std::vector<float>& v, glm::ivec3 d);
};

std::size_t at(glm::ivec3 d, int x, int y, int z) {
    return (std::size_t(z) * d.y + y) * d.x + x;
}

void nan_block(std::vector<float>& v, glm::ivec3 d) {
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 9; ++y)
            for (int x = 0; x < 10; ++x) v[at(d, x, y, z)] = std::nanf("");
}

void scattered_nonfinite(std::vector<float>& v, glm::ivec3) {
    const float kinds[] = {std::nanf(""), INFINITY, -INFINITY};
    for (std::size_t i = 0; i < v.size(); i += 7) v[i] = kinds[i % 3];
}

void all_nan_but_one(std::vector<float>& v, glm::ivec3 d) {
    std::fill(v.begin(), v.end(), std::nanf(""));
    v[at(d, 3, 4, 5)] = 42.0f;
}

// A store's octree past 256 MiB is checked on a background thread while the first frame runs
// (octree_cache::check_in_background): a sound one lets the program go on; a damaged one ends it
// with one line naming the file and status 1, however far the program has got.
TEST(OctreeCache, ABackgroundCheckPassesASoundOctreeAndEndsTheProgramOnADamagedOne) {
    const fs::path dir = test::scratch_dir("octree_background");
    const octree_cache::Key key{7, kCacheDims, 42};
    std::vector<std::byte> nodes(4096);
    for (std::size_t i = 0; i < nodes.size(); ++i) nodes[i] = std::byte(i * 31);
    FiniteRange range;
    range.merge(1.0);
    range.merge(9.0);
    const fs::path file = dir / "octree.isowall";
    ASSERT_TRUE(octree_cache::write(file, key, nodes, range, nullptr));
    auto sound = std::make_shared<const MappedFile>(file);
    // Sound: the check ends quietly when its guard goes.
    octree_cache::check_in_background(sound, file, nodes.size()).reset();
    sound.reset();

    // One node byte flipped: match sees it only when asked to check the content ...
    {
        std::fstream f(file, std::ios::binary | std::ios::in | std::ios::out);
        f.seekp(128 + 1000);
        f.put('\x7f');
    }
    const auto damaged = std::make_shared<const MappedFile>(file);
    EXPECT_FALSE(octree_cache::match(*damaged, key, nodes.size(), nullptr));
    EXPECT_TRUE(octree_cache::match(*damaged, key, nodes.size(), nullptr, false));
    // ... and the background check ends the program, naming the file.
    EXPECT_EXIT(octree_cache::check_in_background(damaged, file, nodes.size()).reset(),
                ::testing::ExitedWithCode(1), "octree.isowall: the octree is damaged");
}

TEST(OctreeNonFinite, NanIsBelowEveryIsovalueAndTheRangeIsFinite) {
    const glm::ivec3 d(21, 18, 13);
    const NanCase cases[] = {{"nan block", nan_block},
                             {"scattered nan and inf", scattered_nonfinite},
                             {"all nan but one", all_nan_but_one}};
    for (const NanCase& c : cases) {
        SCOPED_TRACE(c.name);
        std::vector<float> data(std::size_t(d.x) * d.y * d.z);
        for (std::size_t i = 0; i < data.size(); ++i) data[i] = float(i % 97) - 40.0f;
        c.fill(data, d);
        const VolumeView<float> v{data.data(), d, glm::vec3(1)};
        const auto o = MinMaxOctree<float>::build(v, ThreadBudget{3});
        FiniteRange want;
        for (float x : data) want.merge(double(x));
        EXPECT_EQ(o.finite_range().any, want.any);
        EXPECT_EQ(o.finite_range().min, want.min);
        EXPECT_EQ(o.finite_range().max, want.max);
        // Every leaf against brute force with NaN as -infinity.
        const auto& shape = o.shape();
        const auto& leaf = shape.levels[0];
        for (int z = 0; z < leaf.dims.z; ++z)
            for (int y = 0; y < leaf.dims.y; ++y)
                for (int x = 0; x < leaf.dims.x; ++x) {
                    const glm::ivec3 n(x, y, z), b = shape.cell_begin(0, n),
                                                 e = shape.cell_end(0, n);
                    float lo = INFINITY, hi = -INFINITY;
                    bool only_nan = true;
                    for (int k = b.z; k <= e.z; ++k)
                        for (int j = b.y; j <= e.y; ++j)
                            for (int i = b.x; i <= e.x; ++i) {
                                const float f = v.at(i, j, k);
                                only_nan = only_nan && std::isnan(f);
                                lo = std::min(lo, std::isnan(f) ? -INFINITY : f);
                                hi = std::max(hi, std::isnan(f) ? -INFINITY : f);
                            }
                    ASSERT_EQ(o.min(0, n), lo) << x << "," << y << "," << z;
                    ASSERT_EQ(o.max(0, n), hi) << x << "," << y << "," << z;
                    for (double iso : {-1e30, -40.0, 0.0, 42.0, 1e30}) {
                        EXPECT_TRUE(!only_nan || !o.active(0, n, iso)) << iso;
                    }
                }
    }
}

}  // namespace
}  // namespace isowall
