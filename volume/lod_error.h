#pragma once
// How far a meta-cell's surface may lie from the full-resolution surface, for any isovalue: the
// bound adaptive resolution (extract/adaptive.h) projects to pixels to pick each unit's
// level, so that a meta-cell is drawn coarse only where the eye cannot tell.
//
// A meta-cell of level i (2^i cells a side at a multiple of 2^i) is extracted from its eight
// corners, that is, from the trilinear field T those corners span. The fine field f differs from T
// by at most delta = max |f - T| over the meta-cell's (2^i + 1)^3 voxels, so the fine surface at
// any isovalue lies where |T - iso| <= delta: within delta / |grad T| of T's surface. That ratio,
// in cells, is the meta-cell's error. It needs no isovalue, so it is computed once per volume:
//   - a field that is linear across the meta-cell (a smooth surface, or a volume resampled from a
//     coarser one) has error 0, and is drawn coarse at any distance;
//   - a twig, vessel or sheet thinner than the meta-cell is a spike that T cannot follow: delta is
//     its height while T stays nearly flat, so the error is large and the meta-cell stays fine;
//   - a NaN or infinite voxel makes the error infinite (never coarse).
// |grad T| is taken at the meta-cell's centre in value per cell, so the error is in cells; times
// the largest spacing component it bounds the object-space distance from above.
//
// Stored one byte per unit (a ceiling on a log scale: 16 steps per octave, 4.4% apart), per leaf
// brick of the octree (4^3 cells) the largest error of its eight level-1 meta-cells and its own
// level-2 error, and per node of the octree's level 1 (8^3 cells) the level-3 error: 2/64 + 1/512
// bytes per cell, 3.3% of a uint8 volume. Meta-cells that do not fit inside the volume are never
// units and get the infinite code.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/thread_budget.h"
#include "volume/mapped_file.h"
#include "volume/octree.h"
#include "volume/volume.h"

namespace isowall {

// The byte code of an error: 0 is exactly 0, 255 is infinite (or not a unit), and code q in
// [1, 254] stands for 2^((q - 128) / 16) cells, the ceiling of the errors it encodes.
namespace lod_code {
inline constexpr std::uint8_t kExact = 0;
inline constexpr std::uint8_t kNever = 255;

inline std::uint8_t encode(double cells) {
    if (!(cells > 0)) return cells == 0 ? kExact : kNever;  // NaN: never
    if (!std::isfinite(cells)) return kNever;
    const double q = std::ceil(16.0 * std::log2(cells)) + 128.0;
    if (q > 254.0) return kNever;  // past the scale (about 230 cells): never coarse
    return static_cast<std::uint8_t>(std::max(q, 1.0));
}

inline float decode(std::uint8_t code) {
    if (code == kExact) return 0.0f;
    if (code == kNever) return std::numeric_limits<float>::infinity();
    return std::exp2((static_cast<float>(code) - 128.0f) / 16.0f);
}
}  // namespace lod_code

// The per-volume table of meta-cell errors (see above); cheap to copy a view of.
class LodErrors {
  public:
    LodErrors() = default;
    // Over `codes` laid out as described: leaf_count * 2 bytes, then l1_count bytes.
    LodErrors(glm::ivec3 cell_dims, std::span<const std::uint8_t> codes);

    // The bytes a volume of `cell_dims` cells needs.
    static std::size_t byte_count(glm::ivec3 cell_dims);
    static glm::ivec3 leaf_dims(glm::ivec3 cell_dims);
    static glm::ivec3 l1_dims(glm::ivec3 cell_dims);

    bool empty() const { return codes_.empty(); }
    std::span<const std::uint8_t> codes() const { return codes_; }

    // The error code of the meta-cell of `level` in [1, 3] whose first cell is `base` (a
    // multiple of 2^level). Level 1 answers for the whole leaf brick around it (its largest).
    std::uint8_t code(int level, glm::ivec3 base) const {
        if (level >= 3) {
            const glm::ivec3 n = base >> 3;
            return codes_[l1_first_ + (static_cast<std::size_t>(n.z) * l1_.y + n.y) * l1_.x + n.x];
        }
        const glm::ivec3 n = base >> 2;
        const std::size_t leaf = (static_cast<std::size_t>(n.z) * leaf_.y + n.y) * leaf_.x + n.x;
        return codes_[2 * leaf + static_cast<std::size_t>(level - 1)];
    }
    float cells(int level, glm::ivec3 base) const { return cells_[code(level, base)]; }

  private:
    std::array<float, 256> cells_{};  // lod_code::decode of every code
    glm::ivec3 leaf_{0}, l1_{0};
    std::size_t l1_first_ = 0;
    std::span<const std::uint8_t> codes_;
};

namespace lod_detail {

// The largest |f - T| of every complete meta-cell of S cells a side in slab `bz` (z cells
// [bz * S, bz * S + S]), into delta[by * m.x + bx] for the m.x by m.y complete meta-cells of the
// slab. The volume is read row by row: along a row of voxels T is linear between the meta-cells'
// faces, so the inner loop is a multiply-add and a subtraction per voxel. NaN or infinity gives
// NaN (never coarse).
template <int S, class T>
void slab_deltas(const VolumeView<T>& v, int bz, glm::ivec2 m, std::vector<float>& delta,
                 std::vector<float>& scratch) {
    const int z0 = bz * S;
    constexpr float inv = 1.0f / static_cast<float>(S);
    const std::size_t n = static_cast<std::size_t>(m.x) + 1;
    delta.assign(static_cast<std::size_t>(m.x) * m.y, 0.0f);
    scratch.resize(5 * n);
    float* c00 = scratch.data();  // T's corners on the faces x = k * S of one meta-cell row
    float* c10 = c00 + n;
    float* c01 = c10 + n;
    float* c11 = c01 + n;
    float* edge = c11 + n;  // T on those faces along one row of voxels
    for (int by = 0; by < m.y; ++by) {
        const int y0 = by * S;
        for (std::size_t k = 0; k < n; ++k) {
            const int x = static_cast<int>(k) * S;
            c00[k] = static_cast<float>(v.at(x, y0, z0));
            c10[k] = static_cast<float>(v.at(x, y0 + S, z0));
            c01[k] = static_cast<float>(v.at(x, y0, z0 + S));
            c11[k] = static_cast<float>(v.at(x, y0 + S, z0 + S));
        }
        float* d = delta.data() + static_cast<std::size_t>(by) * m.x;
        for (int z = 0; z <= S; ++z)
            for (int y = 0; y <= S; ++y) {
                const float u = static_cast<float>(y) * inv, w = static_cast<float>(z) * inv;
                for (std::size_t k = 0; k < n; ++k) {
                    const float lo = c00[k] + (c10[k] - c00[k]) * u;
                    const float hi = c01[k] + (c11[k] - c01[k]) * u;
                    edge[k] = lo + (hi - lo) * w;
                }
                // A bricked volume (a store's) is read voxel by voxel.
                const T* row = v.bricked() ? nullptr : v.data + v.index(0, y0 + y, z0 + z);
                for (int k = 0; k < m.x; ++k) {
                    const float a = edge[k], slope = (edge[k + 1] - a) * inv;
                    const T* r = row ? row + k * S : nullptr;
                    float worst = d[k];
                    for (int x = 0; x <= S; ++x) {
                        const T value = r ? r[x] : v.at(k * S + x, y0 + y, z0 + z);
                        const float e = std::abs(static_cast<float>(value) -
                                                 (a + slope * static_cast<float>(x)));
                        if (e > worst || e != e) worst = e;  // NaN sticks
                    }
                    d[k] = worst;
                }
            }
    }
}

template <class T>
void slab_deltas(const VolumeView<T>& v, int level, int bz, glm::ivec2 m, std::vector<float>& delta,
                 std::vector<float>& scratch) {
    if (level == 1)
        slab_deltas<2>(v, bz, m, delta, scratch);
    else if (level == 2)
        slab_deltas<4>(v, bz, m, delta, scratch);
    else
        slab_deltas<8>(v, bz, m, delta, scratch);
}

// grad T at the meta-cell's centre, in value per cell, from its eight corners.
template <class T>
glm::vec3 centre_gradient(const VolumeView<T>& v, glm::ivec3 b, int s) {
    float c[8];
    for (int i = 0; i < 8; ++i)
        c[i] = static_cast<float>(
            v.at(b.x + s * (i & 1), b.y + s * ((i >> 1) & 1), b.z + s * ((i >> 2) & 1)));
    const float q = 0.25f / static_cast<float>(s);
    const float gx = ((c[1] - c[0]) + (c[3] - c[2]) + (c[5] - c[4]) + (c[7] - c[6])) * q;
    const float gy = ((c[2] - c[0]) + (c[3] - c[1]) + (c[6] - c[4]) + (c[7] - c[5])) * q;
    const float gz = ((c[4] - c[0]) + (c[5] - c[1]) + (c[6] - c[2]) + (c[7] - c[3])) * q;
    return {gx, gy, gz};
}

// The bend of the fine surface inside the meta-cell, in cells: the largest angle alpha between a
// voxel's central-difference gradient and T's (voxels whose gradient is under a quarter of T's
// are left out: noise and flat parts carry no surface T stands for), as the sagitta of an arc
// turning by 2 alpha over the meta-cell's diagonal, (sqrt 3 / 2) s tan(alpha / 2). The coarse
// triangles' vertices lie on the fine surface (adaptive.h), so a surface that is flat inside the
// meta-cell is drawn where the fine one is whatever its profile across it; what differs is its
// bend, and a turn of a half circle or more (a twig, a vessel, a thin sheet) is never coarse.
template <class T>
float bend_error(const VolumeView<T>& v, glm::ivec3 b, int s, glm::vec3 g) {
    const float g2 = g.x * g.x + g.y * g.y + g.z * g.z;
    float worst_cos = 1.0f;
    auto at = [&](int x, int y, int z) {
        x = std::clamp(x, 0, v.dims.x - 1);
        y = std::clamp(y, 0, v.dims.y - 1);
        z = std::clamp(z, 0, v.dims.z - 1);
        return static_cast<float>(v.at(x, y, z));
    };
    for (int z = b.z; z <= b.z + s; ++z)
        for (int y = b.y; y <= b.y + s; ++y)
            for (int x = b.x; x <= b.x + s; ++x) {
                const glm::vec3 f(at(x + 1, y, z) - at(x - 1, y, z),
                                  at(x, y + 1, z) - at(x, y - 1, z),
                                  at(x, y, z + 1) - at(x, y, z - 1));
                const float f2 = 0.25f * (f.x * f.x + f.y * f.y + f.z * f.z);  // (f / 2)^2
                if (!(f2 * 16.0f >= g2)) continue;  // under a quarter of |g|
                const float c = 0.5f * (f.x * g.x + f.y * g.y + f.z * g.z) / std::sqrt(f2 * g2);
                worst_cos = std::min(worst_cos, c);
            }
    if (worst_cos <= -0.9f) return std::numeric_limits<float>::infinity();
    // tan(alpha / 2) = sqrt((1 - cos) / (1 + cos))
    const float half_tan = std::sqrt(std::max(0.0f, 1.0f - worst_cos) / (1.0f + worst_cos));
    return 0.8660254f * static_cast<float>(s) * half_tan;
}

// The error code: the smaller of two estimates of how far the coarse surface lies from the fine
// one, delta / |grad T| (the fine surface lies where |T - iso| <= delta) and the bend; the first
// alone is the bound for every isovalue but counts a ramp that bends in value (a kink across the
// surface, as every resampled or blurred edge has) as an error of half the meta-cell, which the
// vertices placed on the fine surface do not make.
template <class T>
std::uint8_t error_code(const VolumeView<T>& v, glm::ivec3 b, int s, float delta) {
    if (delta == 0) return lod_code::kExact;
    if (!(delta < std::numeric_limits<float>::infinity())) return lod_code::kNever;  // NaN, inf
    const glm::vec3 g = centre_gradient(v, b, s);
    const float gm = std::sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    if (!(gm > 0)) return lod_code::kNever;  // a flat T cannot follow a spike
    const float by_delta = delta / gm;
    const std::uint8_t c = lod_code::encode(static_cast<double>(by_delta));
    if (c <= lod_code::encode(0.05)) return c;  // the bend can only say less: skip its cost
    return std::min(c, lod_code::encode(static_cast<double>(bend_error(v, b, s, g))));
}

}  // namespace lod_detail

// The code of the meta-cell of 2^level cells a side at `base` (complete: base + 2^level <= the
// cell dims), voxel by voxel: the plain statement of what build_lod_codes computes row by row.
template <class T>
std::uint8_t meta_cell_code(const VolumeView<T>& v, glm::ivec3 base, int level) {
    const int s = 1 << level;
    const float inv = 1.0f / static_cast<float>(s);
    float c[8];
    for (int i = 0; i < 8; ++i)
        c[i] = static_cast<float>(
            v.at(base.x + s * (i & 1), base.y + s * ((i >> 1) & 1), base.z + s * ((i >> 2) & 1)));
    float delta = 0;
    for (int z = 0; z <= s; ++z)
        for (int y = 0; y <= s; ++y)
            for (int x = 0; x <= s; ++x) {
                const float u = x * inv, t = y * inv, w = z * inv;
                const float x00 = c[0] + (c[1] - c[0]) * u, x10 = c[2] + (c[3] - c[2]) * u;
                const float x01 = c[4] + (c[5] - c[4]) * u, x11 = c[6] + (c[7] - c[6]) * u;
                const float lo = x00 + (x10 - x00) * t, hi = x01 + (x11 - x01) * t;
                const float e =
                    std::abs(static_cast<float>(v.at(base.x + x, base.y + y, base.z + z)) -
                             (lo + (hi - lo) * w));
                if (e > delta || e != e) delta = e;  // NaN sticks
            }
    return lod_detail::error_code(v, base, s, delta);
}

// The code table of `v` (LodErrors' layout): one slab of level-1 octree nodes (8 cells of z) per
// step, the slabs split over `budget`'s threads, so each byte has one writer.
template <class T>
std::vector<std::uint8_t> build_lod_codes(const VolumeView<T>& v, ThreadBudget budget) {
    const glm::ivec3 cells = v.cell_dims();
    const glm::ivec3 leaf = LodErrors::leaf_dims(cells), l1 = LodErrors::l1_dims(cells);
    std::vector<std::uint8_t> out(LodErrors::byte_count(cells), lod_code::kNever);
    const std::size_t l1_first = 2 * static_cast<std::size_t>(leaf.x) * leaf.y * leaf.z;
    auto leaf_index = [&](int x, int y, int z) {
        return (static_cast<std::size_t>(z) * leaf.y + y) * leaf.x + x;
    };
    auto slabs = [&](int z0, int z1) {
        std::vector<float> delta, edge;
        for (int nz = z0; nz < z1; ++nz)
            for (int level = 3; level >= 1; --level) {
                const int s = 1 << level;
                const glm::ivec2 m(cells.x / s, cells.y / s);  // complete meta-cells a slab
                const int per = 8 / s;                         // slabs of this level in nz's
                for (int j = 0; j < per; ++j) {
                    const int bz = nz * per + j;
                    if (bz * s + s > cells.z) break;
                    lod_detail::slab_deltas(v, level, bz, m, delta, edge);
                    for (int by = 0; by < m.y; ++by)
                        for (int bx = 0; bx < m.x; ++bx) {
                            const glm::ivec3 b(bx * s, by * s, bz * s);
                            const std::uint8_t c = lod_detail::error_code(
                                v, b, s, delta[static_cast<std::size_t>(by) * m.x + bx]);
                            if (level == 3) {
                                out[l1_first + (static_cast<std::size_t>(nz) * l1.y + by) * l1.x +
                                    bx] = c;
                            } else if (level == 2) {
                                out[2 * leaf_index(bx, by, bz) + 1] = c;
                            } else {
                                // The leaf's level-1 byte: the worst of its eight, and never when
                                // one of them is not complete (set below for border leaves).
                                std::uint8_t& w = out[2 * leaf_index(bx / 2, by / 2, bz / 2)];
                                const bool first = (bx & 1) == 0 && (by & 1) == 0 && (bz & 1) == 0;
                                w = first ? c : std::max(w, c);
                            }
                        }
                }
            }
    };
    const int threads = std::max(1, std::min(budget.usable(), l1.z));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t)
        pool.emplace_back(slabs, l1.z * t / threads, l1.z * (t + 1) / threads);
    slabs(0, l1.z / threads);
    for (auto& th : pool) th.join();
    // A leaf whose eight level-1 meta-cells are not all complete keeps "never" for level 1.
    for (int z = 0; z < leaf.z; ++z)
        for (int y = 0; y < leaf.y; ++y)
            for (int x = 0; x < leaf.x; ++x)
                if ((x + 1) * 4 > cells.x || (y + 1) * 4 > cells.y || (z + 1) * 4 > cells.z)
                    out[2 * leaf_index(x, y, z)] = lod_code::kNever;
    return out;
}

// A volume's table with what holds its bytes (a buffer, or the mapped cache file), and how it came.
struct LodTable {
    LodErrors errors;
    double build_s = 0;  // 0 when mapped from the cache
    bool from_cache = false;
    std::string cache_note;  // why the cache was not used or written, if it was not

    LodTable() = default;
    LodTable(LodTable&&) = default;  // the buffer moves with its bytes; `errors` stays valid
    LodTable& operator=(LodTable&&) = default;

    std::vector<std::uint8_t> owned;
    std::shared_ptr<MappedFile> mapped;
};

// Maps the table from the cache next to the octree's (same key, `.lod` for `.octree`) when it
// matches the volume, else calls `build` and writes the cache; without a cacheable source, builds.
LodTable load_or_build_lod(const OctreeSource& source, VoxelType type, glm::ivec3 dims,
                           const std::function<std::vector<std::uint8_t>()>& build);

template <class T>
LodTable load_or_build_lod(const VolumeView<T>& v, const OctreeSource& source,
                           ThreadBudget budget) {
    return load_or_build_lod(source, voxel_type_of<T>(), v.dims,
                             [&] { return build_lod_codes(v, budget); });
}

}  // namespace isowall
