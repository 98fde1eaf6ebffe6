#pragma once
// The mosaic of a wall: the tiles' images placed on the virtual screen. Pure functions over
// images, so compositing is tested without MPI or GL. Bezel gaps stay a dark grey; where
// projectors overlap, both tiles light a pixel and the mosaic shows their average.
#include <cstdint>
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "core/image_ops.h"  // composite_by_depth, for callers of the mosaic

namespace isowall {

inline constexpr std::uint8_t kBezelGrey = 40;

struct Mosaic {
    Image image;
    std::vector<std::uint8_t> count;  // tiles that lit each pixel so far (overlaps)
};

// width x height of bezel grey, nothing lit.
Mosaic empty_mosaic(int width, int height);

// Places `tile` with its top-left at (where.x, where.y); pixels outside the mosaic are skipped.
// A pixel lit by n tiles shows the mean of their colours.
void paste(Mosaic& mosaic, const Image& tile, const PixelRect& where);

}  // namespace isowall
