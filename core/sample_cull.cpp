#include "core/sample_cull.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "core/camera.h"

namespace isowall {
namespace {

constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();

// The pixels (i, i in [0, n)) whose centres i + 0.5 lie in [lo, hi], widened by the margin:
// first > last when none.
struct Span {
    float first, last;
};
Span centres_in(float lo, float hi, int n) {
    return {std::max(std::ceil(lo - kSampleCullMarginPx - 0.5f), 0.0f),
            std::min(std::floor(hi + kSampleCullMarginPx - 0.5f), float(n - 1))};
}

// A triangle whose box holds at most this many centres has each tested against its edges; a
// larger one is kept (it covers one surely enough, and testing would cost more than drawing).
constexpr float kCentresTested = 4;

// Whether the point lies inside the triangle (a, b, c) or within the margin of it; `area2` is
// twice its signed area (non-zero).
bool near_inside(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c, float area2) {
    const glm::vec2 v[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        const glm::vec2 e = v[(k + 1) % 3] - v[k], d = p - v[k];
        // The point's distance inside the edge's line (positive inside), against the margin.
        const float cross = (e.x * d.y - e.y * d.x) * (area2 > 0 ? 1.0f : -1.0f);
        if (cross < -kSampleCullMarginPx * std::sqrt(e.x * e.x + e.y * e.y)) return false;
    }
    return true;
}

// Whether the triangle may cover the centre of a pixel of a width x height frame.
bool covers_a_centre(glm::vec2 a, glm::vec2 b, glm::vec2 c, int width, int height) {
    const Span x = centres_in(std::min({a.x, b.x, c.x}), std::max({a.x, b.x, c.x}), width);
    const Span y = centres_in(std::min({a.y, b.y, c.y}), std::max({a.y, b.y, c.y}), height);
    if (x.first > x.last || y.first > y.last) return false;
    const float area2 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if ((x.last - x.first + 1) * (y.last - y.first + 1) > kCentresTested || area2 == 0) return true;
    for (float j = y.first; j <= y.last; ++j)
        for (float i = x.first; i <= x.last; ++i)
            if (near_inside({i + 0.5f, j + 0.5f}, a, b, c, area2)) return true;
    return false;
}

}  // namespace

bool box_holds_a_centre(float x0, float x1, float y0, float y1, int width, int height) {
    const Span x = centres_in(x0, x1, width), y = centres_in(y0, y1, height);
    return x.first <= x.last && y.first <= y.last;
}

std::size_t keep_sampled_triangles(const Mesh& mesh, const glm::mat4& clip, int width, int height,
                                   Mesh& out, SampleCullScratch& scratch) {
    out.positions.clear();
    out.normals.clear();
    out.colours.clear();
    out.indices.clear();
    const std::size_t n = mesh.positions.size();
    const bool colours = mesh.colours.size() == n;
    scratch.window.resize(n);
    scratch.kept_always.assign(n, 0);
    for (std::size_t v = 0; v < n; ++v) {
        const glm::vec4 c = clip * glm::vec4(mesh.positions[v], 1.0f);
        scratch.window[v] = ndc_to_window(c.x / c.w, c.y / c.w, width, height);
        scratch.kept_always[v] =
            !(c.w > 0) || !std::isfinite(scratch.window[v].x + scratch.window[v].y);
    }
    scratch.remap.assign(n, kUnused);
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t i[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
        const bool always =
            scratch.kept_always[i[0]] || scratch.kept_always[i[1]] || scratch.kept_always[i[2]];
        if (!always && !covers_a_centre(scratch.window[i[0]], scratch.window[i[1]],
                                        scratch.window[i[2]], width, height))
            continue;
        for (const std::uint32_t v : i) {
            if (scratch.remap[v] == kUnused) {
                scratch.remap[v] = static_cast<std::uint32_t>(out.positions.size());
                out.positions.push_back(mesh.positions[v]);
                out.normals.push_back(mesh.normals[v]);
                if (colours) out.colours.push_back(mesh.colours[v]);
            }
            out.indices.push_back(scratch.remap[v]);
        }
    }
    return out.triangle_count();
}

}  // namespace isowall
