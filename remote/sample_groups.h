#pragma once
// Groups as one frame of the progressive engine makes them, without the engine (which needs a
// renderer): rays along +y through a grid over the volume's x-z extent, front view, each ray
// that finds a cell no earlier pass took starting a propagation pass. The order is row by row,
// not the engine's refining grids, so the groups are cut differently, but their size and shape
// (one connected patch of at most max_count cells) are the engine's. For the codec tests and
// benchmark; header-only so the codec library does not depend on the extractor.
#include <vector>

#include "extract/surface_extractor.h"

namespace isowall::remote {

// `levels`: the units the passes take (uniform_levels(l): meta-cells of 2^l cells, cells at the
// volume's border).
inline std::vector<Group> sample_groups(const Volume& volume, double iso, int grid, int max_count,
                                        const ResolutionLevels& levels = {}) {
    auto ex = make_surface_extractor(volume);
    ex->begin_frame(iso, levels);
    PropagationParams params;
    params.max_count = max_count;
    const Box3 box = volume.bounds();
    const glm::vec3 size = box.max - box.min;
    std::vector<Group> groups;
    for (int j = 0; j < grid; ++j) {
        for (int i = 0; i < grid; ++i) {
            const glm::vec3 o(box.min.x + size.x * (static_cast<float>(i) + 0.5f) / grid,
                              box.min.y - 1.0f,
                              box.min.z + size.z * (static_cast<float>(j) + 0.5f) / grid);
            const Ray ray{o, glm::vec3(0, 1, 0)};
            const RayHit hit = ex->cast(ray, IntersectMode::exact);
            if (!hit.found || ex->visited(hit.cell)) continue;
            Group g =
                ex->propagate(hit.cell, static_cast<std::uint32_t>(groups.size()), params, ray);
            if (!g.mesh.empty()) groups.push_back(std::move(g));
        }
    }
    return groups;
}

}  // namespace isowall::remote
