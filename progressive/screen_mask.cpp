#include "progressive/screen_mask.h"

#include <algorithm>
#include <utility>

#include "core/pixel_rect_ops.h"
#include "core/ray.h"

namespace isowall {
namespace {

PixelRect bounding(std::span<const PixelRect> rects) {
    int x0 = rects.front().x, y0 = rects.front().y;
    int x1 = x0 + rects.front().width, y1 = y0 + rects.front().height;
    for (const PixelRect& r : rects) {
        x0 = std::min(x0, r.x), y0 = std::min(y0, r.y);
        x1 = std::max(x1, r.x + r.width), y1 = std::max(y1, r.y + r.height);
    }
    return {x0, y0, x1 - x0, y1 - y0};
}

// The union of `rects` (non-empty, inside their bounding box `area`) as a mask of `area`. A sweep
// down the rows keeps one row of differences, +1 at the left edge and -1 past the right edge of
// each rectangle the row is inside, and a prefix sum along the row gives the cover count: one
// pass over the area and two events per rectangle, with a row of ints as the only scratch (a
// screen-sized difference array cost more in first-touch page faults than in arithmetic).
ScreenMask sweep(std::vector<PixelRect> starts, const PixelRect& area) {
    std::vector<PixelRect> ends = starts;
    std::sort(starts.begin(), starts.end(), [](auto& a, auto& b) { return a.y < b.y; });
    std::sort(ends.begin(), ends.end(),
              [](auto& a, auto& b) { return a.y + a.height < b.y + b.height; });
    ScreenMask m;
    m.rect = area;
    const std::size_t w = std::size_t(area.width);
    m.cast.assign(w * std::size_t(area.height), 0);
    std::vector<int> row(w + 1, 0);
    const auto edge = [&](const PixelRect& r, int sign) {
        row[std::size_t(r.x - area.x)] += sign;
        row[std::size_t(r.x - area.x + r.width)] -= sign;
    };
    std::size_t next_start = 0, next_end = 0, open = 0;
    for (int y = area.y; y < area.y + area.height; ++y) {
        for (; next_end < ends.size() && ends[next_end].y + ends[next_end].height == y; ++next_end)
            edge(ends[next_end], -1), --open;
        for (; next_start < starts.size() && starts[next_start].y == y; ++next_start)
            edge(starts[next_start], +1), ++open;
        if (open == 0) continue;
        std::uint8_t* out = m.cast.data() + std::size_t(y - area.y) * w;
        int cover = 0;
        for (std::size_t x = 0; x < w; ++x) {
            cover += row[x];
            out[x] = cover > 0 ? 1 : 0;
            m.count += cover > 0 ? 1 : 0;
        }
    }
    return m;
}

}  // namespace

ScreenMask screen_mask(std::span<const Box3> boxes, const glm::mat4& view, const Frustum& frustum,
                       int width, int height, PixelRect region) {
    const PixelRect area = intersect(region, {0, 0, std::max(width, 0), std::max(height, 0)});
    if (is_empty(area)) return {};
    std::vector<PixelRect> rects;
    rects.reserve(boxes.size());
    for (const Box3& b : boxes) {
        if (b.empty()) continue;
        const PixelRect r = intersect(screen_box(b, view, frustum, width, height), area);
        if (!is_empty(r)) rects.push_back(r);
    }
    if (rects.empty()) return {};
    const PixelRect box = bounding(rects);
    return sweep(std::move(rects), box);
}

}  // namespace isowall
