#pragma once
// A display wall: a grid of identical tiles, the bezels (or projector overlap) between them, and
// which MPI rank drives which tile. The whole wall, bezels included, is one virtual screen, so a
// straight line stays straight across tiles: each tile's frustum is a sub-rectangle of the wall's.
//
// Tiles are indexed row-major from the top-left (index = row * columns + column) whatever the
// rank order; the rank order only decides which rank owns which tile.
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera.h"

namespace isowall {

inline constexpr int kMasterRank = 0;
inline constexpr int kNoTile = -1;  // tile_of_rank(kMasterRank): the master drives no tile
inline constexpr int kNoRank = -1;  // rank_of_tile of a disabled tile

// How ranks 1..T are laid over the tiles. row_major: left to right, then top to bottom;
// column_major: top to bottom, then left to right; serpentine: row-major with every odd row run
// right to left (how daisy-chained displays are often cabled).
enum class RankOrder { row_major, column_major, serpentine };

// Frame widths around each tile's active area. The gap between horizontal neighbours is
// right + left, between vertical neighbours bottom + top. Negative widths are projector overlap.
struct Bezels {
    int left = 0, right = 0, top = 0, bottom = 0;
};

struct BezelsMm {
    double left = 0, right = 0, top = 0, bottom = 0;
};

// The physical sizes as given in the file; parse_wall has already turned bezel_mm into pixels
// (WallSpec::bezel_px) through the tile's pixel pitch.
struct PhysicalSize {
    double tile_width_mm = 0, tile_height_mm = 0;  // active area of one tile
    BezelsMm bezel_mm;
    // Tracked or nominal eye position: origin at the centre of the virtual screen, x right, y up,
    // z out of the screen towards the viewer (so z > 0).
    std::optional<glm::dvec3> viewer_mm;
};

// One tile that differs from the grid: switched off (no rank drives it), or shifted on the
// virtual screen (a panel mounted off its nominal place).
struct TileOverride {
    int column = 0, row = 0;
    bool disabled = false;
    int offset_x_px = 0, offset_y_px = 0;  // x right, y down
    std::string display = {};              // X display of this tile's window; empty: the wall's
};

struct WallSpec {
    int columns = 1, rows = 1;
    int tile_width_px = 1024, tile_height_px = 768;
    Bezels bezel_px;
    std::optional<PhysicalSize> physical;
    RankOrder rank_order = RankOrder::row_major;
    std::vector<TileOverride> overrides;  // at most one per (column, row)
    // The X display (and screen) every tile's window opens with --windows, as "[host]:D[.S]";
    // empty: each tile rank's $DISPLAY.
    std::string display;
};

struct PixelSize {
    int width = 0, height = 0;
};

// Parses a wall file (TOML; walls/6x4.toml documents every key).
// Throws InputError naming `where`, the field, what was expected and what was found; unknown keys
// are errors, so a typo never passes silently.
WallSpec parse_wall(std::string_view toml_text, const std::string& where);
// A regular file of at most kMaxWallFileBytes (a folder or a device is an error naming "file").
WallSpec load_wall(const std::filesystem::path& path);
inline constexpr std::size_t kMaxWallFileBytes = 1u << 20;

std::string to_string(RankOrder order);  // "row-major", "column-major", "serpentine"

int tile_count(const WallSpec& spec);  // columns * rows, disabled tiles included
int tile_index(const WallSpec& spec, int column, int row);
bool tile_enabled(const WallSpec& spec, int tile_index);
// 1 (the master) + the enabled tiles: the -np of a wall run.
int rank_count(const WallSpec& spec);

// All tiles plus the bezels between them (not around the outside).
PixelSize virtual_screen_size(const WallSpec& spec);
// Where tile `tile_index`'s pixels sit on the virtual screen (top-left origin, y down). With
// overlap, neighbouring rects share pixels; with bezels, the gaps between them are bezel pixels.
PixelRect tile_rect(const WallSpec& spec, int tile_index);
// `wall` is the frustum of the whole virtual screen; the result is the off-axis frustum of one
// tile.
Frustum tile_frustum(const Frustum& wall, const WallSpec& spec, int tile_index);

// Rank 0 is the master (kNoTile); ranks 1..T own the enabled tiles in rank order. Ranks outside
// [0, rank_count) and tile indices outside [0, tile_count) throw std::out_of_range.
int tile_of_rank(const WallSpec& spec, int rank);
// The X display of tile `tile_index`'s window: its [[tile]] display, else the wall's, else empty
// (the rank's $DISPLAY).
std::string tile_display(const WallSpec& spec, int tile_index);
int rank_of_tile(const WallSpec& spec, int tile_index);  // kNoRank for a disabled tile

std::ostream& operator<<(std::ostream& os, const WallSpec& spec);
std::ostream& operator<<(std::ostream& os, const PixelRect& r);

}  // namespace isowall
