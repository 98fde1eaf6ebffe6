#pragma once
// A wall rank's jobs for a picture of several surfaces (core/surface_style.h): one TileJobs a
// surface, each with an engine of its own (over an extractor sharing the octree, colouring its
// groups in the surface's colour) and tile and help renderers of its own. A job runs for every
// surface in turn over the same region; a helper's result for another tile carries its layer and
// lands in that surface's jobs there, by depth as one surface's would; what the tile shows is its
// layers composited back to front (core/image_ops.h composite_layers). Each layer is what one
// surface alone draws, so a region drawn by a helper composites exactly as one drawn at home. With
// one plain surface, this is TileJobs itself.
#include <atomic>
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

#include "core/surface_style.h"
#include "engine/progressive_engine.h"
#include "extract/surface_extractor.h"
#include "render/renderer.h"
#include "tile/tile_jobs.h"
#include "wall_protocol/protocol.h"

namespace isowall {

struct LayeredJobsSetup {
    SurfaceExtractor* extractor;  // the first surface's; the others share its octree
    Renderer& tile;               // the first surface's tile and help renderers
    Renderer& help;
    EngineOptions engine;  // every surface's, but for the colour (a second field's colours all)
    // Renderers for the other surfaces (two each); empty: one surface only.
    std::function<std::unique_ptr<Renderer>()> make_renderer;
    bool measure = false;
};

class LayeredJobs {
  public:
    explicit LayeredJobs(LayeredJobsSetup setup);
    ~LayeredJobs();

    void prepare(int width, int height);
    // Another volume from the next frame on (a time step, volume/time_steps.h): every surface's
    // engine is made again over `extractor`, which must outlive its use here.
    void use_extractor(SurfaceExtractor& extractor);
    // A new frame: the surfaces of `v` (one plain one at v.view.iso when it lists none).
    void begin(const ViewMsg& v, const std::atomic<bool>& stop,
               const ProgressiveEngine::Progress& progress);
    bool started() const;
    std::uint64_t generation() const;

    struct Outcome {
        bool completed = false;          // false: stopped by a new view or quit
        JobDoneMsg done;                 // summed over the surfaces
        std::vector<RegionMsg> results;  // for the owner, one a surface, when it is another rank
    };
    Outcome run(const JobMsg& job, int rank);

    // TileJobs's, for the surface whose job runs.
    void measure_point();
    void present_own();
    void exclude_cpu(double cpu_s);
    // A helper's result, into its surface's layer; a WireError when the view has no such layer or
    // it came twice. True when it was the job's last: every surface's result of the job is in.
    bool land(RegionMsg m);
    // The layers composited.
    Image image();
    double busy_cpu_s() const;
    void add_busy(double cpu_s);
    double frame_wall_s() const { return wall_end_ - wall0_; }
    // Every surface's figures so far, summed.
    TimelineSample now() const;
    double workers_beyond_s() const;
    // The curve of one surface (TileJobs::curve); a picture of several is not measured
    // (std::logic_error: the master refuses --measure with several surfaces).
    std::vector<CurvePoint> curve(std::uint64_t& significant);

  private:
    struct Layer;
    // Layer k built for `style` (its engine colours as the style says), kept between frames.
    Layer& layer(std::size_t k, const SurfaceStyle& style);

    LayeredJobsSetup setup_;
    std::vector<std::unique_ptr<Layer>> layers_;
    std::size_t active_ = 0;   // the layers of this frame
    std::size_t running_ = 0;  // the layer whose job runs
    double wall0_ = 0, wall_end_ = 0;
    // The layers landed of each helped job of the frame, a bit a layer.
    std::unordered_map<std::uint32_t, std::uint32_t> landed_;
};

}  // namespace isowall
