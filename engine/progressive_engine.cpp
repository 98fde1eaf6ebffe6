#include "engine/progressive_engine.h"

#include <memory>

#include "engine/frame_run.h"

namespace isowall {

ProgressiveEngine::ProgressiveEngine(SurfaceExtractor& extractor, EngineOptions options)
    : extractor_(extractor), options_(options) {}

FrameResult ProgressiveEngine::run(const FrameView& view, const PixelRect& region,
                                   const FrameOutput& out, const std::atomic<bool>& stop,
                                   const Progress& progress) {
    EngineFrame frame(*this, view, stop, progress);
    out.groups.begin(view);
    RegionCursor c = frame.cursor(view, region);
    const bool done = frame.cast(view, c, out);
    FrameResult result = frame.finish(done);
    result.rays_screen =
        static_cast<std::size_t>(region.width) * static_cast<std::size_t>(region.height);
    result.screen_rect = c.rect;
    result.screen_pixels = c.pixels;
    return result;
}

EngineFrame::EngineFrame(ProgressiveEngine& engine, const FrameView& view,
                         const std::atomic<bool>& stop, const ProgressiveEngine::Progress& progress)
    : run_(std::make_unique<FrameRun>(engine.extractor_, engine.options_, view, stop, progress)) {}

EngineFrame::~EngineFrame() = default;

RegionCursor EngineFrame::cursor(const FrameView& view, const PixelRect& region) const {
    return run_->cursor(view, region);
}

bool EngineFrame::cast(const FrameView& view, RegionCursor& c, const FrameOutput& out,
                       std::size_t ray_limit) {
    return run_->cast(view, c, out, ray_limit);
}

FrameResult EngineFrame::finish(bool completed) {
    return run_->finish(completed);
}

const TimelineSample& EngineFrame::now() const {
    return run_->now();
}

const WorkersCpu& EngineFrame::workers() const {
    return run_->workers_cpu();
}

}  // namespace isowall
