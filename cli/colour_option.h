#pragma once
// --color-by, --colormap and --color-range: a surface coloured by a second field on the same grid
// (volume/colour_field.h), for every subcommand that draws one (render, wall).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/volume_options.h"
#include "volume/colour_field.h"

namespace isowall {

struct ColourOptions {
    std::string by;               // --color-by FILE; empty: the surface's one colour
    std::string map = "viridis";  // --colormap
    std::vector<double> range;    // --color-range LO HI; empty: the field's finite values
};

void add_colour_options(CLI::App& cmd, ColourOptions& colour);

// The colour map --colormap names; throws an InputError naming the option otherwise. Checked
// before any volume is read.
ColourMap checked_colour_map(const ColourOptions& colour);

// The second field, opened, and its scale: what colours the surface.
struct OpenedColourField {
    std::unique_ptr<OpenedVolume> opened;  // holds the voxels the field reads
    ColourField field;
};

// Opens --color-by as `surface_options` would open a volume (a raw file takes the surface's
// --dims, --type, --spacing) and checks it against `surface`; nullopt without --color-by. Throws
// an InputError naming --color-by and the file when it cannot colour the surface.
std::optional<OpenedColourField> open_colour_field(const ColourOptions& colour,
                                                   const VolumeOptions& surface_options,
                                                   const Volume& surface);

// The legend's title: the field's file name, lower case, and the map ("dose.nrrd (viridis)").
std::string colour_label(const ColourOptions& colour, const ColourScale& scale);

// The engine's colour hook for `field` over `surface`'s spacing (EngineOptions::colour).
std::function<void(Mesh&)> colour_hook(const ColourField& field, glm::vec3 spacing);

}  // namespace isowall
