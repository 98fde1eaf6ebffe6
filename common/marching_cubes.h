#pragma once
// Marching cubes on one cell (chapter 2.1; Lorensen and Cline): case index from the eight corner
// signs, vertices by linear interpolation on crossed edges, normals from interpolated
// central-difference gradients. Voxels equal to the isovalue count as inside (value >= iso): the
// epsilon perturbation of the dissertation, which keeps every case non-degenerate.
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "common/edge_cache.h"
#include "common/mc_tables.h"
#include "common/mesh.h"
#include "common/volume.h"

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

inline int cell_case(const double corner[8], double iso) {
    int c = 0;
    for (int k = 0; k < 8; ++k) c |= (corner[k] >= iso ? 1 : 0) << k;
    return c;
}

// Central differences in object units; one-sided at the volume's faces.
template <class T>
inline glm::vec3 gradient(const VolumeView<T>& v, glm::ivec3 p) {
    glm::vec3 g;
    for (int a = 0; a < 3; ++a) {
        glm::ivec3 lo = p, hi = p;
        lo[a] = p[a] > 0 ? p[a] - 1 : p[a];
        hi[a] = p[a] < v.dims[a] - 1 ? p[a] + 1 : p[a];
        const double d = static_cast<double>(v.at(hi.x, hi.y, hi.z)) -
                         static_cast<double>(v.at(lo.x, lo.y, lo.z));
        g[a] = static_cast<float>(d / (static_cast<double>(hi[a] - lo[a]) * v.spacing[a]));
    }
    return g;
}

// The key of the edge from voxel `lower` along `axis`: unique in the volume.
template <class T>
inline std::uint64_t edge_key(const VolumeView<T>& v, glm::ivec3 lower, int axis) {
    return static_cast<std::uint64_t>(v.index(lower.x, lower.y, lower.z)) * 3 + static_cast<std::uint64_t>(axis);
}

// Appends the triangles of cell c to `mesh`, sharing vertices through `cache` (keys are global
// edges, so cells triangulated with one cache form one connected indexed face set).
// Returns the number of triangles added.
template <class T>
inline int triangulate_cell(const VolumeView<T>& v, glm::ivec3 c, double iso, EdgeVertexCache& cache,
                            Mesh& mesh) {
    double corner[8];
    cell_corners(v, c, corner);
    const int cs = cell_case(corner, iso);
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    if (count == 0) return 0;
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    for (int i = 0; i < 3 * count; ++i) {
        const int e = edges[static_cast<std::size_t>(i)];
        const int ca = mc::kEdgeCorners[static_cast<std::size_t>(e)][0];
        const int cb = mc::kEdgeCorners[static_cast<std::size_t>(e)][1];
        const auto& oa = mc::kCornerOffset[static_cast<std::size_t>(ca)];
        const glm::ivec3 pa = c + glm::ivec3(oa[0], oa[1], oa[2]);
        const int axis = mc::kEdgeAxis[static_cast<std::size_t>(e)];
        auto [slot, inserted] = cache.find_or_insert(edge_key(v, pa, axis));
        if (inserted) {
            glm::ivec3 pb = pa;
            pb[axis] += 1;
            const double va = corner[ca], vb = corner[cb];
            const float t = static_cast<float>((iso - va) / (vb - va));
            glm::vec3 pos = glm::vec3(pa);
            pos[axis] += t;
            const glm::vec3 g = glm::mix(gradient(v, pa), gradient(v, pb), t);
            const float len = glm::length(g);
            // The surface faces the low side: the normal is the negated gradient.
            const glm::vec3 n = len > 0 ? -g / len : glm::vec3(0, 0, 1);
            *slot = static_cast<std::uint32_t>(mesh.positions.size());
            mesh.positions.push_back(pos * v.spacing);
            mesh.normals.push_back(n);
        }
        mesh.indices.push_back(*slot);
    }
    return count;
}

}  // namespace isowall
