#pragma once
// Pixel operations on read-back frames shared by the master and the tile ranks: placing one image
// on another, depth compositing. Pure functions over Image.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/camera.h"
#include "core/image.h"

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

// Layers of one screen (each a surface drawn alone: core/surface_style.h) blended at every pixel
// back to front by depth over a black background, layer k with opacity[k] in [0, 1]; at equal
// depth the earlier layer lies in front. The result's alpha is 255 and its depth the nearest
// layer's where any layer covers the pixel; elsewhere it is the first layer's background. Every
// layer must have the first's size and depth, and `opacity` one entry a layer
// (std::invalid_argument otherwise).
Image composite_layers(const std::vector<const Image*>& layers, const std::vector<float>& opacity);

// The smallest rect holding every pixel `img` covers (depth below 1); empty when it covers none
// or has no depth.
PixelRect covered_box(const Image& img);

// The pixels of `r` (inside `img`) as an image of their own, colour and depth (where img has it).
Image crop(const Image& img, const PixelRect& r);

// Copies `src` into `where` of dst, colour and depth (where dst has depth).
void place(Image& dst, const Image& src, const PixelRect& where);

// The smallest integer factor f >= 1 that brings both sides of a width x height image to at most
// max_side pixels once divided by f (rounded up): the factor shrink_box needs for a preview of at
// most max_side a side. max_side < 1 counts as 1.
int shrink_factor(int width, int height, int max_side);

// `src` made `factor` times smaller (each side rounded up): each pixel is the rounded mean colour
// of its factor x factor box of src, boxes at the right and bottom edges clipped to the image (a
// box filter, so a thin line fades instead of vanishing as with point sampling). Alpha is 255,
// no depth. factor < 1 counts as 1 (a copy).
Image shrink_box(const Image& src, int factor);

// `src` stretched or squeezed to width x height by nearest-neighbour sampling (each output pixel
// takes the src pixel under its centre); colour only, alpha 255, no depth. An empty src gives
// black.
Image resample_nearest(const Image& src, int width, int height);

}  // namespace isowall
