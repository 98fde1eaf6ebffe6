#pragma once
// Seeds taken where the picture still shows nothing: the engine's side of
// extract/hit_neighbours.h (a region's rays note the unvisited cells beside their hits on
// visited ones) and the frontier units of full passes (Group::frontier). The engine seeds them
// before the ray order's fill level and, the cells beside hits, again at the region's end.
#include <cstdint>
#include <optional>
#include <vector>

#include "core/camera.h"
#include "core/ray.h"
#include "core/view.h"
#include "extract/group_sink.h"
#include "extract/hit_neighbours.h"
#include "extract/surface_extractor.h"

namespace isowall {

// Appends to `out` the unvisited cells beside `hit` (through `pixel`, the screen's) when it met a
// visited cell (`exact`: the intersection mode was exact).
void note_beside(const SurfaceExtractor& ex, const RayHit& hit, const Ray& ray, glm::ivec2 pixel,
                 bool exact, std::vector<BesideSeed>& out);

// The pixel (top-left origin) of a `width` x `height` screen where the centre of the cell at
// `cell` (voxel space) projects through `clip_from_voxel` (projection * view * voxel-to-object);
// nullopt behind the eye or off the screen.
std::optional<glm::ivec2> cell_pixel(const glm::mat4& clip_from_voxel, glm::ivec3 cell, int width,
                                     int height);

// Empties `pending` (frontier units of full passes, Group::frontier) and returns as seeds those
// still unvisited whose first cell's centre projects to a pixel that shows nothing in `covered`
// (rect-local, what the sink shows in `rect`; none when it is not that size), with the ray
// through that pixel: where a pass had to stop short of what the picture still misses. At most
// one seed per pixel (its pixel is marked in `covered`).
std::vector<BesideSeed> take_frontier_still_empty(std::vector<glm::ivec3>& pending,
                                                  const SurfaceExtractor& ex, const FrameView& view,
                                                  const glm::mat4& view_inverse,
                                                  const PixelRect& rect,
                                                  std::vector<std::uint8_t>& covered);

// Empties `pending` and returns those of its seeds whose pixel shows nothing in `covered`
// (rect-local, what the sink shows in `rect`; none taken when it is not that size). Whether a
// seed's cell is still unvisited is the caller's to check as it seeds: one seed's pass may take
// another's cell.
std::vector<BesideSeed> take_still_empty(std::vector<BesideSeed>& pending, const PixelRect& rect,
                                         const std::vector<std::uint8_t>& covered);
// The same with the coverage read from `shown` into `scratch`; none without `shown`.
std::vector<BesideSeed> take_still_empty(std::vector<BesideSeed>& pending, ShownPixels* shown,
                                         const PixelRect& rect, std::vector<std::uint8_t>& scratch);

}  // namespace isowall
