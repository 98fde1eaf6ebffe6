#include "progressive/mesh_coverage.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "core/pixel_rect_ops.h"

namespace isowall {
namespace {

// Twice the signed area of (a, b, p): which side of a -> b the point p lies on.
float edge(glm::vec2 a, glm::vec2 b, glm::vec2 p) {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

}  // namespace

void add_mesh_coverage(const Mesh& mesh, const glm::mat4& view, const Frustum& frustum, int width,
                       int height, const PixelRect& rect, std::vector<std::uint8_t>& covered) {
    if (covered.size() != pixel_count(rect))
        throw std::invalid_argument("add_mesh_coverage: covered does not match the rect");
    if (is_empty(rect)) return;
    const glm::mat4 m = frustum.matrix() * view;
    // Window coordinates, y from the top; the flag marks corners the renderer would clip.
    std::vector<glm::vec2> win(mesh.positions.size());
    std::vector<std::uint8_t> clipped(mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::vec4 c = m * glm::vec4(mesh.positions[i], 1.0f);
        clipped[i] = !(c.w > 0.0f) || c.z < -c.w || c.z > c.w;
        const float inv_w = clipped[i] ? 0.0f : 1.0f / c.w;
        win[i] = ndc_to_window(c.x * inv_w, c.y * inv_w, width, height);
    }
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t ia = mesh.indices[t], ib = mesh.indices[t + 1],
                            ic = mesh.indices[t + 2];
        if (clipped[ia] || clipped[ib] || clipped[ic]) continue;
        const glm::vec2 a = win[ia], b = win[ib], c = win[ic];
        const float area = edge(a, b, c);
        if (area == 0.0f || !std::isfinite(area)) continue;
        // Pixel centres (x + 0.5) inside the triangle's bounding box, clipped to the rect (in
        // floats first: a corner near the eye plane may lie far outside any int).
        const float fx0 = std::max(std::min({a.x, b.x, c.x}) - 0.5f, float(rect.x));
        const float fx1 =
            std::min(std::max({a.x, b.x, c.x}) - 0.5f, float(rect.x + rect.width - 1));
        const float fy0 = std::max(std::min({a.y, b.y, c.y}) - 0.5f, float(rect.y));
        const float fy1 =
            std::min(std::max({a.y, b.y, c.y}) - 0.5f, float(rect.y + rect.height - 1));
        if (!(fx0 <= fx1 && fy0 <= fy1)) continue;
        const int x0 = int(std::ceil(fx0)), x1 = int(std::floor(fx1));
        const int y0 = int(std::ceil(fy0)), y1 = int(std::floor(fy1));
        const float s = area > 0.0f ? 1.0f : -1.0f;  // either winding
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const glm::vec2 p(float(x) + 0.5f, float(y) + 0.5f);
                if (s * edge(a, b, p) >= 0.0f && s * edge(b, c, p) >= 0.0f &&
                    s * edge(c, a, p) >= 0.0f)
                    covered[std::size_t(y - rect.y) * std::size_t(rect.width) +
                            std::size_t(x - rect.x)] = 1;
            }
    }
}

}  // namespace isowall
