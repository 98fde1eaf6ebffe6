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

// Stereo: every enabled tile is driven by a pair of ranks, one per eye, on consecutive ranks
// (left, then right), so a hostfile's slots keep a tile's two eyes on one host. How the tile's
// display takes the two eyes decides the pixels of each:
//   side_by_side: each eye W/2 x H, the left eye on the screen's left half (passive 3D panels
//                 and projectors that stretch each half back to the full width);
//   top_bottom:   each eye W x H/2, the left eye on the top half;
//   full:         each eye W x H (a pair of projectors per screen, one per eye, or any display
//                 fed a full frame per eye).
enum class StereoMode { side_by_side, top_bottom, full };
enum class Eye { centre, left, right };

struct Stereo {
    StereoMode mode = StereoMode::side_by_side;
    // The distance between the eyes: in mm on a wall with [physical], else as a fraction of the
    // virtual screen's width.
    double separation = 0;
    // The zero-parallax plane's distance as a fraction of the camera's distance to its target:
    // 1 puts what lies at the target on the screen's plane, nearer in front of it.
    double convergence = 1;
    // The X display of every right eye's window (--windows) in the full mode, where each eye
    // has a screen (a projector) of its own; the left eyes use the tiles' displays.
    std::string right_display;
};
inline constexpr double kDefaultEyeSeparationMm = 65;
inline constexpr double kDefaultEyeSeparation = 0.03;

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
    std::optional<Stereo> stereo;  // none: one rank per tile, the centre eye
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
// 1 (the master) + the enabled tiles times the eyes per tile: the -np of a wall run.
int rank_count(const WallSpec& spec);
int eyes_per_tile(const WallSpec& spec);  // 2 with stereo, else 1

// All tiles plus the bezels between them (not around the outside).
PixelSize virtual_screen_size(const WallSpec& spec);
// Where tile `tile_index`'s pixels sit on the virtual screen (top-left origin, y down). With
// overlap, neighbouring rects share pixels; with bezels, the gaps between them are bezel pixels.
PixelRect tile_rect(const WallSpec& spec, int tile_index);
// `wall` is the frustum of the whole virtual screen; the result is the off-axis frustum of one
// tile.
Frustum tile_frustum(const Frustum& wall, const WallSpec& spec, int tile_index);

// Rank 0 is the master (kNoTile); ranks 1..T own the enabled tiles in rank order (with stereo,
// ranks 2k+1 and 2k+2 the left and right eyes of the k-th). Ranks outside [0, rank_count) and
// tile indices outside [0, tile_count) throw std::out_of_range.
int tile_of_rank(const WallSpec& spec, int rank);
// Eye::centre without stereo (and for the master), else the rank's eye.
Eye eye_of_rank(const WallSpec& spec, int rank);
// The images of one eye: tile_rect and virtual_screen_size scaled as the stereo mode squeezes
// them (the same as those without stereo, or in the full mode). A tile rank's frame is
// eye_rect's size; an eye's mosaic is eye_screen_size.
PixelRect eye_rect(const WallSpec& spec, int tile_index);
PixelSize eye_screen_size(const WallSpec& spec);
// The X display of tile `tile_index`'s window: its [[tile]] display, else the wall's, else empty
// (the rank's $DISPLAY). The right eye of a full-mode stereo wall: stereo.right_display.
std::string tile_display(const WallSpec& spec, int tile_index, Eye eye = Eye::centre);
// kNoRank for a disabled tile; with stereo, the rank of `eye` (left for Eye::centre).
int rank_of_tile(const WallSpec& spec, int tile_index, Eye eye = Eye::centre);

// How the report names a tile rank's screen: "tile 3", with stereo "tile 3, left eye".
std::string tile_name(const WallSpec& spec, int rank);

std::string to_string(StereoMode mode);  // "side-by-side", "top-bottom", "full"
std::string to_string(Eye eye);          // "centre", "left", "right"

std::ostream& operator<<(std::ostream& os, const WallSpec& spec);
std::ostream& operator<<(std::ostream& os, const PixelRect& r);

}  // namespace isowall
