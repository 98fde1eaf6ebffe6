// The engine's conveniences around a frame: one region into a sink, a region's cursor and clip,
// the warm-up draw, the whole-screen run that keeps every group and the final image, and the
// replay that measures correctness.
#include <algorithm>
#include <atomic>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "common/core/pixel_rect_ops.h"
#include "common/core/ray.h"
#include "common/progressive/mesh_coverage.h"
#include "common/progressive/screen_mask.h"
#include "tile/progressive_engine.h"

namespace isowall {

FrameResult ProgressiveEngine::run(const FrameView& view, const PixelRect& region, GroupSink& sink,
                                   const std::atomic<bool>& stop, const Progress& progress) {
    EngineFrame frame(*this, view, stop, progress);
    sink.begin(view);
    RegionCursor c = frame.cursor(view, region);
    const bool done = frame.cast(view, c, sink);
    FrameResult result = frame.finish(done);
    result.rays_screen =
        static_cast<std::size_t>(region.width) * static_cast<std::size_t>(region.height);
    result.screen_rect = c.rect;
    result.screen_pixels = c.pixels;
    return result;
}

ResolutionLevels frame_levels(const EngineOptions& opt, const FrameView& view, glm::vec3 spacing) {
    ResolutionLevels levels;
    if (opt.uniform_level > 0) return uniform_levels(opt.uniform_level);
    if (!opt.adaptive) return levels;
    // D[] depends on the eye, the frustum and the pixel size only: once per frame (every tile of
    // a wall has the same pixel size, so one frame serves all of them).
    levels = resolution_levels(view.camera, view.frustum, view.height, spacing,
                               opt.adaptive_max_level, opt.adaptive_pixels);
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
    c.sizing = kind == RayOrderKind::dynamic_grid;
    if (c.sizing) c.drawn.assign(pixel_count(c.rect), 0);
}

void add_drawn(RegionCursor& c, const Mesh& mesh, const glm::mat4& view_m, const FrameView& view) {
    add_mesh_coverage(mesh, view_m, view.frustum, view.width, view.height, c.rect, c.drawn);
}

void give_order_coverage(RayOrder& order, RegionCursor& c, GroupSink& sink,
                         std::vector<std::uint8_t>& scratch) {
    if (c.sizing) {
        order.set_coverage(c.drawn);
        c.sizing = order.wants_coverage();  // still searching: no piece found in the region yet
        if (!c.sizing) c.drawn = {};
        return;
    }
    if (!sink.coverage(scratch, c.rect)) scratch.assign(pixel_count(c.rect), 0);
    order.set_coverage(scratch);
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

void warm_up(Renderer& renderer) {
    Mesh tiny;
    tiny.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tiny.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    tiny.indices = {0, 1, 2};
    renderer.resize(16, 16);
    renderer.clear();
    renderer.draw(tiny, glm::mat4(1.0f), glm::mat4(1.0f));
    renderer.finish();
}

Image draw_alone(Renderer& renderer, const Mesh& mesh, const FrameView& view) {
    Image image;
    renderer.resize(view.width, view.height);
    renderer.clear();
    renderer.draw(mesh, view.camera.view(), view.frustum.matrix());
    renderer.read_back(image);
    return image;
}

FrameResult ProgressiveEngine::run(const FrameView& view, const std::atomic<bool>* stop,
                                   const Progress& progress) {
    static const std::atomic<bool> never{false};
    RendererSink draw(renderer_);
    RecordingSink record;
    TeeSink both({&draw, &record});
    FrameResult frame = run(view, view.screen(), both, stop ? *stop : never, progress);
    frame.groups = std::move(record.groups);
    if (frame.completed) draw.read_back(frame.final_image);
    return frame;
}

void ProgressiveEngine::measure(
    FrameResult& frame, const FrameView& view,
    const std::function<void(const TimelineSample&, const Image&)>& on_image) {
    if (frame.final_image.pixel_count() == 0) return;
    RendererSink replay(renderer_);
    replay.begin(view);
    std::size_t drawn = 0;
    Image image;
    for (TimelineSample& s : frame.timeline) {
        for (; drawn < s.groups; ++drawn) replay.add(frame.groups[drawn]);
        replay.read_back(image);
        s.correctness = measure_correctness(image, frame.final_image);
        if (on_image) on_image(s, image);
    }
}

}  // namespace isowall
