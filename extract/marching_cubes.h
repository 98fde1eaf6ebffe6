#pragma once
// Marching cubes on one cell or meta-cell (chapter 2.1; Lorensen and Cline): case index from the
// eight corner signs, vertices by interpolation on crossed edges, normals from interpolated
// central-difference gradients. Voxels equal to the isovalue count as inside (value >= iso): the
// epsilon perturbation of the dissertation, which keeps every case non-degenerate. NaN voxels are
// outside for every isovalue (NaN >= iso is false), and no vertex is placed by interpolating
// towards a NaN or infinite voxel (crossing_fraction).
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "extract/edge_cache.h"
#include "extract/mc_tables.h"
#include "volume/volume.h"

namespace isowall {

// The classification threshold in the voxel type: value >= iso exactly when value >= the
// returned threshold, so classification needs no conversion per voxel. Integer types round iso up;
// an iso above the type's range classifies nothing as inside.
template <class T>
struct InsideTest {
    explicit InsideTest(double iso) {
        if constexpr (std::is_integral_v<T>) {
            const double c = std::ceil(iso);
            none = c > static_cast<double>(std::numeric_limits<T>::max());
            threshold = c < static_cast<double>(std::numeric_limits<T>::lowest())
                            ? std::numeric_limits<T>::lowest()
                            : static_cast<T>(none ? std::numeric_limits<T>::max() : c);
        } else {
            threshold_fp = iso;
        }
    }
    bool operator()(T value) const {
        if constexpr (std::is_integral_v<T>)
            return !none && value >= threshold;
        else
            return static_cast<double>(value) >= threshold_fp;
    }
    T threshold{};
    double threshold_fp = 0;
    bool none = false;
};

// A unit is a cell (level 0) or the meta-cell of level i >= 1: the block of 2^i cells per side at
// `base`, a multiple of 2^i, whose corners are the eight voxels at stride 2^i (adaptive.h). Every
// function below takes the level, so a cell is the meta-cell of level 0 and the two share one copy
// of the code. At level 0 the strides are those of a cell and edge_crossing() returns the linear
// estimate at once, so a cell pays only a few shifts for the generality: against separate cell
// copies, full extraction and propagation of vhp_ct_head at 40 ran no slower (and no more
// instructions under callgrind).

// The functions that read voxels take any View with VolumeView's members (data, dims, spacing,
// bricked(), index(), at()): a view that says bricked() reads each voxel through at() alone, so
// a client that holds only some voxels of a volume (remote/cell_codec.cpp) runs this same code.

// Index offsets from a unit's first voxel to its corners along x, y and z.
struct UnitStrides {
    std::size_t x, y, z;
};
template <class View>
inline UnitStrides unit_strides(const View& v, int level) {
    const std::size_t s = std::size_t{1} << level;
    const std::size_t row = static_cast<std::size_t>(v.dims.x);
    return {s, s * row, s * row * static_cast<std::size_t>(v.dims.y)};
}

// Corner values of the unit of `level` at `base` (corner k at base + 2^level * kCornerOffset[k]);
// the unit must be complete (all eight corners inside the volume).
template <class View>
inline void meta_cell_corners(const View& v, glm::ivec3 base, int level, double out[8]) {
    if (v.bricked()) {
        const int s = 1 << level;
        for (int k = 0; k < 8; ++k)
            out[k] = static_cast<double>(
                v.at(base.x + s * (k & 1), base.y + s * ((k >> 1) & 1), base.z + s * (k >> 2)));
        return;
    }
    const UnitStrides d = unit_strides(v, level);
    const auto* p = v.data + v.index(base.x, base.y, base.z);
    out[0] = static_cast<double>(p[0]);
    out[1] = static_cast<double>(p[d.x]);
    out[2] = static_cast<double>(p[d.y]);
    out[3] = static_cast<double>(p[d.y + d.x]);
    out[4] = static_cast<double>(p[d.z]);
    out[5] = static_cast<double>(p[d.z + d.x]);
    out[6] = static_cast<double>(p[d.z + d.y]);
    out[7] = static_cast<double>(p[d.z + d.y + d.x]);
}

// The level-0 names (a cell is the unit of level 0) forward to the one copy.
template <class T>
inline void cell_corners(const VolumeView<T>& v, glm::ivec3 c, double out[8]) {
    meta_cell_corners(v, c, 0, out);
}

// The marching-cubes case of the unit, classified in the voxel type: the same case as
// cell_case() on meta_cell_corners(), without converting the corners of an inactive unit (most
// units a ray walks through).
template <class T>
inline int meta_cell_case(const VolumeView<T>& v, glm::ivec3 base, int level,
                          const InsideTest<T>& inside) {
    if (v.bricked()) {
        const int s = 1 << level;
        int c = 0;
        for (int k = 0; k < 8; ++k)
            c |= inside(
                     v.at(base.x + s * (k & 1), base.y + s * ((k >> 1) & 1), base.z + s * (k >> 2)))
                 << k;
        return c;
    }
    const UnitStrides d = unit_strides(v, level);
    const T* p = v.data + v.index(base.x, base.y, base.z);
    return inside(p[0]) | inside(p[d.x]) << 1 | inside(p[d.y]) << 2 | inside(p[d.y + d.x]) << 3 |
           inside(p[d.z]) << 4 | inside(p[d.z + d.x]) << 5 | inside(p[d.z + d.y]) << 6 |
           inside(p[d.z + d.y + d.x]) << 7;
}

inline int cell_case(const double corner[8], double iso) {
    int c = 0;
    for (int k = 0; k < 8; ++k) c |= (corner[k] >= iso ? 1 : 0) << k;
    return c;
}

// Central differences in voxel units (one-sided at the volume's faces), scaled per axis by
// `inv_step` = 1 / (2 * spacing), so the result is in object units without a division per axis.
template <class View>
inline glm::vec3 gradient(const View& v, glm::ivec3 p, glm::vec3 inv_step) {
    const std::size_t i = v.index(p.x, p.y, p.z);
    const std::size_t step[3] = {
        1, static_cast<std::size_t>(v.dims.x),
        static_cast<std::size_t>(v.dims.x) * static_cast<std::size_t>(v.dims.y)};
    glm::vec3 g(0.0f);  // every axis is set below (GCC 12 cannot always tell)
    for (int a = 0; a < 3; ++a) {
        const bool has_lo = p[a] > 0, has_hi = p[a] < v.dims[a] - 1;
        const std::size_t lo = has_lo ? i - step[a] : i, hi = has_hi ? i + step[a] : i;
        // A one-sided difference spans one voxel, not two.
        const float scale = (has_lo && has_hi) ? inv_step[a] : 2.0f * inv_step[a];
        if (v.bricked()) {
            glm::ivec3 l = p, h = p;
            l[a] -= has_lo ? 1 : 0;
            h[a] += has_hi ? 1 : 0;
            g[a] = (static_cast<float>(v.at(h.x, h.y, h.z)) -
                    static_cast<float>(v.at(l.x, l.y, l.z))) *
                   scale;
            continue;
        }
        g[a] = (static_cast<float>(v.data[hi]) - static_cast<float>(v.data[lo])) * scale;
    }
    return g;
}

template <class T>
inline glm::vec3 gradient(const VolumeView<T>& v, glm::ivec3 p) {
    return gradient(v, p, 0.5f / v.spacing);
}

// Appends a vertex at `pos` (voxel space) whose normal mixes the gradients at the edge's two ends
// at t, and returns its index. The surface faces the low side: the normal is the negated gradient.
// A gradient through a NaN or infinite voxel is not finite: such a vertex gets +z, like a flat
// spot, so no NaN reaches a mesh.
inline std::uint32_t append_vertex(Mesh& mesh, glm::vec3 pos, glm::vec3 g0, glm::vec3 g1, float t,
                                   glm::vec3 spacing) {
    const glm::vec3 g = glm::mix(g0, g1, t);
    const float len2 = glm::dot(g, g);
    const bool usable = len2 > 0 && std::isfinite(len2);
    const glm::vec3 n = usable ? g * (-1.0f / std::sqrt(len2)) : glm::vec3(0, 0, 1);
    mesh.positions.push_back(pos * spacing);
    mesh.normals.push_back(n);
    return static_cast<std::uint32_t>(mesh.positions.size() - 1);
}

// Where the surface crosses the edge of a unit that runs 2^level voxels from pa along `axis`,
// whose end values va (at pa) and vb straddle iso. Level 0: the linear estimate from va and vb.
// Level >= 1: of the crossings between neighbouring voxels on the edge (at least one, an odd
// number), the one nearest that estimate. The answer depends on the edge alone, so the (up to
// four) meta-cells sharing an edge share its vertex and a level has no cracks inside.
struct EdgeCrossing {
    int segment = 0;  // the crossing lies between voxels pa + segment and pa + segment + 1
    float frac = 0;   // and that far from the first of them
    float t() const { return static_cast<float>(segment) + frac; }  // voxels from pa
};

// How far from va to vb, in [0, 1], the surface crosses an edge whose ends straddle iso. NaN is
// below every isovalue and +-infinity is ordered, but neither can be interpolated: the crossing
// then lies at the finite end, the limit of linear interpolation as the other end goes to
// infinity (and at the middle when neither end is finite), so every vertex is finite.
inline double crossing_fraction(double iso, double va, double vb) {
    const bool fa = std::isfinite(va), fb = std::isfinite(vb);
    if (!fa || !fb) return fa ? 0.0 : fb ? 1.0 : 0.5;
    const double f = (iso - va) / (vb - va);
    return f >= 0 && f <= 1 ? f : f > 1 ? 1.0 : 0.0;  // NaN (an overflowed difference) to 0
}

template <class View>
inline EdgeCrossing edge_crossing(const View& v, glm::ivec3 pa, int axis, int level, double iso,
                                  double va, double vb) {
    EdgeCrossing best;
    best.frac = static_cast<float>(crossing_fraction(iso, va, vb));
    if (level == 0) return best;
    const int s = 1 << level;
    const float linear = static_cast<float>(s) * best.frac;
    float best_miss = std::numeric_limits<float>::max();
    glm::ivec3 p = pa;
    double f0 = va;
    for (int k = 0; k < s; ++k) {
        ++p[axis];
        const double f1 = k + 1 == s ? vb : static_cast<double>(v.at(p.x, p.y, p.z));
        if ((f0 >= iso) != (f1 >= iso)) {
            const auto frac = static_cast<float>(crossing_fraction(iso, f0, f1));
            const float miss = std::abs(static_cast<float>(k) + frac - linear);
            if (miss < best_miss) {
                best_miss = miss;
                best = {k, frac};
            }
        }
        f0 = f1;
    }
    return best;
}

// The first voxel of the long edge `e` of the unit of `level` at `base`.
inline glm::ivec3 edge_start(glm::ivec3 base, int level, int e) {
    const int ca = mc::kEdgeCorners[static_cast<std::size_t>(e)][0];
    const auto& oa = mc::kCornerOffset[static_cast<std::size_t>(ca)];
    return base + (glm::ivec3(oa[0], oa[1], oa[2]) << level);
}

// The triangles of the unit in voxel space (three vertices each), for ray tests; returns the
// triangle count.
template <class T>
int meta_cell_triangles(const VolumeView<T>& v, glm::ivec3 base, int level, double iso,
                        std::array<glm::vec3, 3 * mc::kMaxTriangles>& out) {
    double corner[8];
    meta_cell_corners(v, base, level, corner);
    const int cs = cell_case(corner, iso);
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    for (int i = 0; i < 3 * count; ++i) {
        const int e = edges[static_cast<std::size_t>(i)];
        const int ca = mc::kEdgeCorners[static_cast<std::size_t>(e)][0];
        const int cb = mc::kEdgeCorners[static_cast<std::size_t>(e)][1];
        const glm::ivec3 pa = edge_start(base, level, e);
        const int axis = mc::kEdgeAxis[static_cast<std::size_t>(e)];
        glm::vec3 p = glm::vec3(pa);
        p[axis] += edge_crossing(v, pa, axis, level, iso, corner[ca], corner[cb]).t();
        out[static_cast<std::size_t>(i)] = p;
    }
    return count;
}

template <class T>
int cell_triangles(const VolumeView<T>& v, glm::ivec3 c, double iso,
                   std::array<glm::vec3, 3 * mc::kMaxTriangles>& out) {
    return meta_cell_triangles(v, c, 0, iso, out);
}

// Emits the triangles of case `cs` of the unit, whose corner values are known, into `mesh`,
// sharing vertices through `cache` (HashEdgeCache or BrickEdgeCache: units triangulated with one
// cache form one connected indexed face set). A vertex per long edge at its edge_crossing(), keyed
// by (first voxel of the edge, axis + 3 * level): a pass that crosses into units of another level
// (adaptive resolution) keeps their edges apart; the brick cache sees level 0 only. Its
// normal is the fine central-difference gradient interpolated between the two voxels that bracket
// the crossing: the normal the full-resolution surface has at that point. (Gradients at stride
// 2^level at the corners were tried: they smooth away shading the pixels show, and the phantom's
// zoomed-out C fell by 0.01 to 0.02.) Returns the number of triangles added.
template <class View, class Cache>
inline int emit_meta_cell(const View& v, glm::ivec3 base, int level, double iso, int cs,
                          const double corner[8], Cache& cache, Mesh& mesh) {
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    const glm::vec3 inv_step = 0.5f / v.spacing;
    for (int i = 0; i < 3 * count; ++i) {
        const int e = edges[static_cast<std::size_t>(i)];
        const glm::ivec3 pa = edge_start(base, level, e);
        const int axis = mc::kEdgeAxis[static_cast<std::size_t>(e)];
        auto [slot, inserted] = cache.find_or_insert(pa, axis + 3 * level);
        if (inserted) {
            const int ca = mc::kEdgeCorners[static_cast<std::size_t>(e)][0];
            const int cb = mc::kEdgeCorners[static_cast<std::size_t>(e)][1];
            const EdgeCrossing x = edge_crossing(v, pa, axis, level, iso, corner[ca], corner[cb]);
            glm::ivec3 pa_fine = pa;
            pa_fine[axis] += x.segment;
            glm::ivec3 pb_fine = pa_fine;
            pb_fine[axis] += 1;
            glm::vec3 pos = glm::vec3(pa);
            pos[axis] += x.t();
            *slot = append_vertex(mesh, pos, gradient(v, pa_fine, inv_step),
                                  gradient(v, pb_fine, inv_step), x.frac, v.spacing);
        }
        mesh.indices.push_back(*slot);
    }
    return count;
}

template <class T, class Cache>
inline int emit_cell(const VolumeView<T>& v, glm::ivec3 c, double iso, int cs,
                     const double corner[8], Cache& cache, Mesh& mesh) {
    return emit_meta_cell(v, c, 0, iso, cs, corner, cache, mesh);
}

}  // namespace isowall
