#pragma once
// Pure operations on pixel rectangles, shared by the engine's regions and the screen mask.
#include <algorithm>
#include <cstddef>

#include "core/camera.h"

namespace isowall {

// True when the rectangle holds no pixel.
inline bool is_empty(const PixelRect& r) {
    return r.width <= 0 || r.height <= 0;
}

// The pixels the rectangle holds (0 when it is empty).
inline std::size_t pixel_count(const PixelRect& r) {
    return is_empty(r) ? 0 : std::size_t(r.width) * std::size_t(r.height);
}

// The pixels both rectangles hold: at the corner where they would meet, with a width or height of
// 0 when they do not overlap.
inline PixelRect intersect(const PixelRect& a, const PixelRect& b) {
    const int x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
    const int x1 = std::min(a.x + a.width, b.x + b.width);
    const int y1 = std::min(a.y + a.height, b.y + b.height);
    return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
}

}  // namespace isowall
