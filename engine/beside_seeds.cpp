#include "engine/beside_seeds.h"

#include <glm/common.hpp>
#include <glm/ext/matrix_transform.hpp>

#include "core/pixel_rect_ops.h"

namespace isowall {

void note_beside(const SurfaceExtractor& ex, const RayHit& hit, const Ray& ray, glm::ivec2 pixel,
                 bool exact, std::vector<BesideSeed>& out) {
    const Volume& v = ex.volume();
    const HitNeighbours n =
        unvisited_beside_hit(hit, ray, exact, v.spacing(), glm::max(v.dims() - 1, glm::ivec3(0)),
                             [&ex](glm::ivec3 c) { return ex.visited(c); });
    for (int i = 0; i < n.count; ++i) out.push_back({n.cells[std::size_t(i)], ray, pixel});
}

std::vector<BesideSeed> take_still_empty(std::vector<BesideSeed>& pending, const PixelRect& rect,
                                         const std::vector<std::uint8_t>& covered) {
    std::vector<BesideSeed> all;
    all.swap(pending);
    std::vector<BesideSeed> out;
    if (covered.size() != pixel_count(rect)) return out;
    for (const BesideSeed& b : all) {
        const glm::ivec2 p = b.pixel - glm::ivec2(rect.x, rect.y);
        if (p.x < 0 || p.y < 0 || p.x >= rect.width || p.y >= rect.height) continue;
        const std::size_t i = std::size_t(p.y) * std::size_t(rect.width) + std::size_t(p.x);
        if (!covered[i]) out.push_back(b);
    }
    return out;
}

std::vector<BesideSeed> take_still_empty(std::vector<BesideSeed>& pending, ShownPixels* shown,
                                         const PixelRect& rect,
                                         std::vector<std::uint8_t>& scratch) {
    if (pending.empty() || !shown) {
        pending.clear();
        return {};
    }
    shown->coverage(scratch, rect);
    return take_still_empty(pending, rect, scratch);
}

std::optional<glm::ivec2> cell_pixel(const glm::mat4& clip_from_voxel, glm::ivec3 cell, int width,
                                     int height) {
    return clip_to_pixel(clip_from_voxel * glm::vec4(glm::vec3(cell) + 0.5f, 1.0f), width, height);
}

std::vector<BesideSeed> take_frontier_still_empty(std::vector<glm::ivec3>& pending,
                                                  const SurfaceExtractor& ex, const FrameView& view,
                                                  const glm::mat4& view_inverse,
                                                  const PixelRect& rect,
                                                  std::vector<std::uint8_t>& covered) {
    std::vector<glm::ivec3> all;
    all.swap(pending);
    std::vector<BesideSeed> out;
    std::erase_if(all, [&ex](glm::ivec3 c) { return ex.visited(c); });
    if (all.empty() || covered.size() != pixel_count(rect)) return out;
    const glm::mat4 clip_from_voxel = view.frustum.matrix() * view.camera.view() *
                                      glm::scale(glm::mat4(1.0f), ex.volume().spacing());
    for (const glm::ivec3 c : all) {
        const auto px = cell_pixel(clip_from_voxel, c, view.width, view.height);
        if (!px) continue;
        const glm::ivec2 p = *px - glm::ivec2(rect.x, rect.y);
        if (p.x < 0 || p.y < 0 || p.x >= rect.width || p.y >= rect.height) continue;
        std::uint8_t& shown =
            covered[std::size_t(p.y) * std::size_t(rect.width) + std::size_t(p.x)];
        if (shown) continue;
        shown = 1;  // one seed per pixel: its pass reaches the others' cells if they are one piece
        out.push_back(
            {c, pixel_ray(view_inverse, view.frustum, view.width, view.height, *px), *px});
    }
    return out;
}

}  // namespace isowall
