#pragma once
// The order in which a progressive extractor casts one ray per pixel (dissertation, section 3.1.2).
// Seeds found early decide how soon the picture looks right, so the order front-loads rays
// spread evenly over the screen; every pixel of the rect is still handed out exactly once, so a
// run that is not interrupted ends with the correct image (section 2.1.1).
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>

#include "core/camera.h"

namespace isowall {

// dynamic_gaps: the dynamic grid, then every pixel that still shows nothing, then the refining
// grids (opt-in while it costs the share of final pixels what it gains C = 1 - E).
enum class RayOrderKind { refining_grid, screen_readback, dynamic_grid, dynamic_gaps };

// The option spelling: "grid", "readback", "dynamic" or "gaps" (parse_ray_order reads it back).
std::string_view to_string(RayOrderKind kind);
// "grid" or "refining" -> refining_grid, "readback" -> screen_readback, "dynamic" -> dynamic_grid,
// "gaps" -> dynamic_gaps.
std::optional<RayOrderKind> parse_ray_order(std::string_view name);

// Hands out pixels (x right, y down from the top-left) level by level. Between levels the caster
// may report which pixels show the surface so far; the orders that use it ask via
// wants_coverage().
class RayOrder {
  public:
    virtual ~RayOrder() = default;
    // Appends the next level's pixels to `out` (cleared first); returns false when every pixel of
    // the rect has been handed out. A level is never empty.
    virtual bool next_level(std::vector<glm::ivec2>& out) = 0;
    // True when the caster should call set_coverage() before the next next_level().
    virtual bool wants_coverage() const { return false; }
    // covered[y * screen_width + x] != 0 when pixel (x, y) shows the surface now (full screen,
    // not just the rect); covered.size() must be screen_width * screen_height. The latest
    // coverage given orders every later level, even when not asked for again.
    virtual void set_coverage(std::span<const std::uint8_t> /*covered*/) {}
    virtual int level() const = 0;  // index of the last level handed out; -1 before the first
};

// `rect` is the part of the screen worth casting (the volume's screen bounding box); it is
// clipped to the screen, and no pixel outside it is ever handed out. An empty rect gives no level.
// `mask` (optional; screen_width * screen_height, row-major) narrows it further: a pixel where it
// is 0 is never handed out and counts as cast from the start (the screen mask: its ray cannot
// meet the surface), so the levels are those of the whole rect with such pixels dropped, and a
// rect masked out entirely gives no level.
std::unique_ptr<RayOrder> make_ray_order(RayOrderKind kind, int screen_width, int screen_height,
                                         PixelRect rect, std::span<const std::uint8_t> mask = {});

// The size in pixels of the first surface piece the dynamic grid sizes its grid from: sqrt of the
// area of the 4-connected covered region (inside `rect`) holding the first covered pixel in
// row-major order, clamped to [4, max(rect.width, rect.height)]. 0 when nothing in `rect` is
// covered.
double surface_piece_size(std::span<const std::uint8_t> covered, int screen_width, PixelRect rect);

}  // namespace isowall
