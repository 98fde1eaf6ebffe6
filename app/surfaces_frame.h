#pragma once
// Several isosurfaces of one volume drawn together (core/surface_style.h): each surface's
// progressive frame is cast by an engine of its own (over an extractor that shares the octree)
// into a renderer of its own, one ray-order level of each surface in turn, so every surface fills
// in at once; the final picture is the surfaces' layers composited back to front at every pixel
// (core/image_ops.h composite_layers). A layer is what one surface alone draws, whatever the
// others are, so the picture depends neither on the order the surfaces were listed in nor on the
// threads that cast them.
#include <atomic>
#include <cstddef>
#include <functional>
#include <vector>

#include "core/image.h"
#include "core/surface_style.h"
#include "core/view.h"
#include "engine/progressive_engine.h"
#include "render/renderer.h"

namespace isowall {

// One surface of the picture: its engine (an extractor of its own), the renderer its layer is
// drawn into (warmed up), and its style (isovalue and opacity; the colour is the engine's
// EngineOptions::colour).
struct SurfaceLayer {
    ProgressiveEngine* engine = nullptr;
    Renderer* renderer = nullptr;
    SurfaceStyle style;
};

struct SurfacesFrame {
    // Each surface's frame, as draw_frame gives it: its groups, its timeline, its final layer.
    std::vector<FrameResult> layers;
    // The picture as a whole: rays, groups and triangles summed over the surfaces, one timeline
    // of every surface's samples on the frame's clock (each sample summing what every surface
    // had by then), and the composited final image.
    FrameResult frame;
    // For each sample of frame.timeline, how many groups of each surface it shows.
    std::vector<std::vector<std::size_t>> shown;
};

// Draws `view` (its isovalue aside: each layer's style gives one) with every layer, one
// ray-order level of each in turn in the order given, until every layer's frame is done or `stop`
// reads true. `progress` sees the whole picture's latest sample about every half second.
SurfacesFrame draw_surfaces(const std::vector<SurfaceLayer>& layers, const FrameView& view,
                            const std::atomic<bool>* stop = nullptr,
                            const ProgressiveEngine::Progress& progress = {});

// Replays every surface's groups sample by sample and measures both correctness measures of the
// composited picture at every sample of frame.timeline against the final picture. `on_image`
// (optional) sees each composited image of the whole screen.
void measure_surfaces(
    SurfacesFrame& frame, const std::vector<SurfaceLayer>& layers, const FrameView& view,
    const std::function<void(const TimelineSample&, const Image&)>& on_image = {});

// Each mesh drawn alone at `view`'s size into the layer's renderer and the layers composited:
// the full surfaces' picture. `supersample` > 1 draws each at that many samples a pixel a side and
// box-filters the composite (the truth, progressive/correctness.h).
Image draw_surfaces_alone(const std::vector<SurfaceLayer>& layers, const std::vector<Mesh>& meshes,
                          const FrameView& view, int supersample = 1);

// The opacities of `layers`, in their order: what composite_layers takes.
std::vector<float> layer_opacities(const std::vector<SurfaceLayer>& layers);

}  // namespace isowall
