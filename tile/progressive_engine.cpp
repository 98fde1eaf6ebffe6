#include "tile/progressive_engine.h"

#include <algorithm>
#include <chrono>

#include <glm/matrix.hpp>

#include "common/core/ray.h"

namespace isowall {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kRefreshS = 1.0 / 60.0;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

ProgressiveEngine::ProgressiveEngine(SurfaceExtractor& extractor, Renderer& renderer,
                                     EngineOptions options)
    : extractor_(extractor), renderer_(renderer), options_(options) {
    // Mesa compiles its shader variants on the first draw (about 25 ms in llvmpipe). An
    // interactive viewer pays that once at start-up, not in every frame, so pay it here, before
    // any frame is timed. (scripts/vtk_reference.py warms VTK the same way.)
    Mesh tiny;
    tiny.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tiny.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    tiny.indices = {0, 1, 2};
    renderer_.resize(16, 16);
    renderer_.clear();
    renderer_.draw(tiny, glm::mat4(1.0f), glm::mat4(1.0f));
    renderer_.finish();
}

FrameResult ProgressiveEngine::run(const FrameView& view, const std::function<bool()>& interrupted,
                                   const std::function<void(const TimelineSample&)>& progress) {
    FrameResult frame;
    const auto start = Clock::now();
    // Once the caller says stop, stay stopped: a propagation pass cut short is followed by another
    // poll, and a caller that only reports a change once must not see the frame go on.
    bool stopped = false;
    const std::function<bool()> stop = [&] {
        if (!stopped && interrupted && interrupted()) stopped = true;
        return stopped;
    };
    const glm::mat4 view_m = view.camera.view();
    const glm::mat4 proj_m = view.frustum.matrix();
    const glm::mat4 view_inv = glm::inverse(view_m);
    frame.rays_screen = static_cast<std::size_t>(view.width) * static_cast<std::size_t>(view.height);
    frame.screen_rect = options_.screen_box
                            ? screen_box(extractor_.volume().bounds(), view_m, view.frustum,
                                         view.width, view.height)
                            : PixelRect{0, 0, view.width, view.height};

    if (options_.adaptive) {
        // D[] depends on the eye, the frustum and the pixel size only: once per frame.
        ResolutionLevels levels = resolution_levels(view.camera, view.frustum, view.height,
                                                    extractor_.volume().spacing(),
                                                    options_.adaptive_max_level);
        levels.refine = options_.adaptive_refine;
        extractor_.begin_frame(view.iso, levels);
    } else {
        if (options_.trace) options_.trace->switch_to(Stage::intersection);
    extractor_.begin_frame(view.iso);
    }
    renderer_.resize(view.width, view.height);
    renderer_.clear();

    TimelineSample now;
    std::size_t next_sample_rays = 1;
    std::vector<std::size_t> extra = options_.sample_at_rays;
    std::sort(extra.begin(), extra.end());
    std::size_t next_extra = 0;
    double last_sample_s = 0, last_progress_s = 0, last_finish_s = 0;
    bool dirty = false;  // drawn since the last finish()
    auto record = [&](bool force) {
        now.time_s = since(start);
        while (next_extra < extra.size() && extra[next_extra] < now.rays) ++next_extra;
        if (next_extra < extra.size() && extra[next_extra] == now.rays) force = true;
        if (!force && now.rays < next_sample_rays && now.time_s - last_sample_s < options_.sample_interval_s)
            return;
        // The sample shows what is on screen: wait for the queued draws to land, as a display
        // would at its next refresh. Finishing after every group would cost a full-screen flush
        // each time (about 7 ms at 1600x1200 in llvmpipe), so between refreshes a sample may
        // count groups still in flight: sample times are exact to one refresh (1/60 s).
        if (dirty && (force || now.time_s - last_finish_s >= kRefreshS)) {
            const Stage left = options_.trace ? options_.trace->switch_to(Stage::render) : Stage::render;
            const auto t0 = Clock::now();
            renderer_.finish();
            now.t_render_s += since(t0);
            if (options_.trace) options_.trace->switch_to(left);
            now.time_s = since(start);
            last_finish_s = now.time_s;
            dirty = false;
        }
        now.cells_visited = extractor_.visited_count();
        now.groups = frame.groups.size();
        frame.timeline.push_back(now);
        last_sample_s = now.time_s;
        while (next_sample_rays <= now.rays)
            next_sample_rays = std::max(next_sample_rays + 1,
                                        static_cast<std::size_t>(double(next_sample_rays) * options_.sample_ray_factor));
        if (progress && now.time_s - last_progress_s >= options_.progress_interval_s) {
            last_progress_s = now.time_s;
            progress(now);
        }
    };

    Image coverage_image;
    std::vector<std::uint8_t> covered;
    std::vector<glm::ivec2> pixels;
    auto cast_pass = [&](IntersectMode mode, bool second_pass) -> bool {
        auto order = make_ray_order(options_.order, view.width, view.height, frame.screen_rect);
        while (order->next_level(pixels)) {
            now.level = order->level();
            for (const glm::ivec2 px : pixels) {
                if (stop()) return false;
                const Ray ray = pixel_ray(view_inv, view.frustum, view.width, view.height, px);
                auto t0 = Clock::now();
                const RayHit hit = extractor_.cast(ray, mode);
                now.t_intersect_s += since(t0);
                ++now.rays;
                if (second_pass) ++frame.rays_second_pass;
                // A meta-cell whose triangles miss this pixel's surface gets its full-resolution
                // triangles drawn over (adaptive resolution only); any other unvisited hit seeds.
                if (hit.found && (hit.refine || !extractor_.visited(hit.cell))) {
                    if (options_.trace) options_.trace->switch_to(Stage::propagation);
                    t0 = Clock::now();
                    const auto id = static_cast<std::uint32_t>(frame.groups.size());
                    Group g = hit.refine ? extractor_.refine(hit.cell, hit.level, id, options_.propagation)
                                         : extractor_.propagate(hit.cell, id, options_.propagation,
                                                                ray, stop);
                    const double pass_s = since(t0);
                    const double extract_s = extractor_.last_extract_s();
                    now.t_extract_s += extract_s;
                    now.t_propagate_s += pass_s - extract_s;
                    if (stop()) return false;
                    if (options_.trace) options_.trace->switch_to(Stage::render);
                    if (!g.mesh.indices.empty() || !g.refinement) {
                        t0 = Clock::now();
                        renderer_.draw(g.mesh, view_m, proj_m);
                        now.t_render_s += since(t0);
                        dirty = true;
                        now.triangles += g.mesh.triangle_count();
                        frame.groups.push_back(std::move(g));
                    }
                    if (options_.trace) options_.trace->switch_to(Stage::intersection);
                }
                record(false);
            }
            if (order->wants_coverage()) {
                if (options_.trace) options_.trace->switch_to(Stage::render);
                const auto t0 = Clock::now();
                renderer_.read_back(coverage_image);
                covered.resize(coverage_image.depth.size());
                for (std::size_t i = 0; i < covered.size(); ++i) covered[i] = coverage_image.depth[i] < 1.0f;
                order->set_coverage(covered);
                now.t_render_s += since(t0);
                if (options_.trace) options_.trace->switch_to(Stage::intersection);
            }
            record(true);
        }
        return true;
    };

    bool done = cast_pass(options_.intersect, false);
    // Approximate seeds can miss a pixel whose first active cell's triangles do not cover it
    // (Figure 2.2): a second, exact pass over every pixel restores the guarantee (section 3.1.1).
    if (done && options_.intersect == IntersectMode::approximate)
        done = cast_pass(IntersectMode::exact, true);
    frame.completed = done;
    record(true);
    frame.rays_cast = now.rays;
    frame.elapsed_s = since(start);
    if (done) renderer_.read_back(frame.final_image);
    return frame;
}

void ProgressiveEngine::measure(FrameResult& frame, const FrameView& view,
                                const std::function<void(const TimelineSample&, const Image&)>& on_image) {
    if (frame.final_image.pixel_count() == 0) return;
    const glm::mat4 view_m = view.camera.view();
    const glm::mat4 proj_m = view.frustum.matrix();
    renderer_.resize(view.width, view.height);
    renderer_.clear();
    std::size_t drawn = 0;
    Image image;
    for (TimelineSample& s : frame.timeline) {
        for (; drawn < s.groups; ++drawn) renderer_.draw(frame.groups[drawn].mesh, view_m, proj_m);
        renderer_.read_back(image);
        s.correctness = measure_correctness(image, frame.final_image);
        if (on_image) on_image(s, image);
    }
}

}  // namespace isowall
