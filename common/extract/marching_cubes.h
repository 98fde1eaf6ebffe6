#pragma once
// Marching cubes on one cell (chapter 2.1; Lorensen and Cline): case index from the eight corner
// signs, vertices by linear interpolation on crossed edges, normals from interpolated
// central-difference gradients. Voxels equal to the isovalue count as inside (value >= iso): the
// epsilon perturbation of the dissertation, which keeps every case non-degenerate.
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "common/extract/edge_cache.h"
#include "common/extract/mc_tables.h"
#include "common/core/mesh.h"
#include "common/volume/volume.h"

namespace isowall {

// Corner values of cell c (corner k at offset kCornerOffset[k]).
template <class T>
inline void cell_corners(const VolumeView<T>& v, glm::ivec3 c, double out[8]) {
    const std::size_t base = v.index(c.x, c.y, c.z);
    const std::size_t sy = static_cast<std::size_t>(v.dims.x);
    const std::size_t sz = sy * static_cast<std::size_t>(v.dims.y);
    out[0] = static_cast<double>(v.data[base]);
    out[1] = static_cast<double>(v.data[base + 1]);
    out[2] = static_cast<double>(v.data[base + sy]);
    out[3] = static_cast<double>(v.data[base + sy + 1]);
    out[4] = static_cast<double>(v.data[base + sz]);
    out[5] = static_cast<double>(v.data[base + sz + 1]);
    out[6] = static_cast<double>(v.data[base + sz + sy]);
    out[7] = static_cast<double>(v.data[base + sz + sy + 1]);
}

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
        if constexpr (std::is_integral_v<T>) return !none && value >= threshold;
        else return static_cast<double>(value) >= threshold_fp;
    }
    T threshold{};
    double threshold_fp = 0;
    bool none = false;
};

inline int cell_case(const double corner[8], double iso) {
    int c = 0;
    for (int k = 0; k < 8; ++k) c |= (corner[k] >= iso ? 1 : 0) << k;
    return c;
}

// Central differences in voxel units (one-sided at the volume's faces), scaled per axis by
// `inv_step` = 1 / (2 * spacing), so the result is in object units without a division per axis.
template <class T>
inline glm::vec3 gradient(const VolumeView<T>& v, glm::ivec3 p, glm::vec3 inv_step) {
    const std::size_t i = v.index(p.x, p.y, p.z);
    const std::size_t step[3] = {1, static_cast<std::size_t>(v.dims.x),
                                 static_cast<std::size_t>(v.dims.x) * static_cast<std::size_t>(v.dims.y)};
    glm::vec3 g;
    for (int a = 0; a < 3; ++a) {
        const bool has_lo = p[a] > 0, has_hi = p[a] < v.dims[a] - 1;
        const std::size_t lo = has_lo ? i - step[a] : i, hi = has_hi ? i + step[a] : i;
        // A one-sided difference spans one voxel, not two.
        const float scale = (has_lo && has_hi) ? inv_step[a] : 2.0f * inv_step[a];
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
inline std::uint32_t append_vertex(Mesh& mesh, glm::vec3 pos, glm::vec3 g0, glm::vec3 g1, float t,
                                   glm::vec3 spacing) {
    const glm::vec3 g = glm::mix(g0, g1, t);
    const float len2 = glm::dot(g, g);
    const glm::vec3 n = len2 > 0 ? g * (-1.0f / std::sqrt(len2)) : glm::vec3(0, 0, 1);
    mesh.positions.push_back(pos * spacing);
    mesh.normals.push_back(n);
    return static_cast<std::uint32_t>(mesh.positions.size() - 1);
}

// Emits the triangles of case `cs` of cell c, whose corner values are known, into `mesh`, sharing
// vertices through `cache` (HashEdgeCache or BrickEdgeCache: cells triangulated with one cache
// form one connected indexed face set). Returns the number of triangles added.
template <class T, class Cache>
inline int emit_cell(const VolumeView<T>& v, glm::ivec3 c, double iso, int cs,
                     const double corner[8], Cache& cache, Mesh& mesh) {
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    const glm::vec3 inv_step = 0.5f / v.spacing;
    for (int i = 0; i < 3 * count; ++i) {
        const int e = edges[static_cast<std::size_t>(i)];
        const int ca = mc::kEdgeCorners[static_cast<std::size_t>(e)][0];
        const int cb = mc::kEdgeCorners[static_cast<std::size_t>(e)][1];
        const auto& oa = mc::kCornerOffset[static_cast<std::size_t>(ca)];
        const glm::ivec3 pa = c + glm::ivec3(oa[0], oa[1], oa[2]);
        const int axis = mc::kEdgeAxis[static_cast<std::size_t>(e)];
        auto [slot, inserted] = cache.find_or_insert(pa, axis);
        if (inserted) {
            glm::ivec3 pb = pa;
            pb[axis] += 1;
            const double va = corner[ca], vb = corner[cb];
            const float t = static_cast<float>((iso - va) / (vb - va));
            glm::vec3 pos = glm::vec3(pa);
            pos[axis] += t;
            *slot = append_vertex(mesh, pos, gradient(v, pa, inv_step), gradient(v, pb, inv_step), t,
                                  v.spacing);
        }
        mesh.indices.push_back(*slot);
    }
    return count;
}

// Triangulates one cell from scratch. Returns the number of triangles added.
template <class T, class Cache>
inline int triangulate_cell(const VolumeView<T>& v, glm::ivec3 c, double iso, Cache& cache,
                            Mesh& mesh) {
    double corner[8];
    cell_corners(v, c, corner);
    const int cs = cell_case(corner, iso);
    if (mc::kTriangleCount[static_cast<std::size_t>(cs)] == 0) return 0;
    return emit_cell(v, c, iso, cs, corner, cache, mesh);
}

}  // namespace isowall
