#include "app/whole_frame.h"

#include <atomic>
#include <optional>

#include "core/image_ops.h"
#include "core/pixel_rect_ops.h"
#include "progressive/correctness.h"

#include "render/renderer_sink.h"

namespace isowall {

FrameResult draw_frame(ProgressiveEngine& engine, const FrameView& view, Renderer& renderer,
                       const std::atomic<bool>* stop, const ProgressiveEngine::Progress& progress) {
    static const std::atomic<bool> never{false};
    RendererSink draw(renderer, !engine.options().sampled_triangles);
    RecordingSink record;
    TeeSink both({&draw, &record});
    FrameResult frame = engine.run(view, view.screen(), FrameOutput(both, &draw, nullptr),
                                   stop ? *stop : never, progress);
    frame.groups = std::move(record.groups);
    frame.triangles_drawn = draw.drawn_triangles();
    if (frame.completed) draw.read_back(frame.final_image);
    return frame;
}

Image draw_truth(Renderer& renderer, const Mesh& mesh, const FrameView& view) {
    FrameView big = view;
    big.width *= kTruthSamples;
    big.height *= kTruthSamples;
    return box_filtered_truth(draw_alone(renderer, mesh, big), kTruthSamples);
}

void measure_frame(FrameResult& frame, const FrameView& view, Renderer& renderer,
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
