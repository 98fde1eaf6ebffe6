#pragma once
// The bricks of a bricked volume (Volume::set_bricks) that the surface at an isovalue may pass
// through, from the min/max octree: what a paged volume's read-ahead may read before a ray or a
// propagation pass touches it (store/paged_voxels.h).
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "volume/octree.h"

namespace isowall {

// One byte per brick of `grid` (bricks of 2^brick_log2 voxels a side, x fastest): 1 where a cell
// of an active octree node reads the brick's voxels. A node of the level whose nodes are bricks
// holds the cells that start in its brick; their far corners lie in the next brick along x, y
// and z, so each active node marks its brick and the seven beyond it. Empty when the octree has
// no level of brick-sized nodes (bricks larger than the volume).
template <class T>
std::vector<std::uint8_t> surface_bricks(const MinMaxOctree<T>& octree, int brick_log2,
                                         glm::ivec3 grid, double iso) {
    const int level = brick_log2 - OctreeShape::kLeafLog2;
    if (level < 0 || level >= octree.level_count()) return {};
    const glm::ivec3 nodes = octree.shape().levels[static_cast<std::size_t>(level)].dims;
    std::vector<std::uint8_t> out(static_cast<std::size_t>(grid.x) * grid.y * grid.z, 0);
    auto mark = [&](glm::ivec3 b) {
        if (b.x < grid.x && b.y < grid.y && b.z < grid.z)
            out[(static_cast<std::size_t>(b.z) * grid.y + b.y) * grid.x + b.x] = 1;
    };
    for (int z = 0; z < nodes.z; ++z)
        for (int y = 0; y < nodes.y; ++y)
            for (int x = 0; x < nodes.x; ++x) {
                if (!octree.active(level, {x, y, z}, iso)) continue;
                for (int d = 0; d < 8; ++d) mark({x + (d & 1), y + ((d >> 1) & 1), z + (d >> 2)});
            }
    return out;
}

}  // namespace isowall
