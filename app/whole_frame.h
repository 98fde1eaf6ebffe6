#pragma once
// A whole view drawn by the progressive engine, and the replay that measures its correctness:
// what `isowall render`, the benchmarks and the engine's tests run. The engine hands groups to a
// sink and knows no renderer; here the two meet.
#include <atomic>
#include <functional>

#include "core/image.h"
#include "core/view.h"
#include "engine/progressive_engine.h"
#include "progressive/timeline.h"
#include "render/renderer.h"

namespace isowall {

// The whole screen of `view` drawn into `renderer` (warmed up beforehand: render/renderer.h
// warm_up), keeping every group and, when the frame completed, the final image in the result.
// Triangles that cover no pixel centre are not drawn (they change no pixel) unless the engine
// makes every triangle (EngineOptions::sampled_triangles off).
FrameResult draw_frame(ProgressiveEngine& engine, const FrameView& view, Renderer& renderer,
                       const std::atomic<bool>* stop = nullptr,
                       const ProgressiveEngine::Progress& progress = {});
// The same with an engine made for this one frame.
inline FrameResult draw_frame(ProgressiveEngine&& engine, const FrameView& view, Renderer& renderer,
                              const std::atomic<bool>* stop = nullptr,
                              const ProgressiveEngine::Progress& progress = {}) {
    return draw_frame(engine, view, renderer, stop, progress);
}

// The truth a final image is judged against: `mesh` drawn alone at kTruthSamples x kTruthSamples
// samples a pixel (progressive/correctness.h) and box-filtered to `view`'s size.
Image draw_truth(Renderer& renderer, const Mesh& mesh, const FrameView& view);

// Replays the frame's groups in order and measures both correctness measures of the image at
// every timeline sample against the final image (not part of the timed run). `on_image` sees
// each replayed image (the whole screen), e.g. to write snapshots; without it the replay reads
// back only the box of the pixels the final image covers (the only ones that count), and never
// twice for samples that show the same groups. The replay draws into `renderer`.
void measure_frame(FrameResult& frame, const FrameView& view, Renderer& renderer,
                   const std::function<void(const TimelineSample&, const Image&)>& on_image = {});

}  // namespace isowall
