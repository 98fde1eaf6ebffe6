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

int rank_count(const WallSpec& spec) {
    int disabled = 0;
    for (const TileOverride& o : spec.overrides) disabled += o.disabled ? 1 : 0;
    return 1 + tile_count(spec) - disabled;
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
    for (int k = 0, seen = 0; k < tile_count(spec); ++k) {
        const int tile = tile_at_order(spec, k);
        if (tile_enabled(spec, tile) && ++seen == rank) return tile;
    }
    return kNoTile;  // unreachable: rank < rank_count
}

int rank_of_tile(const WallSpec& spec, int tile_index) {
    check_tile(spec, tile_index);
    if (!tile_enabled(spec, tile_index)) return kNoRank;
    for (int k = 0, rank = 0; k < tile_count(spec); ++k) {
        const int tile = tile_at_order(spec, k);
        if (tile_enabled(spec, tile)) ++rank;
        if (tile == tile_index) return rank;
    }
    return kNoRank;  // unreachable: every tile appears once in the order
}

std::ostream& operator<<(std::ostream& os, const WallSpec& spec) {
    const Bezels& b = spec.bezel_px;
    os << "WallSpec{" << spec.columns << "x" << spec.rows << " tiles of " << spec.tile_width_px
       << "x" << spec.tile_height_px << " px, bezel_px l" << b.left << " r" << b.right << " t"
       << b.top << " b" << b.bottom << ", " << to_string(spec.rank_order);
    if (spec.physical)
        os << ", tile " << spec.physical->tile_width_mm << "x" << spec.physical->tile_height_mm
           << " mm";
    for (const TileOverride& o : spec.overrides)
        os << ", tile (" << o.column << "," << o.row << ")" << (o.disabled ? " disabled" : "")
           << " offset " << o.offset_x_px << "," << o.offset_y_px;
    return os << "}";
}

std::ostream& operator<<(std::ostream& os, const PixelRect& r) {
    return os << "PixelRect{" << r.x << ", " << r.y << ", " << r.width << "x" << r.height << "}";
}

std::string tile_display(const WallSpec& spec, int tile_index) {
    check_tile(spec, tile_index);
    const TileOverride* o = override_of(spec, tile_index);
    return o && !o->display.empty() ? o->display : spec.display;
}

}  // namespace isowall