#pragma once
// The engine's side of common/extract/hit_neighbours.h: a region's rays note the unvisited cells
// beside their hits on visited ones, and at the region's end the engine seeds those whose pixel
// still shows nothing.
#include <cstdint>
#include <vector>

#include "common/core/camera.h"
#include "common/core/ray.h"
#include "common/extract/hit_neighbours.h"
#include "common/extract/surface_extractor.h"
#include "engine/group_sink.h"

namespace isowall {

// Appends to `out` the unvisited cells beside `hit` (through `pixel`, the screen's) when it met a
// visited cell (`exact`: the intersection mode was exact).
void note_beside(const SurfaceExtractor& ex, const RayHit& hit, const Ray& ray, glm::ivec2 pixel,
                 bool exact, std::vector<BesideSeed>& out);

// Empties `pending` and returns those of its seeds whose pixel `sink` shows nothing at in `rect`
// (`scratch` holds its coverage); none when `sink` cannot tell. Whether a seed's cell is still
// unvisited is the caller's to check as it seeds: one seed's pass may take another's cell.
std::vector<BesideSeed> take_still_empty(std::vector<BesideSeed>& pending, GroupSink& sink,
                                         const PixelRect& rect, std::vector<std::uint8_t>& scratch);

}  // namespace isowall
