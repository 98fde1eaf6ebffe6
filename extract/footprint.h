#pragma once
// Footprint units: where cells project to less than a pixel, a propagation pass walks meta-cells
// of about a pixel (adaptive.h's units, chosen by their projected size) instead of cells, and a
// unit hands the renderer what a pixel can show of the full-resolution surface inside it rather
// than coarse triangles: for each pixel centre its projection holds, the first full-resolution
// triangle the centre's ray meets in the unit, as a sample. Work per unit then follows the pixels
// it covers, not the cells it holds, and the picture is the one every full-resolution triangle
// drawn at one sample a pixel gives: the same fragment (depth, interpolated normal, facing) at
// every pixel centre.
//
//   activity: a unit is entered across a face whose voxels straddle the isovalue, the exact test
//     for the fine surface crossing it (two neighbouring voxels of the face on either side mean a
//     fine cell face is crossed), where a meta-cell's eight corners alone miss thin structures;
//   a sample: the centre's ray stepped through the unit's cells (3D DDA), Moller-Trumbore on the
//     marching-cubes triangles of each active cell it passes, the first hit's normal interpolated
//     from the triangle's vertex normals exactly as the rasteriser interpolates them;
//   drawn as a sample triangle: a triangle of under half a pixel around the hit, across the ray,
//     with the same facing as the hit triangle and the interpolated normal at each corner, so it
//     writes exactly the centre's fragment through the same shaders, and every sink, cache and
//     wire format that carries meshes carries it unchanged.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/camera.h"
#include "core/mesh.h"
#include "core/ray.h"
#include "extract/adaptive.h"
#include "extract/marching_cubes.h"

namespace isowall {

// The radius of a sample triangle, in pixels: it holds its own pixel's centre with room for the
// rasteriser's rounding and can reach no other.
inline constexpr float kSampleRadiusPx = 0.35f;

// The largest footprint unit: 8 x 8 x 8 cells (adaptive.h's kMaxMetaLevel).
inline constexpr int kMaxFootprintLevel = kMaxMetaLevel;

// The nearest sample taken so far at each pixel of a frame, as the ray parameter along that
// pixel's centre ray (FootprintGrid::centre_ray, the same ray for every unit): a unit the ray
// enters only beyond it cannot show at that pixel, so its walk there is skipped. Every sample
// taken is drawn, so what is skipped is hidden in the picture. Workers of one frame take and
// read samples side by side: each slot is a float's bits (non-negative floats order as their
// bits), lowered by compare-and-swap.
class SampleDepths {
  public:
    // Forgets every sample; the frame is `width` x `height` pixels.
    void reset(int width, int height) {
        const auto n = static_cast<std::size_t>(std::max(width, 0)) *
                       static_cast<std::size_t>(std::max(height, 0));
        if (n != size_) {
            slots_ = std::make_unique<std::atomic<std::uint32_t>[]>(n);
            size_ = n;
        }
        width_ = width;
        for (std::size_t i = 0; i < n; ++i) slots_[i].store(kFar, std::memory_order_relaxed);
    }

    // Whether a unit the centre ray of pixel (x, y) enters at `t` lies behind a sample taken.
    bool behind(int x, int y, float t) const {
        return t > std::bit_cast<float>(slot(x, y).load(std::memory_order_relaxed));
    }
    // Records a sample at `t` (non-negative) at pixel (x, y).
    void take(int x, int y, float t) {
        std::atomic<std::uint32_t>& s = slot(x, y);
        const std::uint32_t bits = std::bit_cast<std::uint32_t>(std::max(t, 0.0f));
        std::uint32_t old = s.load(std::memory_order_relaxed);
        while (bits < old && !s.compare_exchange_weak(old, bits, std::memory_order_relaxed)) {
        }
    }

  private:
    static constexpr std::uint32_t kFar = 0x7f800000u;  // +infinity
    std::atomic<std::uint32_t>& slot(int x, int y) const {
        return slots_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                      static_cast<std::size_t>(x)];
    }
    std::unique_ptr<std::atomic<std::uint32_t>[]> slots_;
    std::size_t size_ = 0;
    int width_ = 0;
};

// The voxels of one unit of `level` at `base` ((2^level + 1)^3 of them, the unit complete), read
// once: its crossed faces, its cells' cases and the crossings on their edges all come from here.
template <class T>
class UnitBlock {
  public:
    static constexpr int kMaxSide = (1 << kMaxFootprintLevel) + 1;

    UnitBlock(const VolumeView<T>& v, glm::ivec3 base, int level, const InsideTest<T>& inside)
        : base_(base), level_(level), s_(1 << level), n_(s_ + 1) {
        for (int z = 0; z < n_; ++z)
            for (int y = 0; y < n_; ++y) {
                T* row = &value_[static_cast<std::size_t>((z * n_ + y) * n_)];
                if (v.bricked()) {
                    for (int x = 0; x < n_; ++x) row[x] = v.at(base.x + x, base.y + y, base.z + z);
                } else {
                    // A few voxels a row: a plain loop, where std::copy would call memmove.
                    const T* src = v.data + v.index(base.x, base.y + y, base.z + z);
                    for (int x = 0; x < n_; ++x) row[x] = src[x];
                }
            }
        for (int i = 0; i < n_ * n_ * n_; ++i)
            in_[static_cast<std::size_t>(i)] = inside(value_[static_cast<std::size_t>(i)]);
    }

    int level() const { return level_; }
    int side() const { return s_; }
    glm::ivec3 base() const { return base_; }
    T value(int x, int y, int z) const { return value_[index(x, y, z)]; }

    // Whether the voxels of face `f` (axis f >> 1, side f & 1) lie on both sides of the
    // isovalue: whether the full-resolution surface crosses that face.
    bool face_straddles(int f) const {
        const int axis = f >> 1, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        int p[3] = {0, 0, 0};
        p[axis] = (f & 1) ? s_ : 0;
        bool seen[2] = {false, false};
        for (p[a2] = 0; p[a2] <= s_; ++p[a2])
            for (p[a1] = 0; p[a1] <= s_; ++p[a1]) {
                seen[in_[index(p[0], p[1], p[2])]] = true;
                if (seen[0] && seen[1]) return true;
            }
        return false;
    }
    // The faces the full-resolution surface crosses, bit f for face f.
    int crossed_faces() const {
        int faces = 0;
        for (int f = 0; f < 6; ++f)
            if (face_straddles(f)) faces |= 1 << f;
        return faces;
    }
    // Whether its voxels lie on both sides of the isovalue: whether the unit holds surface.
    bool straddles() const {
        bool seen[2] = {false, false};
        for (int i = 0; i < n_ * n_ * n_; ++i) seen[in_[static_cast<std::size_t>(i)]] = true;
        return seen[0] && seen[1];
    }
    // The marching-cubes case of the cell at (x, y, z) within the unit.
    int cell_case(int x, int y, int z) const {
        int c = 0;
        for (int k = 0; k < 8; ++k)
            c |= in_[index(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2))] << k;
        return c;
    }

  private:
    std::size_t index(int x, int y, int z) const {
        return static_cast<std::size_t>((z * n_ + y) * n_ + x);
    }
    glm::ivec3 base_;
    int level_, s_, n_;
    std::array<T, kMaxSide * kMaxSide * kMaxSide> value_;
    std::array<std::uint8_t, kMaxSide * kMaxSide * kMaxSide> in_;
};

// Whether the voxels of face `f` of the unit of `level` at `base` lie on both sides of the
// isovalue, read from the volume (a neighbour's face, without loading its block).
template <class T>
bool face_straddles(const VolumeView<T>& v, glm::ivec3 base, int level, int f,
                    const InsideTest<T>& inside) {
    const int s = 1 << level;
    const int axis = f >> 1, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    glm::ivec3 p = base;
    p[axis] += (f & 1) ? s : 0;
    bool seen[2] = {false, false};
    for (int j = 0; j <= s; ++j)
        for (int i = 0; i <= s; ++i) {
            glm::ivec3 q = p;
            q[a1] += i;
            q[a2] += j;
            seen[inside(v.at(q.x, q.y, q.z)) ? 1 : 0] = true;
            if (seen[0] && seen[1]) return true;
        }
    return false;
}

// What a pixel centre's ray meets first in a unit.
struct FootprintHit {
    bool found = false;
    float t = 0;
    glm::vec3 position{0};  // voxel space
    glm::vec3 normal{0};    // object space, unit length: interpolated over the hit triangle
    bool front = true;      // the hit triangle's winding faces the ray's origin
};

// Moller-Trumbore with barycentrics; the same tolerance at shared edges as intersect_triangle.
inline bool intersect_barycentric(const Ray& r, glm::vec3 a, glm::vec3 b, glm::vec3 c, float& t,
                                  float& u, float& w) {
    const glm::vec3 e1 = b - a, e2 = c - a;
    const glm::vec3 p = glm::cross(r.d, e2);
    const float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12f) return false;
    const float inv = 1.0f / det;
    const glm::vec3 s = r.o - a;
    u = glm::dot(s, p) * inv;
    constexpr float kEps = 1e-5f;
    if (u < -kEps || u > 1.0f + kEps) return false;
    const glm::vec3 q = glm::cross(s, e1);
    w = glm::dot(r.d, q) * inv;
    if (w < -kEps || u + w > 1.0f + kEps) return false;
    t = glm::dot(e2, q) * inv;
    return t >= 0;
}

// The normal emit_meta_cell() gives the vertex on the edge from voxel pa along `axis` at `frac`:
// the fine gradients at the edge's ends, mixed and negated.
template <class T>
glm::vec3 edge_normal(const VolumeView<T>& v, glm::ivec3 pa, int axis, float frac) {
    const glm::vec3 inv_step = 0.5f / v.spacing;
    glm::ivec3 pb = pa;
    pb[axis] += 1;
    const glm::vec3 g = glm::mix(gradient(v, pa, inv_step), gradient(v, pb, inv_step), frac);
    const float len2 = glm::dot(g, g);
    return len2 > 0 && std::isfinite(len2) ? g * (-1.0f / std::sqrt(len2)) : glm::vec3(0, 0, 1);
}

// What the rays of one unit's pixel centres share: each cell's case, and the crossings and vertex
// normals of its edges, worked out the first time a ray needs them (neighbouring centres' rays
// cross the same cells, and often hit the same triangle). Scratch reused from unit to unit.
class UnitCells {
  public:
    struct Cell {
        int cs = -1;                 // -1: not classified yet
        std::uint16_t placed = 0;    // edges whose crossing is in `at`, `start`, `frac`
        std::uint16_t normaled = 0;  // edges whose normal is in `normal`
        std::uint32_t unit = 0;      // the unit these are of (UnitCells::unit_)
        std::array<glm::vec3, 12> at;
        std::array<glm::ivec3, 12> start;
        std::array<float, 12> frac;
        std::array<glm::vec3, 12> normal;
    };

    // Forgets every cell (by a new unit number: no cell is written until a ray needs it); the
    // next unit has `side` cells a side.
    void reset(int side) {
        side_ = side;
        const auto n = static_cast<std::size_t>(side * side * side);
        if (cells_.size() < n) cells_.resize(n);
        if (++unit_ == 0) {  // wrapped: make every cell stale by hand, once in 2^32 units
            for (Cell& c : cells_) c.unit = 0;
            unit_ = 1;
        }
    }
    Cell& at(glm::ivec3 c) {
        Cell& cell = cells_[static_cast<std::size_t>((c.z * side_ + c.y) * side_ + c.x)];
        if (cell.unit != unit_) {
            cell.unit = unit_;
            cell.cs = -1;
            cell.placed = cell.normaled = 0;
        }
        return cell;
    }

  private:
    int side_ = 0;
    std::uint32_t unit_ = 0;
    std::vector<Cell> cells_;
};

// Whether `ray` meets a marching-cubes triangle of cell `c` (within the unit `block`); the
// nearest such hit goes into `hit`, its normal worked out for that triangle alone.
template <class T>
bool hit_in_cell(const VolumeView<T>& v, const UnitBlock<T>& block, glm::ivec3 c, double iso,
                 const Ray& ray, FootprintHit& hit, UnitCells& cells) {
    UnitCells::Cell& cell = cells.at(c);
    if (cell.cs < 0) cell.cs = block.cell_case(c.x, c.y, c.z);
    const int cs = cell.cs;
    if (cs == 0 || cs == 255) return false;
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    const glm::ivec3 base = block.base();
    // Each crossed edge's first voxel, axis and crossing, as emit_meta_cell() places them.
    auto vertex = [&](int e) -> const glm::vec3& {
        const auto ue = static_cast<std::size_t>(e);
        if (!((cell.placed >> e) & 1u)) {
            cell.placed = static_cast<std::uint16_t>(cell.placed | (1u << e));
            const auto& oa = mc::kCornerOffset[static_cast<std::size_t>(mc::kEdgeCorners[ue][0])];
            const glm::ivec3 la = c + glm::ivec3(oa[0], oa[1], oa[2]);
            const int axis = mc::kEdgeAxis[ue];
            glm::ivec3 lb = la;
            lb[axis] += 1;
            cell.frac[ue] = static_cast<float>(
                crossing_fraction(iso, static_cast<double>(block.value(la.x, la.y, la.z)),
                                  static_cast<double>(block.value(lb.x, lb.y, lb.z))));
            cell.start[ue] = base + la;
            cell.at[ue] = glm::vec3(cell.start[ue]);
            cell.at[ue][axis] += cell.frac[ue];
        }
        return cell.at[ue];
    };
    int best = -1;
    float best_u = 0, best_w = 0;
    for (int i = 0; i < count; ++i) {
        const auto k = static_cast<std::size_t>(3 * i);
        const glm::vec3 a = vertex(edges[k]);
        const glm::vec3 b = vertex(edges[k + 1]);
        const glm::vec3 cc = vertex(edges[k + 2]);
        float t, u, w;
        if (!intersect_barycentric(ray, a, b, cc, t, u, w) || (best >= 0 && t >= hit.t)) continue;
        best = i;
        best_u = u;
        best_w = w;
        hit.t = t;
        hit.front = glm::dot(glm::cross(b - a, cc - a), ray.d) < 0;
    }
    if (best < 0) return false;
    hit.found = true;
    hit.position = ray.at(hit.t);
    glm::vec3 n(0.0f);
    const float weight[3] = {1.0f - best_u - best_w, best_u, best_w};
    for (int j = 0; j < 3; ++j) {
        const int e = edges[static_cast<std::size_t>(3 * best + j)];
        const auto ue = static_cast<std::size_t>(e);
        if (!((cell.normaled >> e) & 1u)) {
            cell.normaled = static_cast<std::uint16_t>(cell.normaled | (1u << e));
            cell.normal[ue] = edge_normal(v, cell.start[ue], mc::kEdgeAxis[ue], cell.frac[ue]);
        }
        n += weight[j] * cell.normal[ue];
    }
    const float len2 = glm::dot(n, n);
    hit.normal = len2 > 0 && std::isfinite(len2) ? n / std::sqrt(len2) : glm::vec3(0, 0, 1);
    return true;
}

// The first full-resolution triangle `ray` (voxel space) meets inside the unit `block`: the
// cells the ray passes are stepped through in its order (3D DDA), and the first active one whose
// marching-cubes triangles it hits answers; the normal is worked out for that triangle alone.
// With `depths`, a ray that enters the unit behind the sample taken at pixel (x, y) is not
// walked: it answers no hit.
template <class T>
FootprintHit first_hit_in_unit(const VolumeView<T>& v, const UnitBlock<T>& block, double iso,
                               const Ray& ray, UnitCells& cells,
                               const SampleDepths* depths = nullptr, int x = 0, int y = 0) {
    FootprintHit hit;
    const int s = block.side();
    const glm::ivec3 base = block.base();
    const glm::vec3 inv_d = inverse_direction(ray);
    float t0, t1;
    if (!intersect_box(ray, inv_d, glm::vec3(base), glm::vec3(base + s), t0, t1) || t1 < 0)
        return hit;
    t0 = std::max(t0, 0.0f);
    if (depths && depths->behind(x, y, t0)) return hit;
    // The cells the ray passes within the unit, from the one it enters.
    CellWalk walk(ray, inv_d,
                  base + glm::clamp(glm::ivec3(glm::floor(ray.at(t0))) - base, glm::ivec3(0),
                                    glm::ivec3(s - 1)));
    for (;;) {
        if (hit_in_cell(v, block, walk.cell - base, iso, ray, hit, cells)) return hit;
        if (!walk.next(base, base + s, t1)) return hit;
    }
}

// The pixel grid a unit's samples are taken on: the frame's clip transform and its inverse.
struct FootprintGrid {
    glm::mat4 clip_from_voxel{1.0f};
    glm::mat4 voxel_from_clip{1.0f};
    int width = 0, height = 0;

    // The ray through window point `w` (pixels, top-left origin) in voxel space: from the near
    // plane's point towards the point at NDC depth 0 (not of unit length).
    Ray ray_through(glm::vec2 w) const {
        const float nx = w.x * 2.0f / static_cast<float>(width) - 1.0f;
        const float ny = 1.0f - w.y * 2.0f / static_cast<float>(height);
        const glm::vec4 mid =
            nx * voxel_from_clip[0] + ny * voxel_from_clip[1] + voxel_from_clip[3];
        const glm::vec4 near = mid - voxel_from_clip[2];
        const glm::vec3 o = glm::vec3(near) / near.w;
        return {o, glm::vec3(mid) / mid.w - o};
    }
    // The ray through the centre of pixel (x, y).
    Ray centre_ray(int x, int y) const {
        return ray_through({static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f});
    }

    // The window position of a voxel-space point (w > 0 assumed).
    glm::vec2 window(glm::vec3 p) const {
        const glm::vec4 c = clip_from_voxel * glm::vec4(p, 1.0f);
        return ndc_to_window(c.x / c.w, c.y / c.w, width, height);
    }
};

// The shape of a unit's sample triangles: three offsets kSampleRadiusPx across the direction the
// unit is seen in, worked out once per unit (its rays are all but parallel).
struct SampleShape {
    bool usable = false;
    std::array<glm::vec3, 3> offset{};  // counter-clockwise about d seen from the eye: normal d

    // The shape at voxel-space point `p` seen along `dir`.
    static SampleShape at(const FootprintGrid& grid, glm::vec3 p, glm::vec3 dir) {
        SampleShape shape;
        const float len = glm::length(dir);
        if (!(len > 0) || !std::isfinite(len)) return shape;
        const glm::vec3 d = dir / len;
        const glm::vec3 helper = std::abs(d.x) < 0.6f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
        const glm::vec3 e1 = glm::normalize(glm::cross(d, helper));
        const glm::vec3 e2 = glm::cross(d, e1);  // (e1, e2, d) right-handed: e1 x e2 = d
        // Pixels per voxel unit across the ray, from the longer of the two directions.
        const glm::vec2 w0 = grid.window(p);
        const float px =
            std::max(glm::length(grid.window(p + e1) - w0), glm::length(grid.window(p + e2) - w0));
        if (!(px > 0) || !std::isfinite(px)) return shape;
        const float r = kSampleRadiusPx / px;
        constexpr float kC = 0.8660254f;  // cos 30 degrees: corners at 90, 210 and 330 degrees
        shape.usable = true;
        shape.offset = {r * e2, r * (-kC * e1 - 0.5f * e2), r * (kC * e1 - 0.5f * e2)};
        return shape;
    }
};

// Appends the sample triangle of `hit` to `mesh` (object space, `spacing` per voxel): `shape`'s
// corners around the hit, wound to face as the hit triangle does, each with the hit's normal.
inline void append_sample_triangle(const FootprintHit& hit, const SampleShape& shape,
                                   glm::vec3 spacing, Mesh& mesh) {
    // The shape's own winding has normal d, away from the eye: a front-facing hit swaps two.
    const std::size_t b = hit.front ? 2 : 1, c = hit.front ? 1 : 2;
    const auto first = static_cast<std::uint32_t>(mesh.positions.size());
    for (const std::size_t k : {std::size_t{0}, b, c}) {
        mesh.positions.push_back((hit.position + shape.offset[k]) * spacing);
        mesh.normals.push_back(hit.normal);
    }
    mesh.indices.insert(mesh.indices.end(), {first, first + 1, first + 2});
}

}  // namespace isowall
