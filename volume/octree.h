#pragma once
// Branch-on-need min/max octree (Wilhelms and Van Gelder; chapter 2.1.1).
//
// Stored as a pyramid of levels: level 0 holds one node per leaf brick of 4x4x4 cells, and each
// level above halves the node grid with a ceiling division. Node n of level l covers cells
// [n << (l+2), (n+1) << (l+2)) clipped to the volume, so children split at power-of-two
// boundaries and only branches that hold cells exist: the branch-on-need partition, without
// pointers. The two lowest levels of the full-depth tree (2x2x2 and single cells) are implicit:
// a walk reads their values from the volume. Depth = ceil(log2 D) + 1 for D cells on the
// longest side. Min/max are kept in the voxel type, so the overhead is 2/64 * 8/7 ~ 3.6% of the
// volume bytes for every type.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include <glm/vec3.hpp>

#include "core/thread_budget.h"
#include "volume/mapped_file.h"
#include "volume/volume.h"

namespace isowall {

// The geometry of the pyramid, independent of the voxel type.
struct OctreeShape {
    static constexpr int kLeafLog2 = 2;
    static constexpr int kLeafCells = 1 << kLeafLog2;

    struct Level {
        glm::ivec3 dims;
        std::size_t first;  // index of the level's first node
    };
    glm::ivec3 cell_dims{0};
    std::vector<Level> levels;  // [0] = leaf bricks, back() = root (1x1x1)
    std::size_t node_count = 0;

    static OctreeShape for_cells(glm::ivec3 cell_dims);
    std::size_t node_index(int level, glm::ivec3 n) const {
        const Level& L = levels[static_cast<std::size_t>(level)];
        return L.first + (static_cast<std::size_t>(n.z) * L.dims.y + n.y) * L.dims.x + n.x;
    }
    // First cell and one-past-last cell of node n at `level`, clipped to the volume.
    glm::ivec3 cell_begin(int level, glm::ivec3 n) const { return n << (level + kLeafLog2); }
    // Written out rather than glm::min: GCC 12 kept glm's out of line in the ray walk.
    glm::ivec3 cell_end(int level, glm::ivec3 n) const {
        const glm::ivec3 e = (n + 1) << (level + kLeafLog2);
        return {std::min(e.x, cell_dims.x), std::min(e.y, cell_dims.y), std::min(e.z, cell_dims.z)};
    }
    // ceil(log2 D) + 1 for the longest side D in cells: the depth of the full octree.
    int depth() const { return static_cast<int>(levels.size()) + kLeafLog2; }
};

// Where a cached octree comes from, for the cache key.
struct OctreeSource {
    std::filesystem::path volume_path;  // empty: not cacheable (generated volume)
    std::filesystem::path cache_dir;    // empty: no cache
    // Every other file the voxels come from (a detached header's data file): the key covers each,
    // so data replaced behind an unchanged header is never served a stale octree.
    std::vector<std::filesystem::path> data_files{};
    // The files the key digests: the volume's path and its data files. A URL ("scheme://...")
    // cannot be stat'ed: its objects' copies in the HTTP cache are its data files, and without
    // them (--no-cache) there is nothing to key on: empty.
    std::vector<std::filesystem::path> key_files() const {
        const bool remote = volume_path.native().find("://") != std::string::npos;
        if (remote && data_files.empty()) return {};
        std::vector<std::filesystem::path> files;
        if (!remote) files.push_back(volume_path);
        files.insert(files.end(), data_files.begin(), data_files.end());
        return files;
    }
    // A volume that carries its own octree (a store, store/open_store.h): the file, and
    // the key of the content it was built from (the store's identity, not where it lies, so a
    // moved or shared store keeps its octree). Empty/nullopt: the cache folder and the files'
    // key above.
    std::filesystem::path own_file{};
    std::optional<std::uint64_t> content_key{};
};

struct OctreeStats {
    double build_s = 0;       // 0 when mapped from the cache
    bool from_cache = false;  // true when the cache file was mapped
    std::filesystem::path cache_file;
    std::string cache_note;  // why the cache was not used or written, if it was not
};

// The range of a volume's finite voxels (NaN and +-infinity left out); `any` is false when there
// is none. Isovalues are checked against it.
struct FiniteRange {
    bool any = false;
    double min = 0, max = 0;
    void merge(double v) {
        if (!std::isfinite(v)) return;
        min = any ? std::min(min, v) : v;
        max = any ? std::max(max, v) : v;
        any = true;
    }
    void merge(const FiniteRange& r) {
        if (r.any) merge(r.min), merge(r.max);
    }
};

// NaN voxels are outside the surface for every isovalue: marching cubes classifies them below
// (value >= iso is false), so the octree orders them as -infinity too. A node of only NaN then
// has min = max = -inf and is never active, and a node where NaN meets a value >= iso is, as the
// cells it holds are crossed. Infinite voxels are ordinary ordered values.
template <class T>
constexpr T octree_key(T v) {
    if constexpr (std::is_floating_point_v<T>)
        return v != v ? -std::numeric_limits<T>::infinity() : v;
    else
        return v;
}

template <class T>
class MinMaxOctree {
  public:
    MinMaxOctree() = default;

    // Splits the leaf level over `budget` threads (the rank's budget; by default every core).
    static MinMaxOctree build(const VolumeView<T>& volume,
                              ThreadBudget budget = ThreadBudget::hardware());
    // Map a cache file when its key and checksum match the volume, else build and write it.
    static MinMaxOctree load_or_build(const VolumeView<T>& volume, const OctreeSource& source,
                                      OctreeStats* stats,
                                      ThreadBudget budget = ThreadBudget::hardware());

    // Built slab by slab in z (an import): start(), leaf_slab() for each slab of slices [z0, z1)
    // (ends multiples of kLeafCells; it reads slice z1 too; v.data may start at plane z_base;
    // disjoint slabs from any thread), then finish() with the merged ranges.
    static MinMaxOctree start(glm::ivec3 cell_dims);
    FiniteRange leaf_slab(const VolumeView<T>& v, int z0, int z1, int z_base = 0);
    void finish(const FiniteRange& finite);

    const OctreeShape& shape() const { return shape_; }
    int level_count() const { return static_cast<int>(shape_.levels.size()); }
    T min(int level, glm::ivec3 n) const { return nodes_[2 * shape_.node_index(level, n)]; }
    T max(int level, glm::ivec3 n) const { return nodes_[2 * shape_.node_index(level, n) + 1]; }
    T value_min() const { return min(level_count() - 1, glm::ivec3(0)); }
    T value_max() const { return max(level_count() - 1, glm::ivec3(0)); }
    // The finite voxels' range: value_min()/value_max() without NaN and infinity.
    const FiniteRange& finite_range() const { return finite_; }
    // A node holds part of the surface when some corner is >= iso and some is < iso.
    bool active(int level, glm::ivec3 n, double iso) const {
        const std::size_t i = 2 * shape_.node_index(level, n);
        return static_cast<double>(nodes_[i]) < iso && static_cast<double>(nodes_[i + 1]) >= iso;
    }
    std::span<const T> nodes() const { return nodes_; }
    std::size_t bytes() const { return nodes_.size_bytes(); }

  private:
    FiniteRange build_leaves(const VolumeView<T>& v, ThreadBudget budget);
    // Leaf rows [bz0, bz1): their nodes, and the finite range of their voxels (floats only).
    FiniteRange leaf_rows(const VolumeView<T>& v, int bz0, int bz1, int z_base = 0);
    void build_upper_levels();

    OctreeShape shape_;
    std::span<const T> nodes_;  // (min, max) per node, in node_index order
    std::vector<T> owned_;
    std::shared_ptr<MappedFile> mapped_;
    std::shared_ptr<void> check_;  // the background check of a store's octree, while it runs
    FiniteRange finite_;
};

// Cache file plumbing shared by every voxel type (octree_cache.cpp).
namespace octree_cache {
struct Key {
    std::uint32_t type = 0;
    glm::ivec3 dims{0};
    std::uint64_t sources = 0;  // digest of each source file's path, size, mtime, ctime, inode
};
// nullopt when a file cannot be stat'ed.
std::optional<Key> key_for(const std::vector<std::filesystem::path>& files, VoxelType type,
                           glm::ivec3 dims);
std::filesystem::path file_for(const std::filesystem::path& cache_dir,
                               const std::filesystem::path& volume_path);
// 64-bit FNV-1a over 8-byte words (the tail bytes zero-padded): a changed word always changes it.
std::uint64_t checksum(std::span<const std::byte> bytes);
// The header's checksum: the node bytes', continued over the value range's fields (a flipped bit
// in the range is a damaged file, not a range to serve).
std::uint64_t content_checksum(std::span<const std::byte> nodes, double finite_min,
                               double finite_max, std::uint64_t has_finite);
struct Hit {
    std::span<const std::byte> nodes;
    FiniteRange range;
};
// The node bytes of a cache file whose header matches `key` and whose nodes and value range match
// their checksum;
// nullopt (and `why`: stale, truncated or damaged) otherwise.
// With `check_content` false, the nodes' checksum is left to check_in_background.
std::optional<Hit> match(const MappedFile& file, const Key& key, std::size_t node_bytes,
                         std::string* why, bool check_content = true);
// Checks the nodes' checksum of a matched `file` on an idle-priority thread while the program goes
// on (a 30 GB store's octree is a gigabyte); on a mismatch prints one line naming `path` and ends
// the process (status 1). The returned guard waits for the check when it goes.
inline constexpr std::uintmax_t kBackgroundCheckBytes = std::uintmax_t(256) << 20;
std::shared_ptr<void> check_in_background(std::shared_ptr<const MappedFile> file,
                                          const std::filesystem::path& path,
                                          std::size_t node_bytes);
// Writes header + nodes to a temporary file and renames it into place (atomic for readers).
bool write(const std::filesystem::path& file, const Key& key, std::span<const std::byte> nodes,
           const FiniteRange& range, std::string* why);
// The default folder: $ISOWALL_CACHE_DIR, else $XDG_CACHE_HOME/isowall, else ~/.cache/isowall.
std::filesystem::path default_dir();
}  // namespace octree_cache

// Leaves: a brick of B cells spans B+1 voxels per axis (cells share their faces). Leaf slabs are
// independent; they are split over the budget (the build runs once per volume), each slab
// keeping its own finite range, merged at the end.
// Leaf (bx, by, bz) covers voxels [4b, 4b + 4] on each axis (clipped). For a row of leaves the 25
// voxel rows of its y and z windows are merged element by element (vectorised loops), then the x
// windows are taken; a bricked volume (a store's) is read voxel by voxel into the same merge.
template <class T>
FiniteRange MinMaxOctree<T>::leaf_rows(const VolumeView<T>& v, int bz0, int bz1, int z_base) {
    T* nodes = owned_.data();
    const auto& leaf = shape_.levels[0];
    constexpr int B = OctreeShape::kLeafCells;
    FiniteRange range;
    const auto nx = static_cast<std::size_t>(v.dims.x);
    std::vector<T> lo(nx), hi(nx), brick_row(v.bricked() ? nx : 0);
    for (int bz = bz0; bz < bz1; ++bz)
        for (int by = 0; by < leaf.dims.y; ++by) {
            const int z0 = bz * B, z1 = std::min(z0 + B, v.dims.z - 1);
            const int y0 = by * B, y1 = std::min(y0 + B, v.dims.y - 1);
            bool first = true;
            for (int z = z0; z <= z1; ++z)
                for (int y = y0; y <= y1; ++y, first = false) {
                    const T* row = v.data + (v.bricked() ? 0 : v.index(0, y, z - z_base));
                    if (v.bricked()) {
                        for (std::size_t x = 0; x < nx; ++x) brick_row[x] = v.at(int(x), y, z);
                        row = brick_row.data();
                    }
                    if constexpr (std::is_floating_point_v<T>)
                        for (std::size_t x = 0; x < nx; ++x) range.merge(double(row[x]));
                    if (first) {
                        for (std::size_t x = 0; x < nx; ++x) lo[x] = hi[x] = octree_key(row[x]);
                        continue;
                    }
                    for (std::size_t x = 0; x < nx; ++x) {
                        lo[x] = std::min(lo[x], octree_key(row[x]));
                        hi[x] = std::max(hi[x], octree_key(row[x]));
                    }
                }
            T* n = nodes + 2 * shape_.node_index(0, {0, by, bz});
            for (int bx = 0; bx < leaf.dims.x; ++bx) {
                const auto x0 = static_cast<std::size_t>(bx * B);
                const std::size_t x1 = std::min(x0 + B, nx - 1);
                T l = lo[x0], h = hi[x0];
                for (std::size_t x = x0 + 1; x <= x1; ++x) {
                    l = std::min(l, lo[x]);
                    h = std::max(h, hi[x]);
                }
                n[2 * bx] = l;
                n[2 * bx + 1] = h;
            }
        }
    return range;
}

template <class T>
FiniteRange MinMaxOctree<T>::build_leaves(const VolumeView<T>& v, ThreadBudget budget) {
    const auto& leaf = shape_.levels[0];
    const int threads = std::max(1, std::min(budget.usable(), leaf.dims.z));
    std::vector<FiniteRange> ranges(static_cast<std::size_t>(threads));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t)
        pool.emplace_back([&, t] {
            ranges[static_cast<std::size_t>(t)] =
                leaf_rows(v, leaf.dims.z * t / threads, leaf.dims.z * (t + 1) / threads);
        });
    ranges[0] = leaf_rows(v, 0, leaf.dims.z / threads);
    for (auto& th : pool) th.join();
    FiniteRange all;
    for (const FiniteRange& r : ranges) all.merge(r);
    return all;
}

template <class T>
MinMaxOctree<T> MinMaxOctree<T>::start(glm::ivec3 cell_dims) {
    MinMaxOctree o;
    o.shape_ = OctreeShape::for_cells(cell_dims);
    o.owned_.resize(2 * o.shape_.node_count);
    return o;
}

template <class T>
FiniteRange MinMaxOctree<T>::leaf_slab(const VolumeView<T>& v, int z0, int z1, int z_base) {
    const int rows = shape_.levels[0].dims.z;
    const int first = z0 / OctreeShape::kLeafCells;
    const int last = std::min(rows, (z1 + OctreeShape::kLeafCells - 1) / OctreeShape::kLeafCells);
    return first < last ? leaf_rows(v, first, last, z_base) : FiniteRange{};
}

template <class T>
void MinMaxOctree<T>::finish(const FiniteRange& finite) {
    build_upper_levels();
    nodes_ = owned_;
    finite_ = finite;
    if constexpr (!std::is_floating_point_v<T>) {
        finite_.merge(static_cast<double>(value_min()));
        finite_.merge(static_cast<double>(value_max()));
    }
}

template <class T>
void MinMaxOctree<T>::build_upper_levels() {
    T* nodes = owned_.data();
    for (int l = 1; l < level_count(); ++l) {
        const auto& L = shape_.levels[static_cast<std::size_t>(l)];
        const auto& C = shape_.levels[static_cast<std::size_t>(l - 1)];
        for (int z = 0; z < L.dims.z; ++z)
            for (int y = 0; y < L.dims.y; ++y)
                for (int x = 0; x < L.dims.x; ++x) {
                    const glm::ivec3 c0(2 * x, 2 * y, 2 * z);
                    const glm::ivec3 c1 = glm::min(c0 + 2, C.dims);
                    const std::size_t first = 2 * shape_.node_index(l - 1, c0);
                    T lo = nodes[first], hi = nodes[first + 1];
                    for (int cz = c0.z; cz < c1.z; ++cz)
                        for (int cy = c0.y; cy < c1.y; ++cy)
                            for (int cx = c0.x; cx < c1.x; ++cx) {
                                const std::size_t i = 2 * shape_.node_index(l - 1, {cx, cy, cz});
                                lo = std::min(lo, nodes[i]);
                                hi = std::max(hi, nodes[i + 1]);
                            }
                    const std::size_t i = 2 * shape_.node_index(l, {x, y, z});
                    nodes[i] = lo;
                    nodes[i + 1] = hi;
                }
    }
}

template <class T>
MinMaxOctree<T> MinMaxOctree<T>::build(const VolumeView<T>& v, ThreadBudget budget) {
    MinMaxOctree o;
    o.shape_ = OctreeShape::for_cells(v.cell_dims());
    o.owned_.resize(2 * o.shape_.node_count);
    o.finish(o.build_leaves(v, budget));
    return o;
}

template <class T>
MinMaxOctree<T> MinMaxOctree<T>::load_or_build(const VolumeView<T>& v, const OctreeSource& src,
                                               OctreeStats* stats, ThreadBudget budget) {
    OctreeStats local;
    OctreeStats& st = stats ? *stats : local;
    std::optional<octree_cache::Key> key;
    std::filesystem::path file;
    const std::vector<std::filesystem::path> sources = src.key_files();
    // A volume's own octree (a store's) is part of the volume, not of the cache: it is used
    // with the cache off too.
    if (src.own_file.empty() && (src.volume_path.empty() || src.cache_dir.empty())) {
        st.cache_note = src.volume_path.empty() ? "generated volume, not cached" : "cache disabled";
    } else if ((key = src.content_key ? std::optional(octree_cache::Key{
                                            static_cast<std::uint32_t>(voxel_type_of<T>()), v.dims,
                                            *src.content_key})
                      : sources.empty()
                          ? std::nullopt
                          : octree_cache::key_for(sources, voxel_type_of<T>(), v.dims))) {
        file = src.own_file.empty() ? octree_cache::file_for(src.cache_dir, src.volume_path)
                                    : src.own_file;
        st.cache_file = file;
        std::error_code ec;
        if (std::filesystem::exists(file, ec)) {
            try {
                // A store's octree past kBackgroundCheckBytes is mapped as it is read and
                // checked in the background; others are read and checked at once.
                const bool own = !src.own_file.empty() && std::filesystem::file_size(file, ec) >
                                                              octree_cache::kBackgroundCheckBytes;
                auto mapped = std::make_shared<MappedFile>(file, !own);
                const OctreeShape shape = OctreeShape::for_cells(v.cell_dims());
                const std::size_t count = 2 * shape.node_count;
                if (auto hit = octree_cache::match(*mapped, *key, count * sizeof(T), &st.cache_note,
                                                   !own)) {
                    MinMaxOctree o;
                    o.shape_ = shape;
                    if (own)
                        o.check_ =
                            octree_cache::check_in_background(mapped, file, count * sizeof(T));
                    o.mapped_ = std::move(mapped);
                    o.nodes_ = {reinterpret_cast<const T*>(hit->nodes.data()), count};
                    o.finite_ = hit->range;
                    st.from_cache = true;
                    return o;
                }
            } catch (const std::exception& e) {
                st.cache_note = e.what();
            }
        }
    } else {
        st.cache_note = "cannot stat the volume's files";
    }
    const auto t0 = std::chrono::steady_clock::now();
    MinMaxOctree o = build(v, budget);
    st.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::string write_note;
    if (key && !octree_cache::write(file, *key, std::as_bytes(o.nodes_), o.finite_, &write_note))
        st.cache_note += (st.cache_note.empty() ? "" : "; ") + write_note;
    return o;
}

}  // namespace isowall
