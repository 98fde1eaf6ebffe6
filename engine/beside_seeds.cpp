#include "engine/beside_seeds.h"

#include <glm/common.hpp>

namespace isowall {

void note_beside(const SurfaceExtractor& ex, const RayHit& hit, const Ray& ray, glm::ivec2 pixel,
                 bool exact, std::vector<BesideSeed>& out) {
    const Volume& v = ex.volume();
    const HitNeighbours n =
        unvisited_beside_hit(hit, ray, exact, v.spacing(), glm::max(v.dims() - 1, glm::ivec3(0)),
                             [&ex](glm::ivec3 c) { return ex.visited(c); });
    for (int i = 0; i < n.count; ++i) out.push_back({n.cells[std::size_t(i)], ray, pixel});
}

std::vector<BesideSeed> take_still_empty(std::vector<BesideSeed>& pending, GroupSink& sink,
                                         const PixelRect& rect,
                                         std::vector<std::uint8_t>& scratch) {
    std::vector<BesideSeed> all;
    all.swap(pending);
    std::vector<BesideSeed> out;
    if (all.empty() || !sink.coverage(scratch, rect)) return out;
    for (const BesideSeed& b : all) {
        const glm::ivec2 p = b.pixel - glm::ivec2(rect.x, rect.y);
        if (p.x < 0 || p.y < 0 || p.x >= rect.width || p.y >= rect.height) continue;
        const std::size_t i = std::size_t(p.y) * std::size_t(rect.width) + std::size_t(p.x);
        if (!scratch[i]) out.push_back(b);
    }
    return out;
}

}  // namespace isowall
