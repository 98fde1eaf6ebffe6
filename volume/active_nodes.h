#pragma once
// The active nodes of one coarse octree level: where the surface at an isovalue may be, in a few
// thousand boxes (the screen mask projects them). Every active cell lies inside an
// active node of every level, since a node's [min, max] holds the values of all its cells'
// corners; so a ray that meets no active node meets no surface.
#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

#include "core/box.h"
#include "volume/octree.h"

namespace isowall {

struct ActiveNodes {
    int level = 0;                  // the octree level of every node below
    std::vector<glm::ivec3> nodes;  // node coordinates at that level; empty: no surface
};

// The finest level, not below `finest_level`, whose active nodes number at most `max_nodes`, and
// those nodes. Found top down from the root, expanding only active nodes, so the cost follows the
// active nodes (at most 8 * max_nodes tests per level), not the volume. An inactive root gives
// no nodes at all.
template <class T>
ActiveNodes active_nodes(const MinMaxOctree<T>& octree, double iso, std::size_t max_nodes,
                         int finest_level) {
    ActiveNodes out;
    out.level = octree.level_count() - 1;
    if (out.level < 0 || !octree.active(out.level, glm::ivec3(0), iso)) return out;
    out.nodes.push_back(glm::ivec3(0));
    std::vector<glm::ivec3> children;
    while (out.level > finest_level && out.level > 0) {
        const int below = out.level - 1;
        const glm::ivec3 dims = octree.shape().levels[static_cast<std::size_t>(below)].dims;
        children.clear();
        for (const glm::ivec3 n : out.nodes)
            for (int k = 0; k < 8; ++k) {
                const glm::ivec3 c = 2 * n + glm::ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                if (c.x < dims.x && c.y < dims.y && c.z < dims.z && octree.active(below, c, iso))
                    children.push_back(c);
            }
        if (children.size() > max_nodes) break;
        out.nodes.swap(children);
        out.level = below;
    }
    return out;
}

// The same nodes as object-space boxes (what a screen mask projects).
struct ActiveBoxes {
    int level = 0;
    std::vector<Box3> boxes;
};

// Node n of `level` in object space: its cells' corners, voxel index times spacing.
inline Box3 node_box(const OctreeShape& shape, int level, glm::ivec3 n, glm::vec3 spacing) {
    Box3 b;
    b.merge(glm::vec3(shape.cell_begin(level, n)) * spacing);
    b.merge(glm::vec3(shape.cell_end(level, n)) * spacing);
    return b;
}

inline ActiveBoxes to_boxes(const OctreeShape& shape, const ActiveNodes& a, glm::vec3 spacing) {
    ActiveBoxes out;
    out.level = a.level;
    out.boxes.reserve(a.nodes.size());
    for (const glm::ivec3 n : a.nodes) out.boxes.push_back(node_box(shape, a.level, n, spacing));
    return out;
}

}  // namespace isowall
