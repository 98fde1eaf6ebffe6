// Harness: wall files (wall_spec/wall_file.cpp, TOML through toml++). A wall that parses must
// be one the rest of the program can use as is: its virtual screen and every tile rectangle fit
// in an int (they are computed in int by wall_geometry.cpp; here first in 64 bits, so an overflow
// is caught as a broken property even without UBSan), at least one tile is enabled, and for a
// wall small enough to walk, ranks and tiles map one to one.
#include <climits>
#include <cmath>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "fuzz/fuzz_check.h"
#include "wall_spec/wall.h"

namespace {

using isowall::fuzz::check;

constexpr int kMaxTileSide =
    32768;  // wall_protocol/protocol.h's kMaxImageSide; wall_spec/ cannot see it

bool fits_int(std::int64_t v) {
    return v >= INT_MIN && v <= INT_MAX;
}

// The virtual screen and the tile rectangles, in 64 bits, before wall_geometry computes them in
// int: every value must fit, or the program's geometry is a lie.
void check_sizes(const isowall::WallSpec& s) {
    check(s.columns >= 1 && s.rows >= 1, "at least one column and one row");
    // A tile's image travels to the master in an image message, whose sides are at most
    // kMaxImageSide (wall_protocol/protocol.h): a larger tile would fail only at its first frame.
    check(s.tile_width_px >= 1 && s.tile_height_px >= 1, "positive tile size");
    check(s.tile_width_px <= kMaxTileSide && s.tile_height_px <= kMaxTileSide,
          "a tile no larger than an image message carries");
    const auto& b = s.bezel_px;
    const std::int64_t step_x = std::int64_t{s.tile_width_px} + b.left + b.right;
    const std::int64_t step_y = std::int64_t{s.tile_height_px} + b.top + b.bottom;
    check(step_x > 0 && step_y > 0, "overlap less than a tile");
    const std::int64_t width = std::int64_t{s.columns} * s.tile_width_px +
                               std::int64_t{s.columns - 1} * (std::int64_t{b.left} + b.right);
    const std::int64_t height = std::int64_t{s.rows} * s.tile_height_px +
                                std::int64_t{s.rows - 1} * (std::int64_t{b.top} + b.bottom);
    check(fits_int(width) && fits_int(height) && fits_int(step_x * s.columns) &&
              fits_int(step_y * s.rows),
          "the virtual screen fits in an int");
    for (const isowall::TileOverride& o : s.overrides)
        check(
            fits_int(step_x * o.column + o.offset_x_px) && fits_int(step_y * o.row + o.offset_y_px),
            "a shifted tile's rectangle fits in an int");
    const isowall::PixelSize screen = isowall::virtual_screen_size(s);
    check(screen.width == width && screen.height == height, "virtual_screen_size");
}

// Bezels given in mm are the nearest pixels at the tile's pitch.
void check_bezel_mm(const isowall::WallSpec& s) {
    if (!s.physical) return;
    const isowall::BezelsMm& mm = s.physical->bezel_mm;
    if (mm.left == 0 && mm.right == 0 && mm.top == 0 && mm.bottom == 0) return;  // bezel_px
    const double pitch_x = s.physical->tile_width_mm / s.tile_width_px;
    const double pitch_y = s.physical->tile_height_mm / s.tile_height_px;
    auto near = [](int px, double v) { return std::isfinite(v) && std::abs(px - v) <= 0.5001; };
    const isowall::Bezels& b = s.bezel_px;
    check(near(b.left, mm.left / pitch_x) && near(b.right, mm.right / pitch_x) &&
              near(b.top, mm.top / pitch_y) && near(b.bottom, mm.bottom / pitch_y),
          "bezel_px are bezel_mm at the tile's pixel pitch");
}

void check_ranks(const isowall::WallSpec& s) {
    const int ranks = isowall::rank_count(s);
    check(ranks >= 2 && ranks <= isowall::tile_count(s) * isowall::eyes_per_tile(s) + 1,
          "one master and 1..T tile ranks per eye");
    if (isowall::tile_count(s) > 64) return;  // tile_of_rank walks the wall: keep it quick
    for (int rank = 1; rank < ranks; ++rank) {
        const int tile = isowall::tile_of_rank(s, rank);
        check(tile >= 0 && isowall::rank_of_tile(s, tile, isowall::eye_of_rank(s, rank)) == rank,
              "ranks and tiles' eyes 1:1");
        const isowall::PixelRect r = isowall::tile_rect(s, tile);
        check(r.width == s.tile_width_px && r.height == s.tile_height_px, "tile_rect size");
        const isowall::PixelRect e = isowall::eye_rect(s, tile);
        check(e.width >= 1 && e.height >= 1 && e.width <= r.width && e.height <= r.height,
              "an eye's frame is the tile's, or half of it");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const isowall::WallSpec spec =
            isowall::parse_wall(isowall::fuzz::as_text(data, size), "fuzz.toml");
        check_sizes(spec);
        check_bezel_mm(spec);
        check_ranks(spec);
    } catch (const isowall::InputError&) {
    }
    return 0;
}
