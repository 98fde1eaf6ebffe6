#pragma once
#include <functional>
// What `isowall render` prints about a frame besides its timings: the correctness thresholds
// reached, the draw-only floor, the final image against the full surface, and covered pixels.
#include <cstddef>
#include <string>

#include "cli/volume_options.h"
#include "core/image.h"
#include "core/util.h"
#include "core/view.h"
#include "engine/progressive_engine.h"
#include "extract/surface_extractor.h"
#include "render/renderer.h"

namespace isowall {

// One line per stage, then a summary line that scripts can grep for.
struct Timings {
    Stopwatch command;  // from the command's start: GL context, volume, octree, frame
    double load = 0, octree = 0, extract = 0, render = 0, write = 0;
    double frame = -1;  // the progressive frame (extraction and drawing interleaved), if any
    void print(std::size_t triangles) const;
};

// Pixels the surface covers (depth nearer than the background); scripts compare this count with
// other renderers' hit pixels (scripts/bench_scaling.py).
std::size_t covered_pixels(const Image& image);

// 99.9 -> "99.9", 90 -> "90".
std::string percent_label(double pct);

// Both measures' thresholds (90, 99, 99.9 and 100%): when each was first reached, in `timeline`
// (fr's, or a copy measured against another reference), under the heading `against`.
void print_thresholds(const FrameResult& fr, const std::vector<TimelineSample>& timeline,
                      const char* against = "the final image");

// The floor for "C = 99% in time T": drawing the same triangles in one go.
void print_draw_only(const FrameResult& fr, const FrameView& fv, Renderer& renderer);

// The final image against `full` (the full surface, `triangles` of it, drawn in the same view):
// C, final pixels and coverage IoU, and the `seconds` that took, outside the timings.
void print_full_comparison(const Image& full, std::size_t triangles, const Image& final_image,
                           double seconds);
// The final image and `full` (at one sample a pixel) against `truth`, and the fidelity gate.
void print_truth_comparison(const Image& truth, const Image& full, std::size_t triangles,
                            const Image& final_image, double seconds);

// The final image against the full surface drawn in the same view (outside the timings); returns
// that image, the truth the timeline is also measured against.
// `colour`: the engine's colour hook (EngineOptions::colour), so the full surface is coloured as
// the frame's groups were.
Image print_against_full(const SurfaceExtractor& ex, Renderer& renderer, const FrameView& fv,
                         const Image& final_image, const std::function<void(Mesh&)>& colour = {});

// The final image against the truth (app/whole_frame.h draw_truth), beside the full surface at one
// sample per pixel, and the fidelity gate; outside the timings.
void print_against_truth(const SurfaceExtractor& ex, Renderer& renderer, const FrameView& fv,
                         const Image& final_image, const std::function<void(Mesh&)>& colour = {});

// When the frame's first group showed, counted from the command's start (the frame began
// `frame_at` seconds after it; `load_s` and `octree_s` of that went to the volume and its octree):
// what a user waits before a picture, a cold volume's read included.
void print_first_picture(const FrameResult& fr, double frame_at, double load_s, double octree_s);

// A store's reads (store/paged_voxels.h), when the volume is one; nothing otherwise.
void print_paging(const OpenedVolume& ov);

}  // namespace isowall
