#include "remote/request_checks.h"

#include <cmath>
#include <cstdio>

namespace isowall::remote {
namespace {

std::string format(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

// Why `lo` < `hi` fails as a span named `hi_name` over `lo_name`, or empty.
std::string span_problem(const char* lo_name, double lo, const char* hi_name, double hi) {
    if (!(hi > lo))
        return std::string(hi_name) + ": expected more than " + lo_name + " (" + format(lo) +
               "), got " + format(hi);
    if (hi - lo < kMinFrustumSpan)
        return std::string(hi_name) + ": expected at least " + format(kMinFrustumSpan) +
               " more than " + lo_name + " (" + format(lo) + "), got " + format(hi);
    return {};
}

}  // namespace

std::string frustum_problem(const Frustum& f) {
    const struct {
        const char* name;
        double value;
    } fields[] = {{"left", f.left}, {"right", f.right},   {"bottom", f.bottom},
                  {"top", f.top},   {"near_z", f.near_z}, {"far_z", f.far_z}};
    for (const auto& field : fields)
        if (!(std::abs(field.value) <= kMaxFrustumReach))  // NaN fails too
            return std::string(field.name) + ": expected a number within " +
                   format(kMaxFrustumReach) + " of zero, got " + format(field.value);
    if (std::string p = span_problem("left", f.left, "right", f.right); !p.empty()) return p;
    if (std::string p = span_problem("bottom", f.bottom, "top", f.top); !p.empty()) return p;
    if (f.projection == Projection::perspective && !(f.near_z >= kMinFrustumSpan))
        return "near_z: expected at least " + format(kMinFrustumSpan) +
               " for a perspective view, got " + format(f.near_z);
    return span_problem("near_z", f.near_z, "far_z", f.far_z);
}

std::string iso_problem(double iso, double value_min, double value_max) {
    if (iso >= value_min && iso <= value_max) return {};
    return "expected a value in [" + format(value_min) + ", " + format(value_max) +
           "] (the dataset's range), got " + format(iso);
}

}  // namespace isowall::remote
