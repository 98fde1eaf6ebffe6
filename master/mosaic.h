#pragma once
// The mosaic of a wall: the tiles' images placed on the virtual screen. Pure functions over
// images, so compositing is tested without MPI or GL. Bezel gaps stay a dark grey; where
// projectors overlap, both tiles light a pixel and the mosaic shows their average.
#include <cstdint>
#include <filesystem>
#include <utility>
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

// A red-cyan anaglyph of a stereo pair, for checking stereo on an ordinary screen through red
// (left) and cyan (right) glasses: red from the left eye, green and blue from the right. The
// eyes' images may be squeezed (side-by-side, top-bottom); each is stretched (nearest pixel) to
// width x height.
Image anaglyph(const Image& left, const Image& right, int width, int height);

// The files a wall's mosaics go to: without stereo (one mosaic) `path` itself; with stereo (left
// and right), `path` holds their anaglyph at width x height and STEM-left.EXT, STEM-right.EXT the
// eyes as they were drawn.
std::vector<std::pair<std::filesystem::path, Image>> mosaic_files(const std::filesystem::path& path,
                                                                  std::vector<Mosaic> mosaics,
                                                                  int width, int height);

}  // namespace isowall
