#pragma once
// A wall rank's work in one frame, job by job (the scheduler's side on a tile rank; the master's
// side is master/job_board.h). A rank draws every group it extracts into its own tile's image,
// whatever job found it: all jobs of a frame share one set of visited cells (EngineFrame), so a
// group found for another tile may be the one a later ray of its own tile hits. A job for another
// tile (the owner) is drawn into a region image of the owner's view and sent to the owner, which
// composites it by depth into what its tile shows.
//
// A region's image needs the groups found earlier in the frame whose cells its rays meet: the
// engine casts no new pass there. Each is drawn once a ray of the job meets one of its cells (the
// engine's seen()), not up front: most earlier groups that project onto a region only touch its
// edge. A region's fine band on the rank that cast its coarse band draws only what it adds: the
// coarse band's result is at the owner already, which composites the two by depth, and the
// coarse band's coverage stands in for its groups where the engine asks what is covered. Drawing
// the coarse band's groups again was 45% of the triangles helpers drew on a one-tile head.
#include <atomic>
#include <map>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "core/box.h"
#include "engine/progressive_engine.h"
#include "render/renderer_sink.h"
#include "wall_protocol/protocol.h"

namespace isowall {

// The view of `rect` of `owner`'s screen as a screen of its own: the same camera and pixels.
FrameView region_view(const FrameView& owner, const PixelRect& rect);

class TileJobs {
  public:
    // `tile` draws the rank's own frame, `help` the regions it fills for other tiles. With
    // `measure`, each job's result is kept with its emulated time for curve().
    TileJobs(ProgressiveEngine& engine, Renderer& tile, Renderer& help, bool measure);

    // Sizes the tile's frame and buffers for a tile of width x height, as a start-up cost: the
    // first frame then pays no first-touch allocation (about 40 ms at 1024x768 in llvmpipe).
    void prepare(int width, int height);
    // A new frame of the rank's own view: everything of the last frame is dropped.
    void begin(const ViewMsg& v, const std::atomic<bool>& stop,
               const ProgressiveEngine::Progress& progress);
    bool started() const { return frame_ != nullptr; }
    std::uint64_t generation() const { return generation_; }

    struct Outcome {
        bool completed = false;  // false: stopped by a new view or quit
        JobDoneMsg done;
        std::optional<RegionMsg> result;  // for the owner, when it is another rank
    };
    Outcome run(const JobMsg& job, int rank);

    // With `measure`, during a job for the rank's own tile (the engine's progress points), after
    // present_own(): keeps what the tile shows of the job's region, at most every kShotIntervalS
    // of busy CPU. The copy is not counted as busy.
    void measure_point();
    // With `measure`, during a job for the rank's own tile: draws the queued groups, as busy time
    // (a display shows them at its next refresh anyway), so that measure_point's copy, the
    // measurement's own cost, can be charged apart.
    void present_own();
    static constexpr double kShotIntervalS = 0.002;
    // CPU the caller spent inside a job on something that is not the job's (showing the frame in
    // a window): left out of the job's time and the emulated clock.
    void exclude_cpu(double cpu_s) { job_measure_cpu_ += cpu_s; }

    // A helper's result for this rank's tile, composited by depth into what the tile shows.
    // Throws WireError when the rect is not inside the tile.
    void land(RegionMsg m);

    // What the tile shows now: its own drawing with every landed result over it.
    Image image();
    // CPU seconds the frame thread spent in this frame's jobs and landings (and what the caller
    // adds: sending results): a rank's emulated clock, as if it had a core of its own. With
    // several engine threads, each level counts until its last thread ends (WorkersCpu).
    double busy_cpu_s() const { return busy_cpu_s_; }
    void add_busy(double cpu_s) { busy_cpu_s_ += cpu_s; }
    // Wall seconds from the frame's start to its last job's end.
    double frame_wall_s() const { return wall_end_ - wall0_; }
    const TimelineSample& now() const { return frame_->now(); }
    // By how much the engine's workers outlasted the frame thread in this frame's levels.
    double workers_beyond_s() const { return frame_ ? frame_->workers().beyond_s : 0.0; }

    // The correctness of what the tile showed against its final image (image()) at each job end,
    // in emulated time (each rank's CPU clock from the frame's start). Needs `measure`.
    std::vector<CurvePoint> curve(std::uint64_t& significant);

  private:
    using RegionKey = std::tuple<int, int, int>;  // (owner, x, y)
    struct Recorded {
        Group group;
        Box3 bounds;
        RegionKey found_by;
        std::uint64_t drawn_in = 0;  // the last help job whose image has it
    };
    class JobSink;
    // The groups whose cells the job's rays met (seen), into the help image, once each; not those
    // of the region's earlier band (in the owner's image already).
    void draw_seen_groups();
    // A completed help job's result for the owner: its image drawn, read back and cropped to
    // what it covers (and, after a coarse band, that coverage kept for the fine band).
    RegionMsg help_result(const JobMsg& job, const RegionKey& key);
    // The help image's coverage of `rect`, with what the region's earlier band covered.
    void help_coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect);
    // Whether a group with these bounds may show in `view` (its projected box touches it).
    static bool shows(const Box3& bounds, const FrameView& view);

    ProgressiveEngine& engine_;
    RendererSink tile_sink_, help_sink_;
    bool measure_;
    std::unique_ptr<EngineFrame> frame_;
    std::uint64_t generation_ = 0;
    FrameView own_;
    std::vector<Recorded> groups_;
    std::unordered_map<std::uint32_t, std::size_t> group_index_;  // group id -> groups_
    std::map<RegionKey, RegionCursor> cursors_;
    // The help job running (counted from 1), the job's region, and the groups the job saw.
    std::uint64_t help_job_ = 0;
    RegionKey job_key_;
    std::vector<std::uint32_t> seen_;
    // A help region's coverage at the end of its coarse band (region-local, row-major), for its
    // fine band; and the one of the help job running, or null.
    std::map<RegionKey, std::vector<std::uint8_t>> band_cover_;
    const std::vector<std::uint8_t>* earlier_cover_ = nullptr;
    int help_width_ = 0;
    Image landed_;  // helpers' results, composited by depth; depth 1 where none
    bool landed_any_ = false;
    double wall0_ = 0, wall_end_ = 0;
    double busy_cpu_s_ = 0;
    double last_draw_s_ = 0;  // emulated time of this rank's last job: its own image is final
    bool in_own_job_ = false;
    PixelRect job_rect_;
    double job_c0_ = 0, job_measure_cpu_ = 0, job_beyond0_ = 0, last_shot_s_ = -1;
    // The job's busy CPU up to `now` (the frame thread's clock).
    double job_cpu_s(double now) const;
    struct Shot {
        double emulated_s;
        PixelRect rect;
        Image image;
        bool own;  // the tile's own drawing (replaces), or a landed result (composites)
    };
    std::vector<Shot> shots_;
};

}  // namespace isowall
