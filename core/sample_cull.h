#pragma once
// Triangles that cannot show. Drawn at one sample a pixel, a triangle writes a fragment only where
// it covers a pixel's centre; once cells project to less than a pixel most of a fine surface's
// triangles cover none (at 4x a side on the CT head, about four in five), yet each is uploaded,
// transformed and set up by the rasteriser. Leaving them out leaves the frame exactly as it was:
// same colours, same depths.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>

#include "core/mesh.h"

namespace isowall {

// How far outside a triangle (or a box) a pixel centre may lie and still count as covered, for the
// rasteriser's rounding of window coordinates.
inline constexpr float kSampleCullMarginPx = 1.0f / 64.0f;

// Whether the window-space box [x0, x1] x [y0, y1] holds the centre of a pixel of a width x height
// frame (widened by kSampleCullMarginPx).
bool box_holds_a_centre(float x0, float x1, float y0, float y1, int width, int height);

// Space keep_sampled_triangles reuses from call to call (a frame draws thousands of groups).
struct SampleCullScratch {
    std::vector<glm::vec2> window;          // each vertex in window coordinates
    std::vector<std::uint8_t> kept_always;  // the vertex is behind the eye or not finite
    std::vector<std::uint32_t> remap;       // each vertex's index in the output, if used
};

// Of `mesh`, the triangles that may cover the centre of a pixel of a width x height frame under
// `clip` (the projection times the view): the centre inside the projected triangle or within
// kSampleCullMarginPx of it, tested where the triangle's box holds a few centres; a triangle whose
// box holds more is kept. They go into `out` with only the vertices they use. A triangle with a
// vertex at or behind the eye's plane, or not finite, is kept: the rasteriser clips it. Returns
// the triangles kept.
std::size_t keep_sampled_triangles(const Mesh& mesh, const glm::mat4& clip, int width, int height,
                                   Mesh& out, SampleCullScratch& scratch);

}  // namespace isowall
