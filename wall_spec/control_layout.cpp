#include "wall_spec/control_layout.h"

#include <algorithm>
#include <cmath>

namespace isowall {
namespace {

// A virtual-screen coordinate in the mosaic, clamped to it (an offset tile may reach past the
// virtual screen).
int scaled(int v, double scale, int limit) {
    return std::clamp(static_cast<int>(std::floor(v * scale)), 0, limit);
}

}  // namespace

ControlLayout control_layout(const WallSpec& spec, PixelSize max) {
    const PixelSize vs = virtual_screen_size(spec);
    const int max_w = std::max(max.width, 1), max_h = std::max(max.height, 1);
    ControlLayout l;
    l.scale = std::min(
        {1.0, double(max_w) / std::max(vs.width, 1), double(max_h) / std::max(vs.height, 1)});
    // Rounded, then clamped: the fitted side is max_w or max_h up to float rounding.
    l.mosaic.width = std::clamp(static_cast<int>(std::lround(vs.width * l.scale)), 1, max_w);
    l.mosaic.height = std::clamp(static_cast<int>(std::lround(vs.height * l.scale)), 1, max_h);
    l.tiles.resize(static_cast<std::size_t>(tile_count(spec)));
    for (int t = 0; t < tile_count(spec); ++t) {
        if (!tile_enabled(spec, t)) continue;
        const PixelRect r = tile_rect(spec, t);
        const int x0 = scaled(r.x, l.scale, l.mosaic.width);
        const int y0 = scaled(r.y, l.scale, l.mosaic.height);
        const int x1 = scaled(r.x + r.width, l.scale, l.mosaic.width);
        const int y1 = scaled(r.y + r.height, l.scale, l.mosaic.height);
        l.tiles[static_cast<std::size_t>(t)] = {x0, y0, x1 - x0, y1 - y0};
    }
    return l;
}

int preview_max_side(const WallSpec& spec, PixelSize max) {
    int side = 1;
    for (const PixelRect& r : control_layout(spec, max).tiles)
        side = std::max({side, r.width, r.height});
    return side;
}

std::ostream& operator<<(std::ostream& os, const ControlLayout& layout) {
    os << "ControlLayout{" << layout.mosaic.width << "x" << layout.mosaic.height << ", scale "
       << layout.scale << ", tiles";
    for (const PixelRect& r : layout.tiles) os << " " << r;
    return os << "}";
}

}  // namespace isowall
