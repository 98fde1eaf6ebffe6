#include "tile/progressive_engine.h"

#include <algorithm>
#include <chrono>

#include <glm/matrix.hpp>

#include "common/core/ray.h"

namespace isowall {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kRefreshS = 1.0 / 60.0;

double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

PixelRect intersect(const PixelRect& a, const PixelRect& b) {
    const int x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
    const int x1 = std::min(a.x + a.width, b.x + b.width),
              y1 = std::min(a.y + a.height, b.y + b.height);
    return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
}

}  // namespace

// One frame, as named steps: begin (setup), then per ray-order level cast each ray
// (intersection), seed a propagation pass where it hits (propagation), hand the group to the sink
// (render), and between levels give the order the coverage (render). Each step switches the trace
// span, so a rank's CPU time is charged to the step that spent it.
class FrameRun {
  public:
    FrameRun(SurfaceExtractor& ex, const EngineOptions& opt, const FrameView& view, GroupSink& sink,
             const std::atomic<bool>& stop, const ProgressiveEngine::Progress& progress)
        : ex_(ex), opt_(opt), view_(view), sink_(sink), stop_(stop), progress_(progress) {}

    FrameResult run(const PixelRect& region) {
        begin(region);
        bool done = cast_pass(opt_.intersect, false);
        // Approximate seeds can miss a pixel whose first active cell's triangles do not cover it
        // (Figure 2.2): a second, exact pass over every pixel restores the guarantee
        // (section 3.1.1).
        if (done && opt_.intersect == IntersectMode::approximate)
            done = cast_pass(IntersectMode::exact, true);
        frame_.completed = done;
        record(true);
        frame_.rays_cast = now_.rays;
        frame_.elapsed_s = since(start_);
        return std::move(frame_);
    }

  private:
    void stage(Stage s) {
        if (opt_.trace) opt_.trace->switch_to(s);
    }
    bool stopped() const { return stop_.load(std::memory_order_relaxed); }

    void begin(const PixelRect& region) {
        stage(Stage::setup);
        start_ = Clock::now();
        view_m_ = view_.camera.view();
        view_inv_ = glm::inverse(view_m_);
        frame_.rays_screen =
            static_cast<std::size_t>(region.width) * static_cast<std::size_t>(region.height);
        const PixelRect clipped = intersect(region, view_.screen());
        frame_.screen_rect =
            opt_.screen_box
                ? intersect(clipped, screen_box(ex_.volume().bounds(), view_m_, view_.frustum,
                                                view_.width, view_.height))
                : clipped;
        ResolutionLevels levels;
        if (opt_.adaptive) {
            // D[] depends on the eye, the frustum and the pixel size only: once per frame.
            levels = resolution_levels(view_.camera, view_.frustum, view_.height,
                                       ex_.volume().spacing(), opt_.adaptive_max_level);
            levels.refine = opt_.adaptive_refine;
        }
        ex_.begin_frame(view_.iso, levels);
        sink_.begin(view_);
        extra_ = opt_.sample_at_rays;
        std::sort(extra_.begin(), extra_.end());
        stage(Stage::intersection);
    }

    bool cast_pass(IntersectMode mode, bool second_pass) {
        auto order = make_ray_order(opt_.order, view_.width, view_.height, frame_.screen_rect);
        while (order->next_level(pixels_)) {
            now_.level = order->level();
            for (const glm::ivec2 px : pixels_) {
                if (stopped()) return false;
                if (!cast_ray(px, mode, second_pass)) return false;
                record(false);
            }
            if (order->wants_coverage()) give_coverage(*order);
            record(true);
        }
        return true;
    }

    // One ray; false when the frame was stopped inside its propagation pass.
    bool cast_ray(glm::ivec2 px, IntersectMode mode, bool second_pass) {
        const Ray ray = pixel_ray(view_inv_, view_.frustum, view_.width, view_.height, px);
        const auto t0 = Clock::now();
        const RayHit hit = ex_.cast(ray, mode);
        now_.t_intersect_s += since(t0);
        ++now_.rays;
        if (second_pass) ++frame_.rays_second_pass;
        // A meta-cell whose triangles miss this pixel's surface gets its full-resolution triangles
        // drawn over (adaptive resolution only); any other unvisited hit seeds a pass.
        if (!hit.found || (!hit.refine && ex_.visited(hit.cell))) return true;
        return seed(hit, ray);
    }

    bool seed(const RayHit& hit, const Ray& ray) {
        stage(Stage::propagation);
        const auto t0 = Clock::now();
        const auto id = static_cast<std::uint32_t>(frame_.group_count);
        Group g = hit.refine ? ex_.refine(hit.cell, hit.level, id, opt_.propagation)
                             : ex_.propagate(hit.cell, id, opt_.propagation, ray, interrupted_);
        const double pass_s = since(t0);
        const double extract_s = ex_.last_extract_s();
        now_.t_extract_s += extract_s;
        now_.t_propagate_s += pass_s - extract_s;
        if (stopped()) return false;
        if (!g.mesh.indices.empty() || !g.refinement) {
            stage(Stage::render);
            const auto t1 = Clock::now();
            sink_.add(g);
            now_.t_render_s += since(t1);
            dirty_ = true;
            now_.triangles += g.mesh.triangle_count();
            ++frame_.group_count;
        }
        stage(Stage::intersection);
        return true;
    }

    void give_coverage(RayOrder& order) {
        stage(Stage::render);
        const auto t0 = Clock::now();
        if (!sink_.coverage(covered_))
            covered_.assign(
                static_cast<std::size_t>(view_.width) * static_cast<std::size_t>(view_.height), 0);
        order.set_coverage(covered_);
        now_.t_render_s += since(t0);
        stage(Stage::intersection);
    }

    // A timeline sample, after ray counts growing by a factor and at least every interval.
    void record(bool force) {
        now_.time_s = since(start_);
        while (next_extra_ < extra_.size() && extra_[next_extra_] < now_.rays) ++next_extra_;
        if (next_extra_ < extra_.size() && extra_[next_extra_] == now_.rays) force = true;
        if (!force && now_.rays < next_sample_rays_ &&
            now_.time_s - last_sample_s_ < opt_.sample_interval_s)
            return;
        // The sample shows what is on screen: present queued groups as a display would at its
        // next refresh. Presenting after every group would cost a full-screen flush each time
        // (about 7 ms at 1600x1200 in llvmpipe), so between refreshes a sample may count groups
        // still in flight: sample times are exact to one refresh (1/60 s).
        if (dirty_ && (force || now_.time_s - last_present_s_ >= kRefreshS)) {
            stage(Stage::render);
            now_.t_render_s += sink_.present();
            stage(Stage::intersection);
            now_.time_s = since(start_);
            last_present_s_ = now_.time_s;
            dirty_ = false;
        }
        now_.cells_visited = ex_.visited_count();
        now_.groups = frame_.group_count;
        frame_.timeline.push_back(now_);
        last_sample_s_ = now_.time_s;
        while (next_sample_rays_ <= now_.rays)
            next_sample_rays_ = std::max(
                next_sample_rays_ + 1,
                static_cast<std::size_t>(double(next_sample_rays_) * opt_.sample_ray_factor));
        if (progress_ && now_.time_s - last_progress_s_ >= opt_.progress_interval_s) {
            last_progress_s_ = now_.time_s;
            progress_(now_);
        }
    }

    SurfaceExtractor& ex_;
    const EngineOptions& opt_;
    const FrameView& view_;
    GroupSink& sink_;
    const std::atomic<bool>& stop_;
    const ProgressiveEngine::Progress& progress_;
    // What propagation polls; made once per frame, not once per pass.
    const std::function<bool()> interrupted_ = [this] { return stopped(); };

    FrameResult frame_;
    TimelineSample now_;
    Clock::time_point start_;
    glm::mat4 view_m_{1.0f}, view_inv_{1.0f};
    std::vector<std::size_t> extra_;
    std::size_t next_extra_ = 0, next_sample_rays_ = 1;
    // The first progress report comes at the first ray: a wall master then knows the frame began.
    double last_sample_s_ = 0, last_progress_s_ = -1e9, last_present_s_ = 0;
    bool dirty_ = false;  // groups added since the last present()
    std::vector<glm::ivec2> pixels_;
    std::vector<std::uint8_t> covered_;
};

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

FrameResult ProgressiveEngine::run(const FrameView& view, const PixelRect& region, GroupSink& sink,
                                   const std::atomic<bool>& stop, const Progress& progress) {
    return FrameRun(extractor_, options_, view, sink, stop, progress).run(region);
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
