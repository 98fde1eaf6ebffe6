#include "master/mosaic.h"

#include <algorithm>
#include <stdexcept>

namespace isowall {

Mosaic empty_mosaic(int width, int height) {
    Mosaic m;
    m.image.resize(width, height);
    for (std::size_t i = 0; i < m.image.pixel_count(); ++i) {
        for (int k = 0; k < 3; ++k) m.image.rgba[4 * i + k] = kBezelGrey;
        m.image.rgba[4 * i + 3] = 255;
    }
    m.count.assign(m.image.pixel_count(), 0);
    return m;
}

namespace {

// Calls fn(d, s) for every pixel of `src` placed at where.x, where.y (at most where's size) that
// lands inside `dst`: d and s are the pixel indices in dst and src. Edge tiles need no special
// case: what falls outside is skipped.
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

}  // namespace

void paste(Mosaic& mosaic, const Image& tile, const PixelRect& where) {
    Image& out = mosaic.image;
    for_each_placed_pixel(out, tile, where, [&](std::size_t m, std::size_t t) {
        const int n = ++mosaic.count[m];
        for (int k = 0; k < 3; ++k) {
            const int before = n == 1 ? 0 : out.rgba[4 * m + k];
            out.rgba[4 * m + k] =
                static_cast<std::uint8_t>((before * (n - 1) + tile.rgba[4 * t + k]) / n);
        }
        out.rgba[4 * m + 3] = 255;
    });
}

void composite_by_depth(Image& dst, const Image& src, const PixelRect& where) {
    if (dst.depth.size() != dst.pixel_count() || src.depth.size() != src.pixel_count())
        throw std::invalid_argument("composite_by_depth: both images need depth");
    for_each_placed_pixel(dst, src, where, [&](std::size_t d, std::size_t s) {
        if (src.depth[s] >= dst.depth[d]) return;
        dst.depth[d] = src.depth[s];
        for (int k = 0; k < 4; ++k) dst.rgba[4 * d + k] = src.rgba[4 * s + k];
    });
}

}  // namespace isowall
