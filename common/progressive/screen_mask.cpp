#include "common/progressive/screen_mask.h"

#include <algorithm>

#include "common/core/ray.h"

namespace isowall {
namespace {

PixelRect clip(const PixelRect& a, const PixelRect& b) {
    const int x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
    const int x1 = std::min(a.x + a.width, b.x + b.width);
    const int y1 = std::min(a.y + a.height, b.y + b.height);
    if (x1 <= x0 || y1 <= y0) return {};
    return {x0, y0, x1 - x0, y1 - y0};
}

// How many of the rectangles cover each pixel of `area` (row-major, area-local): +1 at each
// rectangle's top-left, -1 past its right and bottom edges, +1 past both, then prefix sums.
std::vector<int> cover_counts(std::span<const PixelRect> rects, const PixelRect& area) {
    const std::size_t w = std::size_t(area.width) + 1, h = std::size_t(area.height) + 1;
    std::vector<int> d(w * h, 0);
    for (const PixelRect& r : rects) {
        const std::size_t x0 = std::size_t(r.x - area.x), y0 = std::size_t(r.y - area.y);
        const std::size_t x1 = x0 + std::size_t(r.width), y1 = y0 + std::size_t(r.height);
        ++d[y0 * w + x0];
        --d[y0 * w + x1];
        --d[y1 * w + x0];
        ++d[y1 * w + x1];
    }
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 1; x < w; ++x) d[y * w + x] += d[y * w + x - 1];
    for (std::size_t y = 1; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) d[y * w + x] += d[(y - 1) * w + x];
    return d;  // row stride w; the last row and column are zero
}

// The pixels of `area` with a count above zero, cropped to their bounding box.
ScreenMask crop(const std::vector<int>& counts, const PixelRect& area) {
    const int stride = area.width + 1;
    int x0 = area.width, y0 = area.height, x1 = -1, y1 = -1;
    for (int y = 0; y < area.height; ++y)
        for (int x = 0; x < area.width; ++x)
            if (counts[std::size_t(y) * std::size_t(stride) + std::size_t(x)] > 0) {
                x0 = std::min(x0, x), x1 = std::max(x1, x);
                y0 = std::min(y0, y), y1 = std::max(y1, y);
            }
    ScreenMask m;
    if (x1 < 0) return m;
    m.rect = {area.x + x0, area.y + y0, x1 - x0 + 1, y1 - y0 + 1};
    m.cast.resize(std::size_t(m.rect.width) * std::size_t(m.rect.height));
    for (int y = 0; y < m.rect.height; ++y)
        for (int x = 0; x < m.rect.width; ++x) {
            const bool on =
                counts[std::size_t(y0 + y) * std::size_t(stride) + std::size_t(x0 + x)] > 0;
            m.cast[std::size_t(y) * std::size_t(m.rect.width) + std::size_t(x)] = on ? 1 : 0;
            m.count += on ? 1 : 0;
        }
    return m;
}

}  // namespace

ScreenMask screen_mask(std::span<const Box3> boxes, const glm::mat4& view, const Frustum& frustum,
                       int width, int height, PixelRect region) {
    const PixelRect area = clip(region, {0, 0, std::max(width, 0), std::max(height, 0)});
    if (area.width == 0) return {};
    std::vector<PixelRect> rects;
    rects.reserve(boxes.size());
    for (const Box3& b : boxes) {
        if (b.empty()) continue;
        const PixelRect r = clip(screen_box(b, view, frustum, width, height), area);
        if (r.width > 0) rects.push_back(r);
    }
    if (rects.empty()) return {};
    return crop(cover_counts(rects, area), area);
}

}  // namespace isowall
