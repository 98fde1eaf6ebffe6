#pragma once
// --iso: one declaration and one check for every subcommand that draws a surface (render,
// extract, wall, view). A volume file has no default isovalue; the built-in phantom's is its
// skin.
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/surface_style.h"

namespace isowall {

void add_iso_option(CLI::App& cmd, std::optional<double>& iso);

// Where an isovalue's values come from: `where` names it in errors (a file, "phantom", a served
// dataset), and [lo, hi] is the range of its values.
struct IsoSource {
    std::string where;
    bool phantom = false;
    double lo = 0, hi = 0;
};

// The isovalue --iso gives for `source`: --iso, else the phantom's skin when `source` is the
// phantom. Throws an InputError naming the source and --iso when a file has none, or when the
// isovalue lies outside [lo, hi] (no surface there: a blank picture).
double checked_iso(const std::optional<double>& iso, const IsoSource& source);

// --iso as `render` takes it: an isovalue, or several surfaces, each VALUE[:COLOUR[:OPACITY]]
// (core/surface_style.h), the option repeated or its values listed.
void add_surfaces_option(CLI::App& cmd, std::vector<std::string>& surfaces);

// The surfaces --iso gives for `source`, in canonical order (core/surface_style.h): without --iso
// the phantom's skin, as checked_iso. Throws an InputError naming the source and --iso for a text
// that is no surface, an isovalue outside [lo, hi], one isovalue given twice or too many.
std::vector<SurfaceStyle> checked_surfaces(const std::vector<std::string>& given,
                                           const IsoSource& source);
// The same texts checked before any volume is read (no range yet): a typo fails at once.
void check_surface_texts(const std::vector<std::string>& given);

}  // namespace isowall
