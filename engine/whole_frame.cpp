// ProgressiveEngine's one-call runs and its replay: one region into a sink, the whole screen
// drawn into a renderer keeping every group and the final image, and the replay that measures
// correctness (engine/progressive_engine.cpp holds the frame they run).
#include <atomic>
#include <optional>

#include "common/core/image_ops.h"
#include "common/core/pixel_rect_ops.h"
#include "common/progressive/correctness.h"

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
    // Only the pixels the final image covers count (correctness.h), so without a caller that
    // wants whole images the replay reads back their box alone; and a sample that shows no group
    // more than the one before shows the same image, so it is not read back again.
    const PixelRect box = on_image
                              ? PixelRect{0, 0, frame.final_image.width, frame.final_image.height}
                              : covered_box(frame.final_image);
    if (is_empty(box)) {
        for (TimelineSample& s : frame.timeline)
            s.correctness = measure_correctness(frame.final_image, frame.final_image);
        return;
    }
    const Image final_box = on_image ? Image{} : crop(frame.final_image, box);
    const Image& against = on_image ? frame.final_image : final_box;
    RendererSink replay(renderer);
    replay.begin(view);
    std::size_t drawn = 0;
    Image image;
    std::optional<std::size_t> shown;  // the groups the image shows
    Correctness last;
    for (TimelineSample& s : frame.timeline) {
        for (; drawn < s.groups; ++drawn) replay.add(frame.groups[drawn]);
        if (shown != s.groups) {
            if (on_image)
                replay.read_back(image);
            else
                replay.read_back(image, box);
            last = measure_correctness(image, against);
            shown = s.groups;
        }
        s.correctness = last;
        if (on_image) on_image(s, image);
    }
}

}  // namespace isowall
