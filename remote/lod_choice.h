#pragma once
// Whether a frame's coarse passes of progressive LOD (the dissertation's section 4.1.3, case 3)
// bring C = 90% sooner, for the server that chooses the schedule (RequestMsg's
// progressive_lod `chosen`). Measured on the shared volumes at their README isovalues
// (docs/benchmarks.md): where the coarse picture alone reaches C = 0.9, the coarse passes bring
// C = 90% 9-20x sooner at 1 Mbit/s (the engine at 75, the tooth at 620), as they take a fraction
// of the rays and bytes; where it does not, C = 90% waits for full-resolution groups behind the
// coarse bytes and comes 10-50% later, at any rate. So the choice turns on the coarse picture's C,
// which depends on the surface and the view far more than on the link.
//
// The server draws nothing and has no final picture, so it forecasts that C: it casts a grid of
// rays through the view at full resolution and at each coarse level (exact hits, as the engine's
// seed rays) and gives each ray's pixel the colour the client would show (render/headlight.h,
// the fine gradient's normal at the hit, as marching_cubes.h gives coarse vertices): the coarse
// picture shows the finest coarse level that the ray hits (the client clears depth for each finer
// level; a coarser level's colour stays where a finer one draws nothing). A pixel the full
// resolution covers and no coarse level does counts an error of 1, as in C = 1 - E
// (progressive/correctness.h). A few thousand rays cost a few milliseconds; the server
// stops once its choice is clear (`decide`).
#include <cstddef>
#include <span>

#include "core/view.h"
#include "extract/surface_extractor.h"

namespace isowall::remote {

struct CoarseForecast {
    double c = 1;                 // the coarse picture's forecast C against the full one
    std::size_t rays = 0;         // cast at full resolution
    std::size_t significant = 0;  // of them, those that hit the surface
    std::size_t casts = 0;        // rays cast at every level
};

// The coarse passes are worth their bytes when their picture reaches C = 90% on its own. Against
// the coarse picture the client measured, the forecast was within 0.037 on 26 views of 8 volumes
// (the shared ones, the 256 head, a 52x47x80 tooth and the phantom; 320x240 to 1600x1200, zoomed
// in and out), 0.007 low on average. The two ways to be wrong do not cost alike: coarse passes
// that fall short put C = 90% behind their bytes (0-30% later), while a forecast that falls
// short where they reach it forgoes C = 90% 4-20x sooner (the shared head at 40 at 1 Mbit/s:
// 0.46 s against 1.77). So they go out from a forecast a typical error under the 0.9.
inline constexpr double kCoarsePaysFrom = 0.88;
inline bool coarse_passes_pay(const CoarseForecast& f) {
    return f.c >= kCoarsePaysFrom;
}

// `levels[i]` casts at level i (begun for the frame's isovalue at uniform level i; levels[0] at
// full resolution), with at least two entries. Rays go through the centres of a grid of about
// `rays` pixels over the volume's box on the screen, in an order that spreads every prefix of them
// over the grid. With `decide` the forecast stops once kCoarsePaysFrom lies 3 standard errors
// from it (after kDecideAfter rays on the surface): the choice, not the figure, is what the server
// needs, and a clear case is clear after a tenth of the rays (cthead at 600: C = 0.73).
inline constexpr std::size_t kDecideAfter = 64;
CoarseForecast forecast_coarse_correctness(std::span<SurfaceExtractor* const> levels,
                                           const FrameView& view, bool decide = false,
                                           std::size_t rays = 3072);

}  // namespace isowall::remote
