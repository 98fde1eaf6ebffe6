// ProgressiveEngine's one-call runs and its replay: one region into a sink, the whole screen
// drawn into a renderer keeping every group and the final image, and the replay that measures
// correctness (engine/progressive_engine.cpp holds the frame they run).
#include <atomic>

#include "engine/progressive_engine.h"
#include "render/renderer.h"

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

FrameResult ProgressiveEngine::run(const FrameView& view, Renderer& renderer,
                                   const std::atomic<bool>* stop, const Progress& progress) {
    static const std::atomic<bool> never{false};
    RendererSink draw(renderer);
    RecordingSink record;
    TeeSink both({&draw, &record});
    FrameResult frame = run(view, view.screen(), both, stop ? *stop : never, progress);
    frame.groups = std::move(record.groups);
    if (frame.completed) draw.read_back(frame.final_image);
    return frame;
}

void ProgressiveEngine::measure(
    FrameResult& frame, const FrameView& view, Renderer& renderer,
    const std::function<void(const TimelineSample&, const Image&)>& on_image) {
    if (frame.final_image.pixel_count() == 0) return;
    RendererSink replay(renderer);
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
