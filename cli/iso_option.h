#pragma once
// --iso: one declaration and one check for every subcommand that draws a surface (render,
// extract, wall, view). A volume file has no default isovalue; the built-in phantom's is its
// skin.
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

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

}  // namespace isowall
