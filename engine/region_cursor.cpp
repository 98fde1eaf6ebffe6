#include "engine/region_cursor.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include "core/pixel_rect_ops.h"
#include "core/ray.h"
#include "engine/progressive_engine.h"
#include "progressive/mesh_coverage.h"
#include "progressive/screen_mask.h"

namespace isowall {

ResolutionLevels frame_levels(const EngineOptions& opt, const FrameView& view, glm::vec3 spacing,
                              const Box3& volume_box) {
    ResolutionLevels levels;
    if (opt.uniform_level > 0) return uniform_levels(opt.uniform_level);
    if (!opt.adaptive) {
        if (!(opt.footprint_pixels > 0) || !opt.sampled_triangles) return levels;
        levels = resolution_levels(view.camera, view.frustum, view.height, spacing, kMaxMetaLevel,
                                   opt.footprint_pixels);
        // Only the levels some unit of the volume is far enough for: a frame whose cells all
        // project above the target walks cells alone and pays no level test per neighbour.
        float farthest = 0;
        for (int k = 0; k < 8; ++k) {
            const glm::vec3 corner((k & 1) ? volume_box.max.x : volume_box.min.x,
                                   (k & 2) ? volume_box.max.y : volume_box.min.y,
                                   (k & 4) ? volume_box.max.z : volume_box.min.z);
            farthest = std::max(farthest, glm::length(corner - levels.eye));
        }
        while (levels.max_level > 0 &&
               !(levels.d[static_cast<std::size_t>(levels.max_level)] < farthest))
            --levels.max_level;
        if (levels.max_level == 0) return ResolutionLevels{};
        levels.refine = false;
        levels.footprint = true;
        return levels;
    }
    // D[] depends on the eye, the frustum and the pixel size only: once per frame (every tile of
    // a wall has the same pixel size, so one frame serves all of them).
    levels = resolution_levels(view.camera, view.frustum, view.height, spacing,
                               opt.adaptive_max_level, opt.adaptive_pixels, opt.adaptive_error_px);
    levels.refine = opt.adaptive_refine;
    return levels;
}

RegionCursor region_cursor(const FrameView& view, const PixelRect& region,
                           const std::optional<Box3>& volume_box,
                           const std::vector<Box3>* mask_boxes) {
    RegionCursor c;
    c.rect = intersect(region, view.screen());
    if (volume_box)
        c.rect = intersect(c.rect, screen_box(*volume_box, view.camera.view(), view.frustum,
                                              view.width, view.height));
    if (mask_boxes) {
        ScreenMask m = screen_mask(*mask_boxes, view.camera.view(), view.frustum, view.width,
                                   view.height, c.rect);
        c.rect = m.rect;
        c.mask = std::move(m.cast);
        c.pixels = m.count;
    } else {
        c.pixels = pixel_count(c.rect);
    }
    c.done = c.pixels == 0;
    return c;
}

void begin_order(RegionCursor& c, RayOrderKind kind) {
    c.order = make_ray_order(kind, c.rect.width, c.rect.height,
                             PixelRect{0, 0, c.rect.width, c.rect.height}, c.mask);
    c.sizing = kind == RayOrderKind::dynamic_grid || kind == RayOrderKind::dynamic_gaps;
    if (c.sizing) c.drawn.assign(pixel_count(c.rect), 0);
}

void add_drawn(RegionCursor& c, const Mesh& mesh, const glm::mat4& view_m, const FrameView& view) {
    add_mesh_coverage(mesh, view_m, view.frustum, view.width, view.height, c.rect, c.drawn);
}

bool give_order_coverage(RayOrder& order, RegionCursor& c, ShownPixels* shown,
                         std::vector<std::uint8_t>& scratch) {
    if (c.sizing) {
        order.set_coverage(c.drawn);
        c.sizing = order.wants_coverage();  // still searching: no piece found in the region yet
        if (!c.sizing) c.drawn = {};
        return false;
    }
    if (shown)
        shown->coverage(scratch, c.rect);
    else
        scratch.assign(pixel_count(c.rect), 0);
    order.set_coverage(scratch);
    return shown != nullptr;
}

void keep_frontier(RegionCursor& c, std::vector<glm::ivec3>& units, const SurfaceExtractor& ex) {
    if (units.empty()) return;
    constexpr std::size_t kFirstDrop = std::size_t{1} << 18;
    if (c.frontier.size() > std::max(kFirstDrop, 2 * c.frontier_kept)) {
        std::erase_if(c.frontier, [&ex](glm::ivec3 u) { return ex.visited(u); });
        c.frontier_kept = c.frontier.size();
    }
    c.frontier.insert(c.frontier.end(), units.begin(), units.end());
    units = {};
}

ScreenClip region_clip(const FrameView& view, const PixelRect& rect, glm::vec3 spacing) {
    ScreenClip clip;
    if (rect.width <= 0 || rect.height <= 0) return clip;
    const glm::mat4 proj = sub_frustum(view.frustum, view.width, view.height, rect).matrix();
    clip.active = true;
    clip.clip_from_voxel = proj * view.camera.view() * glm::scale(glm::mat4(1.0f), spacing);
    clip.ndc_per_unit = std::max(std::abs(proj[0][0]), std::abs(proj[1][1]));
    clip.half_diagonal = 0.5f * glm::length(spacing);
    return clip;
}

SampleGrid sample_grid(const FrameView& view, glm::vec3 spacing) {
    SampleGrid g;
    g.active = view.width > 0 && view.height > 0;
    g.clip_from_voxel =
        view.frustum.matrix() * view.camera.view() * glm::scale(glm::mat4(1.0f), spacing);
    g.voxel_from_clip = glm::inverse(g.clip_from_voxel);
    g.width = view.width;
    g.height = view.height;
    return g;
}

ActiveBoxes screen_mask_nodes(const SurfaceExtractor& ex, double iso,
                              const ResolutionLevels& levels) {
    // The screen mask's node budget: the finest octree level with at most this many active nodes.
    // A few thousand boxes project in well under a millisecond (8 corners each), while the mask's
    // cost per region is its pixels; on the 512^2 CT head's skin this is the level of 16^3 cells,
    // whose boxes hug the surface to within about 16 voxels on screen.
    constexpr std::size_t kMaskNodes = 4096;
    // Meta-cells of level i are 2^i cells at multiples of 2^i, so a node of level i - kLeafLog2
    // or above holds each one whole: an active meta-cell then lies inside an active node (its
    // corners are in the node's range), and the mask stays conservative.
    const int finest = std::max(0, levels.max_level - OctreeShape::kLeafLog2);
    return ex.active_boxes(iso, kMaskNodes, finest);
}

}  // namespace isowall
