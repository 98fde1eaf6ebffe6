#pragma once
// Full-surface extraction: every active cell of the volume, found through the min/max octree so
// inactive regions are skipped a whole node at a time. The oracle the progressive engine is
// compared against, and `isowall extract`.
#include <cstddef>

#include "extract/marching_cubes.h"
#include "volume/octree.h"

namespace isowall {

struct ExtractStats {
    std::size_t nodes_visited = 0;  // octree nodes tested
    std::size_t leaves_active = 0;  // leaf bricks scanned cell by cell
    std::size_t cells_active = 0;   // cells that produced triangles
};

// PASS 1 classifies the brick's voxels once (a bit each), PASS 2 builds each cell's case from the
// bits, so only active cells read their corners as doubles: most cells of an active brick are
// inactive, and classifying each cell's eight corners separately read every voxel eight times.
template <class T, class Cache>
void emit_brick(const VolumeView<T>& v, glm::ivec3 b, glm::ivec3 e, double iso, Cache& cache,
                Mesh& mesh, ExtractStats& st) {
    constexpr int S = OctreeShape::kLeafCells + 1;  // voxels per side of a leaf brick
    std::uint8_t inside[S][S][S];
    const glm::ivec3 n = e - b + 1;
    const InsideTest<T> is_inside(iso);
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y) {
            if (v.bricked()) {
                for (int x = 0; x < n.x; ++x)
                    inside[z][y][x] = is_inside(v.at(b.x + x, b.y + y, b.z + z));
                continue;
            }
            const T* row = v.data + v.index(b.x, b.y + y, b.z + z);
            for (int x = 0; x < n.x; ++x) inside[z][y][x] = is_inside(row[x]);
        }
    if constexpr (requires { cache.begin_brick(b); })
        cache.begin_brick(b >> OctreeShape::kLeafLog2);
    double corner[8];
    for (int z = 0; z + 1 < n.z; ++z)
        for (int y = 0; y + 1 < n.y; ++y)
            for (int x = 0; x + 1 < n.x; ++x) {
                const int cs = inside[z][y][x] | inside[z][y][x + 1] << 1 |
                               inside[z][y + 1][x] << 2 | inside[z][y + 1][x + 1] << 3 |
                               inside[z + 1][y][x] << 4 | inside[z + 1][y][x + 1] << 5 |
                               inside[z + 1][y + 1][x] << 6 | inside[z + 1][y + 1][x + 1] << 7;
                if (cs == 0 || cs == 255) continue;
                const glm::ivec3 c = b + glm::ivec3(x, y, z);
                meta_cell_corners(v, c, 0, corner);
                emit_meta_cell(v, c, 0, iso, cs, corner, cache, mesh);
                ++st.cells_active;
            }
}

template <class T>
Mesh extract_full(const VolumeView<T>& v, const MinMaxOctree<T>& octree, double iso,
                  ExtractStats* stats = nullptr) {
    ExtractStats local;
    ExtractStats& st = stats ? *stats : local;
    Mesh mesh;
    const OctreeShape& shape = octree.shape();
    BrickEdgeCache cache(v.dims);

    // PASS 0: the active leaf bricks, depth first from the root with children in z, y, x order,
    // so the output order is deterministic. Knowing their number sizes the output once.
    std::vector<glm::ivec3> leaves;
    auto visit = [&](auto&& self, int level, glm::ivec3 n) -> void {
        ++st.nodes_visited;
        if (!octree.active(level, n, iso)) return;
        if (level == 0) {
            leaves.push_back(n);
            return;
        }
        const auto& below = shape.levels[static_cast<std::size_t>(level - 1)];
        const glm::ivec3 c0 = 2 * n;
        const glm::ivec3 c1 = glm::min(c0 + 2, below.dims);
        for (int z = c0.z; z < c1.z; ++z)
            for (int y = c0.y; y < c1.y; ++y)
                for (int x = c0.x; x < c1.x; ++x) self(self, level - 1, {x, y, z});
    };
    visit(visit, octree.level_count() - 1, glm::ivec3(0));
    st.leaves_active = leaves.size();
    // About 8 triangles and 4 vertices per active brick on CT data; a guess, not a bound.
    mesh.indices.reserve(leaves.size() * 30);
    mesh.positions.reserve(leaves.size() * 5);
    mesh.normals.reserve(leaves.size() * 5);
    for (const glm::ivec3& n : leaves)
        emit_brick(v, shape.cell_begin(0, n), shape.cell_end(0, n), iso, cache, mesh, st);
    return mesh;
}

}  // namespace isowall
