#pragma once
// The engine's frame (engine/progressive_engine.h's EngineFrame): FrameRun casts a view's regions
// level by level, seeds passes, hands groups to a sink and samples the timeline. Internal to
// engine/: frame_run.h declares FrameRun and frame_run.cpp defines it (its levels, rays, seeds,
// passes, parallel levels and timeline samples); progressive_engine.cpp holds ProgressiveEngine
// and EngineFrame, which forward to it.
#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>

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
             const std::atomic<bool>& stop, const ProgressiveEngine::Progress& progress);

    RegionCursor cursor(const FrameView& view, const PixelRect& region) const;
    bool cast(const FrameView& view, RegionCursor& c, const FrameOutput& out,
              std::size_t ray_limit);
    FrameResult finish(bool completed);

    const TimelineSample& now() const { return now_; }
    const WorkersCpu& workers_cpu() const { return frame_.workers; }

  private:
    void stage(Stage s) {
        if (opt_.trace) opt_.trace->switch_to(s);
    }
    bool stopped() const { return stop_.load(std::memory_order_relaxed); }
    bool masked() const { return opt_.screen_box && opt_.screen_mask; }

    void begin(const FrameView& view);
    int workers() const;
    bool cast_level(RayOrder& order, bool second_pass);

    // One ray; false when the frame was stopped inside its propagation pass.
    bool cast_ray(glm::ivec2 px, IntersectMode mode, bool second_pass);

    // The region's end: seeds the cells beside hits whose pixels still show nothing
    // (beside_seeds.h); false when the frame was stopped in a pass.
    bool seed_beside();

    // A level's end, with covered_ just read back for the order (before the fill level): seeds
    // the frontier units of full passes and the cells beside hits whose pixels still show
    // nothing (beside_seeds.h); false when the frame was stopped in a pass. No coverage is read
    // while the dynamic grid sizes itself from the groups' own projections, so the seeds wait.
    bool seed_frontier();

    // Seeds each of `todo` still unvisited (a pass of one may take another's cell), on the
    // frame's threads; false when the frame was stopped in a pass.
    bool seed_all(const std::vector<BesideSeed>& todo);

    // The put-off sample of the level before (see cast_level), then the new level's number.
    void begin_level(int level);

    // One level over `n` threads (engine/parallel_level.h); false when the frame was stopped.
    // With `seeds`, the level is those seeds instead of the order's pixels (seed_frontier).
    bool cast_level_parallel(int n, IntersectMode mode, bool second_pass, int level,
                             const std::vector<BesideSeed>* seeds = nullptr);

    // Hands a group to the sink, charging its pass to the stages; true when it was one. A pass
    // whose seed another worker took first found no cell, and a refinement done already has no
    // triangle: neither is a group.
    bool add_found(FoundGroup& f);
    bool seed(const RayHit& hit, const Ray& ray);

    // True when covered_ holds what the sink shows now (a read-back).
    bool give_coverage(RayOrder& order);

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
    ActiveBoxes active_;               // the screen mask's nodes at this frame's isovalue
    PixelRect rect_;                   // the region being cast
    RegionCursor* cursor_ = nullptr;   // its cursor
    PropagationParams params_;         // the options, with the clip of the region being cast
    PropagationParams refine_params_;  // the options, with the frame's sample grid
    // The nearest footprint samples of the view whose sample grid is `depths_clip_` (reset when
    // a cast brings another view: a wall rank's jobs for other tiles).
    SampleDepths depths_;
    bool footprint_ = false;  // the frame's levels have footprint units
    glm::mat4 depths_clip_{0.0f};
    int depths_width_ = 0, depths_height_ = 0;
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
