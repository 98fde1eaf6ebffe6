#pragma once
// Pixel operations on read-back frames shared by the master and the tile ranks: placing one image
// on another, depth compositing. Pure functions over Image.
#include <algorithm>
#include <cstddef>

#include "common/core/camera.h"
#include "common/core/image.h"

namespace isowall {

// Calls fn(d, s) for every pixel of `src` placed at where.x, where.y (at most where's size) that
// lands inside `dst`: d and s are the pixel indices in dst and src. What falls outside is skipped,
// so edge tiles need no special case.
template <class Fn>
void for_each_placed_pixel(const Image& dst, const Image& src, const PixelRect& where, Fn fn) {
    for (int y = 0; y < std::min(where.height, src.height); ++y) {
        const int dy = where.y + y;
        if (dy < 0 || dy >= dst.height) continue;
        for (int x = 0; x < std::min(where.width, src.width); ++x) {
            const int dx = where.x + x;
            if (dx < 0 || dx >= dst.width) continue;
            fn(static_cast<std::size_t>(dy) * dst.width + dx,
               static_cast<std::size_t>(y) * src.width + x);
        }
    }
}

// Depth compositing of two renderings of the same screen pixels (the owner of a screen region and
// a helper that rendered part of it): where `src` is nearer than `dst`, dst takes its colour and
// depth. `src` covers `where` of dst; both must carry depth (std::invalid_argument otherwise).
void composite_by_depth(Image& dst, const Image& src, const PixelRect& where);

// Copies `src` into `where` of dst, colour and depth (where dst has depth).
void place(Image& dst, const Image& src, const PixelRect& where);

}  // namespace isowall
