#pragma once
// Colour maps: a value's place in a range turned into a colour, for surfaces coloured by a second
// field (`--color-by`). The tables are matplotlib's, 256 entries each (core/colour_map_tables.inc,
// written by scripts/make_colour_maps.py), so viridis here is viridis everywhere.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

namespace isowall {

using ColourTable = std::array<std::array<std::uint8_t, 3>, 256>;

struct ColourMap {
    std::string_view name;
    const ColourTable* table = nullptr;

    // The colour at `t` in [0, 1] (clamped; NaN takes the low end), linearly between entries.
    glm::u8vec3 at(double t) const;
};

// The map called `name` (viridis, magma, inferno, plasma, cividis, coolwarm, turbo, gray).
std::optional<ColourMap> colour_map_named(std::string_view name);
// "viridis, magma, ...": the names colour_map_named knows, for help and errors.
std::string colour_map_names();

// A map over a range of values: what a coloured surface's legend shows.
struct ColourScale {
    ColourMap map;
    double lo = 0, hi = 1;

    glm::u8vec3 at(double value) const { return map.at(hi > lo ? (value - lo) / (hi - lo) : 0.5); }
};

}  // namespace isowall
