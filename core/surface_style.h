#pragma once
// Several isosurfaces of one volume shown together, each in its colour and with its opacity: the
// skin at 0.3 over the bone. An operator gives each as VALUE[:COLOUR[:OPACITY]] (`--iso
// 40:skin:0.3 --iso 105:bone`). The picture of a set of surfaces is each surface drawn alone (its
// nearest layer at every pixel, as one surface is drawn) and the layers blended back to front by
// depth at every pixel (core/image_ops.h composite_layers): it does not depend on the order the
// surfaces were given in, or on which thread or rank drew a layer.
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"

namespace isowall {

// The colour a surface has when none is given: the headlight's front colour (render/headlight.h).
inline constexpr glm::u8vec3 kDefaultSurfaceColour{230, 217, 191};

// At most this many surfaces in one picture: each is an extractor's frame and a layer of the
// screen's size, and a bound for a message to check.
inline constexpr std::size_t kMaxSurfaces = 8;

struct SurfaceStyle {
    double iso = 0;
    glm::u8vec3 colour = kDefaultSurfaceColour;
    float opacity = 1;      // in [0, 1]; 1 hides what lies behind
    bool coloured = false;  // a colour was given (else the plain headlight colours)

    friend bool operator==(const SurfaceStyle&, const SurfaceStyle&) = default;
};

// "40", "40:skin", "105:#f1d691:0.5", "40::0.3" (the default colour at 0.3). Colours are
// names (colour_names()) or #rrggbb. On failure, nullopt and `problem` says why.
std::optional<SurfaceStyle> parse_surface_style(std::string_view text, std::string& problem);

// The colour called `name`, or nullopt: CSS's colour keywords for the common hues and 3D Slicer's
// anatomy colours for skin and bone (its GenericAnatomyColors table).
std::optional<glm::u8vec3> surface_colour_named(std::string_view name);
// "skin, bone, white, ...": the names surface_colour_named knows.
std::string colour_names();

// The form parse_surface_style reads: "40:#b17a65:0.3".
std::string surface_style_text(const SurfaceStyle& s);

// The surfaces in the one order every picture of them uses (by isovalue), so layers, seeds and
// ties at equal depth never depend on the order an operator listed them in.
std::vector<SurfaceStyle> canonical_order(std::vector<SurfaceStyle> surfaces);

// Why `surfaces` cannot be shown together, or empty: none, more than kMaxSurfaces, or one
// isovalue given twice.
std::string surfaces_problem(const std::vector<SurfaceStyle>& surfaces);

// What colours a surface's meshes (EngineOptions::colour): `field` where a second field colours
// every surface, else the style's own colour where it has one (every vertex), else nothing (the
// plain headlight colours).
std::function<void(Mesh&)> surface_colour_hook(const SurfaceStyle& style,
                                               const std::function<void(Mesh&)>& field = {});

// Whether the set is drawn as one plain opaque surface (the engine's single-surface picture).
inline bool one_opaque_surface(const std::vector<SurfaceStyle>& s) {
    return s.size() == 1 && s[0].opacity >= 1;
}

// Whether the set is one plain surface: opaque, in the headlight's colours (what a bare isovalue
// gives, and what the printed forms leave as the isovalue alone).
inline bool one_plain_surface(const std::vector<SurfaceStyle>& s) {
    return one_opaque_surface(s) && !s[0].coloured;
}

}  // namespace isowall
