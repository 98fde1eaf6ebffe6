#pragma once
// The engine's frame (engine/progressive_engine.h's EngineFrame): FrameRun casts a view's regions
// level by level, seeds passes, hands groups to a sink and samples the timeline. Internal to
// engine/: progressive_engine.cpp holds the rest of it, frame_run.cpp its parallel levels and
// timeline samples.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <vector>

#include <glm/matrix.hpp>

#include "core/ray.h"
#include "engine/beside_seeds.h"
#include "engine/parallel_level.h"
#include "engine/progressive_engine.h"

namespace isowall {
namespace frame_run {

using Clock = std::chrono::steady_clock;
constexpr double kRefreshS = 1.0 / 60.0;
// How often a present in flight is asked whether it is done (a context switch and a fence query
// per ask): a sample's time is late by at most this and one propagation pass.
constexpr double kPollS = 0.25e-3;
inline double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace frame_run

// One frame, as named steps: begin (setup), then per ray-order level cast each ray
// (intersection), seed a propagation pass where it hits (propagation), hand the group to the sink
// (render), and between levels give the order the coverage (render). Each step switches the trace
// span, so a rank's CPU time is charged to the step that spent it. One frame may cast several
// regions, of several views of one camera and isovalue (the jobs of a wall rank): they share the
// extractor's visited cells, so a group found in one region is not extracted again in another.
class FrameRun {
    using Clock = frame_run::Clock;
    static double since(Clock::time_point t0) { return frame_run::since(t0); }

  public:
    FrameRun(SurfaceExtractor& ex, const EngineOptions& opt, const FrameView& view,
             const std::atomic<bool>& stop, const ProgressiveEngine::Progress& progress)
        : ex_(ex), opt_(opt), stop_(stop), progress_(progress) {
        begin(view);
    }

    RegionCursor cursor(const FrameView& view, const PixelRect& region) const {
        return region_cursor(view, region,
                             opt_.screen_box ? std::optional(ex_.volume().bounds()) : std::nullopt,
                             masked() ? &active_.boxes : nullptr);
    }

    bool cast(const FrameView& view, RegionCursor& c, const FrameOutput& out,
              std::size_t ray_limit) {
        settle(true);  // a present in flight belongs to the sink of the last cast
        // The region's rays are intersection until a group, a coverage read or a present says
        // otherwise (the caller may have been in any stage: a wall job starts in render).
        stage(Stage::intersection);
        view_ = &view;
        sink_ = &out.groups;
        shown_ = out.shown;
        seen_ = out.seen;
        view_m_ = view.camera.view();
        view_inv_ = glm::inverse(view_m_);
        rect_ = c.rect;
        cursor_ = &c;
        params_ = opt_.propagation;
        params_.keep_frontier = opt_.frontier_seeds && shown_ != nullptr;
        if (opt_.region_clip) params_.clip = region_clip(view, c.rect, ex_.volume().spacing());
        // Saturating: a fine band's limit is SIZE_MAX, and c.rays + SIZE_MAX would wrap to below
        // c.rays, so a region's second band would cast nothing.
        const std::size_t limit = ray_limit > SIZE_MAX - c.rays ? SIZE_MAX : c.rays + ray_limit;
        while (!c.done && c.rays < limit) {
            if (!c.order) begin_order(c, opt_.order);
            const std::size_t before = now_.rays;
            const bool level = c.order->next_level(pixels_);
            if (level && !cast_level(*c.order, c.pass == 1)) {
                c.rays += now_.rays - before;
                return false;
            }
            c.rays += now_.rays - before;
            if (level) continue;
            // Approximate seeds can miss a pixel whose first active cell's triangles do not cover
            // it (Figure 2.2): a second, exact pass over every pixel restores the guarantee
            // (section 3.1.1).
            c.order.reset();
            if (c.pass == 0 && opt_.intersect == IntersectMode::approximate)
                c.pass = 1;
            else
                c.done = true;
        }
        if (c.done && !seed_beside()) return false;
        // A sample at every job's end, but no present (groups show at the next refresh: a
        // present flushes the renderer, which llvmpipe pays per call, not per triangle), unless
        // the last level's present was put off (see cast_level).
        record(true, present_due_);
        present_due_ = false;
        return true;
    }

    FrameResult finish(bool completed) {
        frame_.completed = completed;
        record(true);
        settle(true);
        frame_.rays_cast = now_.rays;
        frame_.elapsed_s = since(start_);
        return std::move(frame_);
    }

    const TimelineSample& now() const { return now_; }
    const WorkersCpu& workers_cpu() const { return frame_.workers; }

  private:
    void stage(Stage s) {
        if (opt_.trace) opt_.trace->switch_to(s);
    }
    bool stopped() const { return stop_.load(std::memory_order_relaxed); }
    bool masked() const { return opt_.screen_box && opt_.screen_mask; }

    void begin(const FrameView& view) {
        stage(Stage::setup);
        start_ = Clock::now();
        const ResolutionLevels levels = frame_levels(opt_, view, ex_.volume().spacing());
        if (opt_.begin_extractor_frame) ex_.begin_frame(view.iso, levels);
        if (masked()) {
            active_ = screen_mask_nodes(ex_, view.iso, levels);
            frame_.mask_level = active_.level;
            frame_.mask_nodes = active_.boxes.size();
        }
        frame_.group_count = 0;
        extra_ = opt_.sample_at_rays;
        std::sort(extra_.begin(), extra_.end());
        stage(Stage::intersection);
    }

    int workers() const {
        const int have = ex_.threads();
        return std::max(1, opt_.threads <= 0 ? have : std::min(opt_.threads, have));
    }

    bool cast_level(RayOrder& order, bool second_pass) {
        const IntersectMode mode = second_pass ? IntersectMode::exact : opt_.intersect;
        const int n = workers();
        const bool parallel = n > 1 && pixels_.size() > 1;
        if (parallel) {
            if (!cast_level_parallel(n, mode, second_pass, order.level())) return false;
        } else {
            begin_level(order.level());
            for (const glm::ivec2 px : pixels_) {
                if (stopped()) return false;
                if (!cast_ray(px + glm::ivec2(rect_.x, rect_.y), mode, second_pass)) return false;
                record(false);
            }
        }
        if (order.wants_coverage() && give_coverage(order) && !seed_frontier()) return false;
        // After a level on several threads, its sample (and present, which waits for the
        // rasteriser) waits until the next level's other threads cast, or the job's end.
        present_due_ = parallel;
        if (!parallel) record(true);
        return true;
    }

    // One ray; false when the frame was stopped inside its propagation pass.
    bool cast_ray(glm::ivec2 px, IntersectMode mode, bool second_pass) {
        const Ray ray = pixel_ray(view_inv_, view_->frustum, view_->width, view_->height, px);
        const auto t0 = Clock::now();
        const RayHit hit = ex_.cast(ray, mode);
        now_.t_intersect_s += since(t0);
        ++now_.rays;
        if (second_pass) ++frame_.rays_second_pass;
        // A meta-cell whose triangles miss this pixel's surface gets its full-resolution triangles
        // drawn over (adaptive resolution only); any other unvisited hit seeds a pass.
        if (hit.found) ++cursor_->hits;
        if (!hit.found) return true;
        if (!hit.refine && ex_.visited(hit.cell)) {
            if (seen_) seen_->seen(ex_.group_of(hit.cell));
            note_beside(ex_, hit, ray, px, mode == IntersectMode::exact, cursor_->beside);
            return true;
        }
        return seed(hit, ray);
    }

    // The region's end: seeds the cells beside hits whose pixels still show nothing
    // (beside_seeds.h); false when the frame was stopped in a pass.
    bool seed_beside() {
        stage(Stage::render);
        const std::vector<BesideSeed> todo =
            take_still_empty(cursor_->beside, shown_, rect_, covered_);
        stage(Stage::intersection);
        return seed_all(todo);
    }

    // A level's end, with covered_ just read back for the order (before the fill level): seeds
    // the frontier units of full passes and the cells beside hits whose pixels still show
    // nothing (beside_seeds.h); false when the frame was stopped in a pass. No coverage is read
    // while the dynamic grid sizes itself from the groups' own projections, so the seeds wait.
    bool seed_frontier() {
        if (!opt_.frontier_seeds) return true;
        // The cells beside hits (pinholes) go too: the fill level would reach their pixels late.
        std::vector<BesideSeed> todo = take_still_empty(cursor_->beside, rect_, covered_);
        const std::vector<BesideSeed> frontier =
            take_frontier_still_empty(cursor_->frontier, ex_, *view_, view_inv_, rect_, covered_);
        todo.insert(todo.end(), frontier.begin(), frontier.end());
        return seed_all(todo);
    }

    // Seeds each of `todo` still unvisited (a pass of one may take another's cell), on the
    // frame's threads; false when the frame was stopped in a pass.
    bool seed_all(const std::vector<BesideSeed>& todo) {
        const int n = workers();
        if (n > 1 && todo.size() > 1)
            return cast_level_parallel(n, opt_.intersect, false, now_.level, &todo);
        for (const BesideSeed& b : todo)
            if (!ex_.visited(b.cell) && (stopped() || !seed({true, b.cell}, b.ray))) return false;
        return true;
    }

    // The put-off sample of the level before (see cast_level), then the new level's number.
    void begin_level(int level) {
        if (present_due_) record(true);
        present_due_ = false;
        now_.level = level;
    }

    // One level over `n` threads (engine/parallel_level.h); false when the frame was stopped.
    // With `seeds`, the level is those seeds instead of the order's pixels (seed_frontier).
    bool cast_level_parallel(int n, IntersectMode mode, bool second_pass, int level,
                             const std::vector<BesideSeed>* seeds = nullptr);

    // Hands a group to the sink, charging its pass to the stages; true when it was one. A pass
    // whose seed another worker took first found no cell, and a refinement done already has no
    // triangle: neither is a group.
    bool add_found(FoundGroup& f) {
        Group& g = f.group;
        keep_frontier(*cursor_, g.frontier, ex_);
        now_.t_extract_s += f.extract_s;
        now_.t_propagate_s += f.pass_s - f.extract_s;
        if (g.refinement ? g.mesh.indices.empty() : g.cells.empty()) return false;
        stage(Stage::render);
        const auto t1 = Clock::now();
        if (cursor_->sizing) add_drawn(*cursor_, g.mesh, view_m_, *view_);
        sink_->add(g);
        now_.t_render_s += since(t1);
        dirty_ = true;
        now_.triangles += g.mesh.triangle_count();
        ++frame_.group_count;
        stage(Stage::intersection);
        return true;
    }

    bool seed(const RayHit& hit, const Ray& ray) {
        stage(Stage::propagation);
        const auto t0 = Clock::now();
        const auto id = opt_.first_group_id + ids_used_;
        FoundGroup f;
        f.group = hit.refine ? ex_.refine(hit.cell, hit.level, id, opt_.propagation)
                             : ex_.propagate(hit.cell, id, params_, ray, interrupted_);
        f.pass_s = since(t0);
        // Extraction is timed on 1 unit in 16 and scaled: the estimate may overshoot a short pass.
        f.extract_s = std::min(ex_.last_extract_s(), f.pass_s);
        if (stopped()) {
            now_.t_extract_s += f.extract_s;
            now_.t_propagate_s += f.pass_s - f.extract_s;
            return false;
        }
        ids_used_ += add_found(f) ? 1 : 0;
        stage(Stage::intersection);
        return true;
    }

    // True when covered_ holds what the sink shows now (a read-back).
    bool give_coverage(RayOrder& order) {
        // Before any ray of the region has met the surface, what shows there is at most the edge
        // of a group found elsewhere: the order is left searching, which saves a read-back (a
        // renderer flush) and a screen-sized copy per level in every region of background.
        if (cursor_->hits == 0) return false;
        stage(Stage::render);
        const auto t0 = Clock::now();
        const bool read = give_order_coverage(order, *cursor_, shown_, covered_);
        now_.t_render_s += since(t0);
        stage(Stage::intersection);
        return read;
    }

    // A timeline sample, after ray counts growing by a factor and at least every interval.
    void record(bool force, bool present_now = true);
    // The sample of a present in flight, timed and kept once its groups show (`wait`: now);
    // true when it was kept.
    bool settle(bool wait);
    void push(const TimelineSample& s);

    SurfaceExtractor& ex_;
    const EngineOptions& opt_;
    const FrameView* view_ = nullptr;
    GroupSink* sink_ = nullptr;  // the output of the region being cast
    ShownPixels* shown_ = nullptr;
    SeenGroups* seen_ = nullptr;
    const std::atomic<bool>& stop_;
    const ProgressiveEngine::Progress progress_;  // a copy: callers pass temporaries
    // What propagation polls; made once per frame, not once per pass.
    const std::function<bool()> interrupted_ = [this] { return stopped(); };

    FrameResult frame_;
    TimelineSample now_;
    Clock::time_point start_;
    glm::mat4 view_m_{1.0f}, view_inv_{1.0f};
    ActiveBoxes active_;              // the screen mask's nodes at this frame's isovalue
    PixelRect rect_;                  // the region being cast
    RegionCursor* cursor_ = nullptr;  // its cursor
    PropagationParams params_;        // the options, with the clip of the region being cast
    std::vector<std::size_t> extra_;
    std::size_t next_extra_ = 0, next_sample_rays_ = 1;
    // The first progress report comes at the first ray: a wall master then knows the frame began.
    double last_sample_s_ = 0, last_progress_s_ = -1e9;
    double last_present_cpu_s_ = thread_cpu_seconds();
    bool dirty_ = false;        // groups added since the last present()
    bool present_due_ = false;  // a level's sample and present put off (see cast_level)
    std::optional<TimelineSample> pending_;  // its present in flight (GroupSink::present_async)
    double last_poll_s_ = 0;                 // when pending_'s present was last asked about
    // Group ids handed out this frame, from opt_.first_group_id: the groups added, and with
    // several threads also the passes dropped because another took their seed first.
    std::uint32_t ids_used_ = 0;
    std::vector<glm::ivec2> pixels_;
    std::vector<std::uint8_t> covered_;
};

}  // namespace isowall
