#include "common/core/image_ops.h"

#include <stdexcept>

namespace isowall {

void composite_by_depth(Image& dst, const Image& src, const PixelRect& where) {
    if (dst.depth.size() != dst.pixel_count() || src.depth.size() != src.pixel_count())
        throw std::invalid_argument("composite_by_depth: both images need depth");
    for_each_placed_pixel(dst, src, where, [&](std::size_t d, std::size_t s) {
        if (src.depth[s] >= dst.depth[d]) return;
        dst.depth[d] = src.depth[s];
        for (int k = 0; k < 4; ++k) dst.rgba[4 * d + k] = src.rgba[4 * s + k];
    });
}

void place(Image& dst, const Image& src, const PixelRect& where) {
    const bool depth =
        dst.depth.size() == dst.pixel_count() && src.depth.size() == src.pixel_count();
    for_each_placed_pixel(dst, src, where, [&](std::size_t d, std::size_t s) {
        if (depth) dst.depth[d] = src.depth[s];
        for (int k = 0; k < 4; ++k) dst.rgba[4 * d + k] = src.rgba[4 * s + k];
    });
}

}  // namespace isowall
