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

}  // namespace isowall
