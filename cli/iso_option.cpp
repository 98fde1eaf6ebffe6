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
    if (!(*iso >= source.lo && *iso <= source.hi)) {
        char msg[160];
        std::snprintf(msg, sizeof(msg), "isovalue %g is outside the value range [%g, %g]", *iso,
                      source.lo, source.hi);
        throw InputError(source.where, "--iso", msg);
    }
    return *iso;
}

}  // namespace isowall
