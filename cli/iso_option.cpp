#include "cli/iso_option.h"

#include <cstdio>

#include "cli/cli_checks.h"
#include "core/error.h"
#include "volume/phantom.h"

namespace isowall {

void add_iso_option(CLI::App& cmd, std::optional<double>& iso) {
    char help[96];
    std::snprintf(help, sizeof(help), "Isovalue (default for the phantom: skin, %g)",
                  kPhantomSkinIso);
    cmd.add_option("--iso", iso, help)->transform(number_in(limits::kAnyFinite));
}

double checked_iso(const std::optional<double>& iso, const IsoSource& source) {
    if (!iso) {
        if (source.phantom) return kPhantomSkinIso;
        throw InputError(source.where, "--iso", "an isovalue is required (see `isowall info`)");
    }
    return checked_isovalue(*iso, source.lo, source.hi, source.where, "--iso");
}

void add_surfaces_option(CLI::App& cmd, std::vector<std::string>& surfaces) {
    char help[320];
    std::snprintf(help, sizeof(help),
                  "Isovalue (default for the phantom: skin, %g); several surfaces: VALUE[:COLOUR"
                  "[:OPACITY]] each, e.g. --iso 40:skin:0.3 --iso 105:bone (COLOUR: #rrggbb or "
                  "a name: skin, bone, white, red, ...; OPACITY in [0, 1], default 1)",
                  kPhantomSkinIso);
    // Each value is checked as it is parsed (a typo or a non-finite number is refused naming the
    // option and the value); the volume's range is checked once it is read.
    const CLI::Validator style(
        [](std::string& text) {
            std::string problem;
            return parse_surface_style(text, problem) ? std::string() : problem;
        },
        "VALUE[:COLOUR[:OPACITY]]");
    cmd.add_option("--iso", surfaces, help)->type_name("VALUE[:COLOUR[:OPACITY]]")->check(style);
}

namespace {

std::vector<SurfaceStyle> parsed_surfaces(const std::vector<std::string>& given,
                                          const std::string& where, const std::string& field) {
    std::vector<SurfaceStyle> out;
    for (const std::string& text : given) {
        std::string problem;
        const std::optional<SurfaceStyle> s = parse_surface_style(text, problem);
        if (!s) throw InputError(where, field, problem);
        out.push_back(*s);
    }
    if (!out.empty())
        if (std::string problem = surfaces_problem(out); !problem.empty())
            throw InputError(where, field, problem);
    return canonical_order(out);
}

}  // namespace

void check_surface_texts(const std::vector<std::string>& given) {
    (void)parsed_surfaces(given, "--iso", "value");
}

std::vector<SurfaceStyle> checked_surfaces(const std::vector<std::string>& given,
                                           const IsoSource& source) {
    std::vector<SurfaceStyle> out = parsed_surfaces(given, source.where, "--iso");
    if (out.empty()) {
        SurfaceStyle s;
        s.iso = checked_iso(std::nullopt, source);
        return {s};
    }
    for (SurfaceStyle& s : out)
        s.iso = checked_isovalue(s.iso, source.lo, source.hi, source.where, "--iso");
    return out;
}

}  // namespace isowall
