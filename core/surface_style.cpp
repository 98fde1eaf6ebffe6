#include "core/surface_style.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <utility>

#include "core/number.h"

namespace isowall {
namespace {

struct NamedColour {
    std::string_view name;
    glm::u8vec3 rgb;
};

// skin and bone: 3D Slicer's GenericAnatomyColors; the rest: CSS Color Module keywords.
constexpr std::array<NamedColour, 18> kNamed{{
    {"skin", {177, 122, 101}},
    {"bone", {241, 214, 145}},
    {"white", {255, 255, 255}},
    {"silver", {192, 192, 192}},
    {"gray", {128, 128, 128}},
    {"red", {255, 0, 0}},
    {"orange", {255, 165, 0}},
    {"gold", {255, 215, 0}},
    {"yellow", {255, 255, 0}},
    {"green", {0, 128, 0}},
    {"lime", {0, 255, 0}},
    {"teal", {0, 128, 128}},
    {"cyan", {0, 255, 255}},
    {"blue", {0, 0, 255}},
    {"purple", {128, 0, 128}},
    {"magenta", {255, 0, 255}},
    {"pink", {255, 192, 203}},
    {"tan", {210, 180, 140}},
}};

std::optional<glm::u8vec3> parse_colour(std::string_view t) {
    if (t.size() == 7 && t[0] == '#') {
        glm::u8vec3 c{0};
        for (int k = 0; k < 3; ++k) {
            const int hi = hex_digit(t[1 + 2 * k]), lo = hex_digit(t[2 + 2 * k]);
            if (hi < 0 || lo < 0) return std::nullopt;
            c[k] = static_cast<std::uint8_t>(hi * 16 + lo);
        }
        return c;
    }
    return surface_colour_named(t);
}

// Splits at ':' into at most `n` parts; false when there are more.
bool split_fields(std::string_view t, std::vector<std::string_view>& out, std::size_t n) {
    out.clear();
    std::size_t start = 0;
    while (true) {
        const std::size_t colon = t.find(':', start);
        out.push_back(t.substr(start, colon == std::string_view::npos ? colon : colon - start));
        if (colon == std::string_view::npos) return out.size() <= n;
        start = colon + 1;
    }
}

}  // namespace

std::optional<glm::u8vec3> surface_colour_named(std::string_view name) {
    for (const NamedColour& c : kNamed)
        if (c.name == name) return c.rgb;
    return std::nullopt;
}

std::string colour_names() {
    std::string out;
    for (const NamedColour& c : kNamed) {
        if (!out.empty()) out += ", ";
        out += c.name;
    }
    return out;
}

std::optional<SurfaceStyle> parse_surface_style(std::string_view text, std::string& problem) {
    std::vector<std::string_view> f;
    if (!split_fields(text, f, 3)) {
        problem = "expected VALUE[:COLOUR[:OPACITY]], got '" + std::string(text) + "'";
        return std::nullopt;
    }
    SurfaceStyle s;
    const auto iso = parse_number(f[0]);
    if (!iso) {
        problem = "expected an isovalue before ':', got '" + std::string(f[0]) + "'";
        return std::nullopt;
    }
    s.iso = *iso;
    if (f.size() > 1 && !f[1].empty()) {
        const auto c = parse_colour(f[1]);
        if (!c) {
            problem = "unknown colour '" + std::string(f[1]) + "': expected #rrggbb or one of " +
                      colour_names();
            return std::nullopt;
        }
        s.colour = *c;
        s.coloured = true;
    }
    if (f.size() > 2) {
        const auto a = parse_number(f[2]);
        if (!a || *a < 0 || *a > 1) {
            problem = "expected an opacity in [0, 1], got '" + std::string(f[2]) + "'";
            return std::nullopt;
        }
        s.opacity = static_cast<float>(*a);
    }
    return s;
}

std::string surface_style_text(const SurfaceStyle& s) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.9g", s.iso);
    std::string out = buf;
    if (s.coloured) {
        std::snprintf(buf, sizeof(buf), ":#%02x%02x%02x", s.colour.x, s.colour.y, s.colour.z);
        out += buf;
    }
    if (s.opacity < 1) {
        std::snprintf(buf, sizeof(buf), "%s:%.6g", s.coloured ? "" : ":", double(s.opacity));
        out += buf;
    }
    return out;
}

std::vector<SurfaceStyle> canonical_order(std::vector<SurfaceStyle> surfaces) {
    std::stable_sort(surfaces.begin(), surfaces.end(),
                     [](const SurfaceStyle& a, const SurfaceStyle& b) { return a.iso < b.iso; });
    return surfaces;
}

std::string surfaces_problem(const std::vector<SurfaceStyle>& surfaces) {
    if (surfaces.empty()) return "no surface given";
    if (surfaces.size() > kMaxSurfaces)
        return std::to_string(surfaces.size()) + " surfaces: at most " +
               std::to_string(kMaxSurfaces) + " are shown together";
    const std::vector<SurfaceStyle> s = canonical_order(surfaces);
    for (std::size_t k = 1; k < s.size(); ++k)
        if (s[k].iso == s[k - 1].iso) {
            char buf[64];
            std::snprintf(buf, sizeof(buf), "isovalue %.9g given twice", s[k].iso);
            return buf;
        }
    return {};
}

std::function<void(Mesh&)> surface_colour_hook(const SurfaceStyle& style,
                                               const std::function<void(Mesh&)>& field) {
    if (field || !style.coloured) return field;
    return [rgb = style.colour](Mesh& mesh) { mesh.colours.assign(mesh.vertex_count(), rgb); };
}

}  // namespace isowall
