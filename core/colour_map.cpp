#include "core/colour_map.h"

#include <algorithm>
#include <cmath>

namespace isowall {
namespace {

struct NamedTable {
    const char* name;
    ColourTable table;
};

const NamedTable kTables[] = {
#include "core/colour_map_tables.inc"
};

}  // namespace

glm::u8vec3 ColourMap::at(double t) const {
    if (!(t > 0)) t = 0;  // NaN too
    const double x = std::min(t, 1.0) * 255.0;
    const auto i = static_cast<std::size_t>(std::min(x, 254.0));
    const double f = x - static_cast<double>(i);
    glm::u8vec3 c;
    for (std::size_t k = 0; k < 3; ++k) {
        const double a = (*table)[i][k], b = (*table)[i + 1][k];
        c[static_cast<int>(k)] = static_cast<std::uint8_t>(std::lround(a + f * (b - a)));
    }
    return c;
}

std::optional<ColourMap> colour_map_named(std::string_view name) {
    for (const NamedTable& t : kTables)
        if (name == t.name) return ColourMap{t.name, &t.table};
    return std::nullopt;
}

std::string colour_map_names() {
    std::string out;
    for (const NamedTable& t : kTables) out += (out.empty() ? "" : ", ") + std::string(t.name);
    return out;
}

}  // namespace isowall
