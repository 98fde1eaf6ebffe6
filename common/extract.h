#pragma once
// Full-surface extraction: every active cell of the volume, found through the min/max octree so
// inactive regions are skipped a whole node at a time. The oracle the progressive engine is
// compared against, and `isowall extract`.
#include <cstddef>

#include "common/marching_cubes.h"
#include "common/octree.h"

namespace isowall {

struct ExtractStats {
    std::size_t nodes_visited = 0;  // octree nodes tested
    std::size_t leaves_active = 0;  // leaf bricks scanned cell by cell
    std::size_t cells_active = 0;   // cells that produced triangles
};

template <class T>
Mesh extract_full(const VolumeView<T>& v, const MinMaxOctree<T>& octree, double iso,
                  ExtractStats* stats = nullptr) {
    ExtractStats local;
    ExtractStats& st = stats ? *stats : local;
    Mesh mesh;
    const OctreeShape& shape = octree.shape();
    EdgeVertexCache cache(1u << 16);

    // Depth first from the root, children in z, y, x order: the output order is deterministic.
    auto visit = [&](auto&& self, int level, glm::ivec3 n) -> void {
        ++st.nodes_visited;
        if (!octree.active(level, n, iso)) return;
        if (level > 0) {
            const auto& below = shape.levels[static_cast<std::size_t>(level - 1)];
            const glm::ivec3 c0 = 2 * n;
            const glm::ivec3 c1 = glm::min(c0 + 2, below.dims);
            for (int z = c0.z; z < c1.z; ++z)
                for (int y = c0.y; y < c1.y; ++y)
                    for (int x = c0.x; x < c1.x; ++x) self(self, level - 1, {x, y, z});
            return;
        }
        ++st.leaves_active;
        const glm::ivec3 b = shape.cell_begin(0, n), e = shape.cell_end(0, n);
        for (int z = b.z; z < e.z; ++z)
            for (int y = b.y; y < e.y; ++y)
                for (int x = b.x; x < e.x; ++x)
                    if (triangulate_cell(v, {x, y, z}, iso, cache, mesh) > 0) ++st.cells_active;
    };
    visit(visit, octree.level_count() - 1, glm::ivec3(0));
    return mesh;
}

}  // namespace isowall
