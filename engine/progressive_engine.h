#pragma once
// The progressive view-dependent engine (chapters 2-3): fills a region of one view's pixels (a
// whole screen, a wall tile or a screen-region job) ray by ray in a progressive order until every
// pixel of the region that the volume covers has had its ray, or until it is stopped. Each ray that
// finds an unvisited seed starts a propagation pass; the pass's group goes at once to a group sink
// (extract/group_sink.h: drawn into the frame being built, with no clear and no redraw of older
// groups, so drawing cost follows new triangles only; recorded for the replay; streamed to a
// client). The engine draws nothing and sees no renderer.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "core/view.h"
#include "engine/region_cursor.h"
#include "extract/adaptive.h"
#include "extract/group_sink.h"
#include "extract/surface_extractor.h"
#include "progressive/correctness.h"
#include "progressive/ray_order.h"
#include "progressive/timeline.h"
#include "progressive/trace.h"

namespace isowall {

struct EngineOptions {
    // Called on every group's mesh before it reaches the sink (the frame's thread): what colours
    // a surface by a second field (volume/colour_field.h), so that whatever the sink draws,
    // records or sends is coloured alike. Empty: the surface's one colour.
    std::function<void(Mesh&)> colour;
    RayOrderKind order = RayOrderKind::dynamic_grid;
    IntersectMode intersect = IntersectMode::exact;
    PropagationParams propagation;
    bool screen_box = true;  // cast no ray outside the volume's projected bounding box
    // Within the box, cast no ray whose pixel no active node of a coarse octree level covers
    // (progressive/screen_mask.h): such a ray cannot meet the surface. Needs screen_box.
    bool screen_mask = true;
    // Propagation enters only cells that may project into the region being cast (ScreenClip):
    // a wall tile or job extracts no surface its region cannot show. Off: passes run over the
    // whole surface within their limits, as in the text.
    bool region_clip = false;
    // Triangles only where they may show: a unit whose projection holds no pixel centre of the
    // frame is propagated through but not triangulated (extract/propagator.h SampleGrid), as no
    // triangle of it would write a fragment. The frame is the same; off, groups hold every
    // triangle, for a viewer that draws them in other views (a remote server's group cache).
    bool sampled_triangles = true;
    // Frontier seeds: a propagation pass that fills its max count (count mode) stops short of
    // the surface beyond it, which then waits for the rays of its own pixels; at the screen's
    // fill level (the last, with most of the rays) those are the slivers between passes'
    // patches that keep C = 1 - E below 99%. With this, when the order reads what shows before
    // that level, the engine first seeds the units full passes left out whose pixels still show
    // nothing. Needs a sink that can tell coverage; off: the text's passes alone.
    bool frontier_seeds = true;
    // Adaptive resolution (chapter 2.1.3): where a meta-cell of 2^i cells per side projects to
    // less than a pixel, extract it as one cell, up to 2^adaptive_max_level cells per side. Off:
    // every cell at full resolution, exactly as without the option. adaptive_refine: draw a
    // meta-cell again at full resolution where a pixel's ray sees the full-resolution surface that
    // its triangles miss (extract/adaptive.h); false: the text's distance rule alone.
    bool adaptive = false;
    int adaptive_max_level = kMaxMetaLevel;
    bool adaptive_refine = true;
    // The projected size, in pixels, below which a meta-cell is taken (resolution_levels): 1 is
    // the text's rule; 2 keeps triangles about a pixel on volumes finer than the screen.
    float adaptive_pixels = 1.0f;
    // The error rule (volume/lod_error.h): a meta-cell is also taken only where its
    // surface lies within this many pixels of the full-resolution surface, projected. Infinite:
    // the distance rule alone.
    float adaptive_error_px = std::numeric_limits<float>::infinity();
    // Footprint units (extract/footprint.h), with sampled_triangles and without adaptive or
    // uniform levels: where a meta-cell of up to 2^kMaxMetaLevel cells a side projects below
    // this many pixels, propagation walks it as one unit, which shows the full-resolution surface
    // at the pixel centres it covers. The picture is that of every full-resolution triangle, and
    // the work follows the pixels rather than the cells. 0: every cell at full resolution.
    float footprint_pixels = 4.0f;
    // Threads casting rays and propagating side by side over each ray-order level: at most the
    // extractor's workers (its thread budget); 0: all of them. The calling thread is one of them
    // and alone draws (the renderer's context is its own), taking the groups in the order of
    // their ids. A sink that wants seen() gets one thread. With more than one, group ids may skip
    // a number where two threads met one seed at once (the later pass finds it taken and is
    // dropped), and the groups found differ from run to run; the final image does not.
    int threads = 1;
    // Timeline sampling: after ray counts growing by this factor, and at least this often.
    double sample_ray_factor = 1.25;
    double sample_interval_s = 0.1;
    // Optional per-stage spans with thread CPU time (wall runs); null: no spans.
    TraceRecorder* trace = nullptr;
    // How often run() calls its progress callback (at sample points).
    double progress_interval_s = 0.5;
    // Extra samples exactly when these ray counts are reached (snapshots by rays).
    std::vector<std::size_t> sample_at_rays;
    // Remote viewing (sections 4.1.3-4.1.4). uniform_level > 0: every unit is a meta-cell of
    // 2^uniform_level cells per side (where the meta-cell is complete; the volume's border falls
    // back to cells), with no refinement: a coarse level of progressive LOD. Overrides adaptive.
    int uniform_level = 0;
    // False: the frame goes on from the extractor's visited cells instead of forgetting them (the
    // caller began the extractor's frame at the view's isovalue and may have marked cells taken
    // by groups a client caches); new groups' ids then start at first_group_id.
    bool begin_extractor_frame = true;
    std::uint32_t first_group_id = 0;
};

// The CPU of the engine's threads other than the caller's (EngineOptions::threads > 1), summed
// over the frame's levels: their CPU seconds, and by how much each level's busiest worker
// outlasted the caller. The caller's thread CPU plus beyond_s is the frame's time on cores of its
// own (each level ends when its last thread does); plus sum_s, the CPU it used on all of them.
struct WorkersCpu {
    double sum_s = 0, beyond_s = 0;
};

struct FrameResult {
    bool completed = false;  // false: interrupted before the last ray
    std::size_t rays_cast = 0;
    std::size_t rays_screen = 0;  // width * height: the share of rays is rays_cast / rays_screen
    std::size_t rays_second_pass = 0;  // approximate mode: rays cast again exactly
    double elapsed_s = 0;
    std::size_t group_count = 0;
    std::vector<Group> groups;  // every group in order (app/whole_frame.h's run only)
    std::vector<TimelineSample> timeline;
    Image final_image;  // colour and depth after the last ray (app/whole_frame.h's run only;
                        // empty when interrupted)
    // Of the triangles drawn, those that cover a pixel centre (app/whole_frame.h's run only: its
    // drawing leaves the others out, render/renderer_sink.h).
    std::size_t triangles_drawn = 0;
    PixelRect screen_rect;  // the pixels cast: the region clipped to the volume's screen box
    std::size_t screen_pixels = 0;  // of them, the pixels to cast (the screen mask's, if on)
    // The screen mask's octree level and active nodes (-1 and 0 without the mask).
    int mask_level = -1;
    std::size_t mask_nodes = 0;
    WorkersCpu workers;
};

class FrameRun;

class ProgressiveEngine {
  public:
    // The engine draws nothing: each group goes to the output a run is given. The whole screen
    // drawn into a renderer, and the correctness replay, are app/whole_frame.h's.
    explicit ProgressiveEngine(SurfaceExtractor& extractor, EngineOptions options = {});

    using Progress = std::function<void(const TimelineSample&)>;

    // Fills `region` of `view`'s screen, handing each group to `out`. `stop` is read between rays
    // and inside long propagation passes (a communication thread sets it when a new view
    // arrives); once it reads true the frame ends at once with completed = false. `progress`
    // (optional) sees the latest sample about every options().progress_interval_s.
    FrameResult run(const FrameView& view, const PixelRect& region, const FrameOutput& out,
                    const std::atomic<bool>& stop, const Progress& progress = {});

    const EngineOptions& options() const { return options_; }

  private:
    friend class EngineFrame;
    SurfaceExtractor& extractor_;
    EngineOptions options_;
};

// One frame cast region by region, for callers that split the screen into jobs (a wall rank).
// Every region cast in it, of any view of the frame's camera and isovalue, shares one set of
// visited cells: a sink that is to show a region must therefore also hold the groups found
// earlier in the frame for other regions (see tile/tile_jobs.cpp).
class EngineFrame {
  public:
    // Begins the extractor's frame for `view`'s isovalue (and its pixel size, for adaptive
    // resolution). The engine must outlive the frame.
    EngineFrame(ProgressiveEngine& engine, const FrameView& view, const std::atomic<bool>& stop,
                const ProgressiveEngine::Progress& progress = {});
    ~EngineFrame();
    EngineFrame(const EngineFrame&) = delete;
    EngineFrame& operator=(const EngineFrame&) = delete;

    // The cursor of `region` of `view`: clipped to the screen and to the volume's screen box, and
    // masked by the frame's screen mask (EngineOptions::screen_mask).
    RegionCursor cursor(const FrameView& view, const PixelRect& region) const;
    // Casts whole ray-order levels of `c` into `out` until it has cast `ray_limit` more rays or is
    // done; `view` must be the one the cursor was made for. False when stopped (c stays where it
    // was).
    bool cast(const FrameView& view, RegionCursor& c, const FrameOutput& out,
              std::size_t ray_limit = SIZE_MAX);
    // The frame's figures and timeline (groups and the final image are not kept here).
    FrameResult finish(bool completed);
    // The latest sample: rays, groups, triangles of the frame so far.
    const TimelineSample& now() const;
    // The workers' CPU so far (threads > 1).
    const WorkersCpu& workers() const;

  private:
    std::unique_ptr<FrameRun> run_;
};

}  // namespace isowall
