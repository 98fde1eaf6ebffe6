#include "cli/colour_option.h"

#include <cctype>
#include <filesystem>

#include "cli/cli_checks.h"
#include "core/error.h"
#include "core/number.h"

namespace isowall {

void add_colour_options(CLI::App& cmd, ColourOptions& colour) {
    cmd.add_option("--color-by", colour.by,
                   "Colour the surface by a second field on the same grid (any format --volume "
                   "reads; a raw file takes --dims, --type, --spacing)")
        ->type_name("FILE");
    cmd.add_option("--colormap", colour.map, "Colour map of --color-by: " + colour_map_names())
        ->capture_default_str();
    cmd.add_option("--color-range", colour.range,
                   "The values at the colour map's ends (default: the field's finite range)")
        ->expected(2)
        ->type_name("LO HI")
        ->transform(number_in(limits::kAnyFinite));
}

ColourMap checked_colour_map(const ColourOptions& colour) {
    const auto map = colour_map_named(colour.map);
    if (!map)
        throw InputError(
            "--colormap", "value",
            "unknown colour map " + quote(colour.map) + " (expected " + colour_map_names() + ")");
    if (colour.range.size() == 2 && !(colour.range[0] < colour.range[1]))
        throw InputError("--color-range", "value",
                         "expected LO below HI, got " + std::to_string(colour.range[0]) + " " +
                             std::to_string(colour.range[1]));
    return *map;
}

std::optional<OpenedColourField> open_colour_field(const ColourOptions& colour,
                                                   const VolumeOptions& surface_options,
                                                   const Volume& surface) {
    const ColourMap map = checked_colour_map(colour);
    if (colour.by.empty()) return std::nullopt;
    VolumeOptions o = surface_options;
    o.path = colour.by;
    o.no_cache = true;  // its octree is never built: only its voxels are read
    OpenedColourField out;
    out.opened = std::make_unique<OpenedVolume>(open_volume(o, /*quiet=*/true));
    const Volume& values = out.opened->volume;
    if (const std::string p = colour_field_problem(values, surface); !p.empty())
        throw InputError(colour.by, "--color-by", p);
    const auto [lo, hi] = colour.range.size() == 2 ? std::pair{colour.range[0], colour.range[1]}
                                                   : finite_range(values);
    out.field = {&values, {map, lo, hi}};
    return out;
}

std::string colour_label(const ColourOptions& colour, const ColourScale& scale) {
    std::string label = std::filesystem::path(colour.by).filename().string();
    for (char& c : label) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return label + " (" + std::string(scale.map.name) + ")";
}

std::function<void(Mesh&)> colour_hook(const ColourField& field, glm::vec3 spacing) {
    return [field, spacing](Mesh& mesh) { colour_mesh(mesh, field, spacing); };
}

}  // namespace isowall
