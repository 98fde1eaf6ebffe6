#pragma once
// A region's place in its progressive ray order, and the pieces a frame is cast from: the
// resolution levels of a frame, a region's cursor (clipped to the screen, the volume's screen box
// and the screen mask), its ray order and the coverage that order is given, and the clip that
// keeps propagation inside the region. engine/progressive_engine.cpp casts with them.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/box.h"
#include "core/mesh.h"
#include "core/view.h"
#include "extract/adaptive.h"
#include "extract/group_sink.h"
#include "extract/hit_neighbours.h"
#include "extract/surface_extractor.h"
#include "progressive/ray_order.h"

namespace isowall {

struct EngineOptions;

// The clip of `rect` of `view` for propagation (EngineOptions::region_clip): the region's own
// frustum, from the voxel space of a volume of `spacing`; inactive for an empty rect.
ScreenClip region_clip(const FrameView& view, const PixelRect& rect, glm::vec3 spacing);
// The pixel centres of the whole frame of `view`, for propagation (EngineOptions::
// sampled_triangles).
SampleGrid sample_grid(const FrameView& view, glm::vec3 spacing);

// A region's place in its progressive ray order, kept between the calls that cast it (the coarse
// and the fine band of a wall job).
struct RegionCursor {
    // The pixels to cast: the region clipped to the screen and the screen box, or with the screen
    // mask, to the bounding box of the mask's pixels in it.
    PixelRect rect;
    std::vector<std::uint8_t> mask;   // rect-local; 0: never cast. Empty: every pixel of rect
    std::size_t pixels = 0;           // pixels of rect to cast (the mask's count, or rect's area)
    std::unique_ptr<RayOrder> order;  // null before the first level and between passes
    int pass = 0;                     // 1: the exact second pass of approximate mode
    std::size_t rays = 0;             // cast so far
    std::size_t hits = 0;             // of them, rays that met the surface
    bool done = false;                // every pixel to cast has had its ray
    // The dynamic grid before it has sized its grid: the groups this region finds add the pixels
    // they cover to `drawn` (rect-local), which the order gets as the region's coverage, with no
    // read-back from the renderer (progressive/mesh_coverage.h).
    bool sizing = false;
    std::vector<std::uint8_t> drawn;
    // Unvisited cells beside hits on visited ones, seeded at the region's end if their pixels
    // still show nothing then (engine/beside_seeds.h).
    std::vector<BesideSeed> beside;
    // Frontier units of the region's full passes (Group::frontier), seeded at the next level's
    // end where their pixels still show nothing then (engine/beside_seeds.h).
    std::vector<glm::ivec3> frontier;
    std::size_t frontier_kept = 0;  // its size after the last drop of visited units
};

// The resolution levels of a frame of `view` under `opt`: uniform (uniform_level), adaptive,
// footprint units (footprint_pixels, up to the coarsest level a unit of `volume_box` is far
// enough for), or every cell at full resolution; `spacing` is the volume's.
ResolutionLevels frame_levels(const EngineOptions& opt, const FrameView& view, glm::vec3 spacing,
                              const Box3& volume_box);

// The screen mask's nodes for a frame at `iso` with resolution `levels`: the active octree nodes
// of the finest level within its budget that still holds each meta-cell whole.
ActiveBoxes screen_mask_nodes(const SurfaceExtractor& ex, double iso,
                              const ResolutionLevels& levels);

// The cursor of `region` of `view`: the region clipped to the screen; with `volume_box`, to the
// volume's projected box too; with `mask_boxes` (the active octree nodes of the frame's screen
// mask, object space), to the bounding box of the pixels they cover, casting only those.
RegionCursor region_cursor(const FrameView& view, const PixelRect& region,
                           const std::optional<Box3>& volume_box,
                           const std::vector<Box3>* mask_boxes);

// A new ray order for `c`'s next pass, which sees the region as a screen of its own (pixels and
// coverage local to it); the dynamic grid starts sizing (RegionCursor::sizing).
void begin_order(RegionCursor& c, RayOrderKind kind);
// Adds what `mesh` covers of `c`'s region to c.drawn (`view_m`: view's camera matrix).
void add_drawn(RegionCursor& c, const Mesh& mesh, const glm::mat4& view_m, const FrameView& view);
// Moves a pass's frontier units (Group::frontier, emptied) to c.frontier, first dropping the
// units there that `ex` has visited since once the list has doubled since the last such drop: most
// of a frontier is taken by later passes, and a heavy surface would grow it by megabytes.
void keep_frontier(RegionCursor& c, std::vector<glm::ivec3>& units, const SurfaceExtractor& ex);

// Gives `order` the region's coverage after a level that wants it: while sizing, c.drawn (and
// sizing ends once the order has its size); else what `shown` shows (`scratch` holds it), or
// nothing covered without it. True when `scratch` holds what the frame shows now.
bool give_order_coverage(RayOrder& order, RegionCursor& c, ShownPixels* shown,
                         std::vector<std::uint8_t>& scratch);

}  // namespace isowall
