// Tile geometry of a WallSpec: which tile each rank drives, each tile's rectangle of the virtual
// screen (bezels and overlaps included) and its off-axis frustum. Pure functions, no I/O.
#include "wall_spec/wall.h"

#include <algorithm>
#include <ostream>
#include <stdexcept>
#include <string>

namespace isowall {
namespace {

const TileOverride* override_of(const WallSpec& spec, int tile_index) {
    for (const TileOverride& o : spec.overrides)
        if (o.row * spec.columns + o.column == tile_index) return &o;
    return nullptr;
}

void check_tile(const WallSpec& spec, int tile_index) {
    if (tile_index < 0 || tile_index >= tile_count(spec))
        throw std::out_of_range("tile index " + std::to_string(tile_index) + " outside [0, " +
                                std::to_string(tile_count(spec)) + ")");
}

// The tile at position k of the rank order, disabled tiles included.
int tile_at_order(const WallSpec& spec, int k) {
    switch (spec.rank_order) {
        case RankOrder::row_major:
            return k;
        case RankOrder::column_major:
            return (k % spec.rows) * spec.columns + k / spec.rows;
        case RankOrder::serpentine: {
            const int row = k / spec.columns, c = k % spec.columns;
            return row * spec.columns + (row % 2 ? spec.columns - 1 - c : c);
        }
    }
    return k;
}

}  // namespace

int tile_count(const WallSpec& spec) {
    return spec.columns * spec.rows;
}

int tile_index(const WallSpec& spec, int column, int row) {
    return row * spec.columns + column;
}

bool tile_enabled(const WallSpec& spec, int tile_index) {
    check_tile(spec, tile_index);
    const TileOverride* o = override_of(spec, tile_index);
    return !(o && o->disabled);
}

int eyes_per_tile(const WallSpec& spec) {
    return spec.stereo ? 2 : 1;
}

int rank_count(const WallSpec& spec) {
    int disabled = 0;
    for (const TileOverride& o : spec.overrides) disabled += o.disabled ? 1 : 0;
    return 1 + (tile_count(spec) - disabled) * eyes_per_tile(spec);
}

PixelSize virtual_screen_size(const WallSpec& spec) {
    const Bezels& b = spec.bezel_px;
    return {spec.columns * spec.tile_width_px + (spec.columns - 1) * (b.left + b.right),
            spec.rows * spec.tile_height_px + (spec.rows - 1) * (b.top + b.bottom)};
}

PixelRect tile_rect(const WallSpec& spec, int tile_index) {
    check_tile(spec, tile_index);
    const Bezels& b = spec.bezel_px;
    const int column = tile_index % spec.columns, row = tile_index / spec.columns;
    PixelRect r{column * (spec.tile_width_px + b.left + b.right),
                row * (spec.tile_height_px + b.top + b.bottom), spec.tile_width_px,
                spec.tile_height_px};
    if (const TileOverride* o = override_of(spec, tile_index)) {
        r.x += o->offset_x_px;
        r.y += o->offset_y_px;
    }
    return r;
}

PixelRect eye_rect(const WallSpec& spec, int tile_index) {
    PixelRect r = tile_rect(spec, tile_index);
    if (!spec.stereo) return r;
    // Floor division, so tiles on the left of the screen (or above it) keep their order.
    const auto half = [](int v) { return v >= 0 ? v / 2 : -((-v + 1) / 2); };
    if (spec.stereo->mode == StereoMode::side_by_side) {
        r.x = half(r.x);
        r.width /= 2;
    } else if (spec.stereo->mode == StereoMode::top_bottom) {
        r.y = half(r.y);
        r.height /= 2;
    }
    return r;
}

PixelSize eye_screen_size(const WallSpec& spec) {
    PixelSize s = virtual_screen_size(spec);
    if (!spec.stereo) return s;
    if (spec.stereo->mode == StereoMode::side_by_side) s.width = (s.width + 1) / 2;
    if (spec.stereo->mode == StereoMode::top_bottom) s.height = (s.height + 1) / 2;
    return s;
}

Frustum tile_frustum(const Frustum& wall, const WallSpec& spec, int tile_index) {
    const PixelSize screen = virtual_screen_size(spec);
    return sub_frustum(wall, screen.width, screen.height, tile_rect(spec, tile_index));
}

int tile_of_rank(const WallSpec& spec, int rank) {
    if (rank < 0 || rank >= rank_count(spec))
        throw std::out_of_range("rank " + std::to_string(rank) + " outside [0, " +
                                std::to_string(rank_count(spec)) + ")");
    if (rank == kMasterRank) return kNoTile;
    // Walk the rank order, skipping disabled tiles; walls are small enough that this is free.
    const int nth = (rank - 1) / eyes_per_tile(spec) + 1;
    for (int k = 0, seen = 0; k < tile_count(spec); ++k) {
        const int tile = tile_at_order(spec, k);
        if (tile_enabled(spec, tile) && ++seen == nth) return tile;
    }
    return kNoTile;  // unreachable: rank < rank_count
}

Eye eye_of_rank(const WallSpec& spec, int rank) {
    if (tile_of_rank(spec, rank) == kNoTile || !spec.stereo) return Eye::centre;
    return (rank - 1) % 2 == 0 ? Eye::left : Eye::right;
}

int rank_of_tile(const WallSpec& spec, int tile_index, Eye eye) {
    check_tile(spec, tile_index);
    if (!tile_enabled(spec, tile_index)) return kNoRank;
    for (int k = 0, nth = 0; k < tile_count(spec); ++k) {
        const int tile = tile_at_order(spec, k);
        if (tile_enabled(spec, tile)) ++nth;
        if (tile == tile_index)
            return (nth - 1) * eyes_per_tile(spec) + 1 + (spec.stereo && eye == Eye::right ? 1 : 0);
    }
    return kNoRank;  // unreachable: every tile appears once in the order
}

std::string tile_name(const WallSpec& spec, int rank) {
    const Eye eye = eye_of_rank(spec, rank);
    return "tile " + std::to_string(tile_of_rank(spec, rank)) +
           (eye == Eye::centre ? "" : ", " + to_string(eye) + " eye");
}

std::string to_string(StereoMode mode) {
    switch (mode) {
        case StereoMode::side_by_side:
            return "side-by-side";
        case StereoMode::top_bottom:
            return "top-bottom";
        case StereoMode::full:
            return "full";
    }
    return "?";
}

std::string to_string(Eye eye) {
    switch (eye) {
        case Eye::centre:
            return "centre";
        case Eye::left:
            return "left";
        case Eye::right:
            return "right";
    }
    return "?";
}

std::ostream& operator<<(std::ostream& os, const WallSpec& spec) {
    const Bezels& b = spec.bezel_px;
    os << "WallSpec{" << spec.columns << "x" << spec.rows << " tiles of " << spec.tile_width_px
       << "x" << spec.tile_height_px << " px, bezel_px l" << b.left << " r" << b.right << " t"
       << b.top << " b" << b.bottom << ", " << to_string(spec.rank_order);
    if (spec.physical)
        os << ", tile " << spec.physical->tile_width_mm << "x" << spec.physical->tile_height_mm
           << " mm";
    if (spec.stereo)
        os << ", stereo " << to_string(spec.stereo->mode) << " separation "
           << spec.stereo->separation << " convergence " << spec.stereo->convergence;
    for (const TileOverride& o : spec.overrides)
        os << ", tile (" << o.column << "," << o.row << ")" << (o.disabled ? " disabled" : "")
           << " offset " << o.offset_x_px << "," << o.offset_y_px;
    return os << "}";
}

std::ostream& operator<<(std::ostream& os, const PixelRect& r) {
    return os << "PixelRect{" << r.x << ", " << r.y << ", " << r.width << "x" << r.height << "}";
}

std::string tile_display(const WallSpec& spec, int tile_index, Eye eye) {
    check_tile(spec, tile_index);
    if (spec.stereo && spec.stereo->mode == StereoMode::full && eye == Eye::right)
        return spec.stereo->right_display;
    const TileOverride* o = override_of(spec, tile_index);
    return o && !o->display.empty() ? o->display : spec.display;
}

}  // namespace isowall