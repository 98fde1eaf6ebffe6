#include "core/ray.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace isowall {

Ray pixel_ray(const glm::mat4& view_inverse, const Frustum& f, int width, int height,
              glm::ivec2 pixel) {
    const float u = (static_cast<float>(pixel.x) + 0.5f) / static_cast<float>(width);
    const float v = (static_cast<float>(pixel.y) + 0.5f) / static_cast<float>(height);
    const float x = f.left + u * (f.right - f.left);
    const float y = f.top - v * (f.top - f.bottom);
    Ray view_ray;
    if (f.projection == Projection::perspective) {
        view_ray.o = glm::vec3(0);
        view_ray.d = glm::normalize(glm::vec3(x, y, -f.near_z));
    } else {
        view_ray.o = glm::vec3(x, y, 0);
        view_ray.d = glm::vec3(0, 0, -1);
    }
    Ray r;
    r.o = glm::vec3(view_inverse * glm::vec4(view_ray.o, 1.0f));
    r.d = glm::vec3(view_inverse * glm::vec4(view_ray.d, 0.0f));
    return r;
}

bool intersect_box(const Ray& r, const glm::vec3& inv_d, glm::vec3 lo, glm::vec3 hi, float& t0,
                   float& t1) {
    const glm::vec3 a = (lo - r.o) * inv_d;
    const glm::vec3 b = (hi - r.o) * inv_d;
    const glm::vec3 tmin = glm::min(a, b), tmax = glm::max(a, b);
    t0 = std::max({tmin.x, tmin.y, tmin.z});
    t1 = std::min({tmax.x, tmax.y, tmax.z});
    return t0 <= t1;
}

bool intersect_triangle(const Ray& r, glm::vec3 a, glm::vec3 b, glm::vec3 c, float t_min,
                        float& t) {
    const glm::vec3 e1 = b - a, e2 = c - a;
    const glm::vec3 p = glm::cross(r.d, e2);
    const float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12f) return false;  // parallel to the triangle's plane
    const float inv = 1.0f / det;
    const glm::vec3 s = r.o - a;
    const float u = glm::dot(s, p) * inv;
    // A small tolerance closes the cracks between neighbouring triangles for rays that pass
    // exactly through a shared edge: a miss there would cost a pixel in the final image.
    constexpr float kEps = 1e-5f;
    if (u < -kEps || u > 1.0f + kEps) return false;
    const glm::vec3 q = glm::cross(s, e1);
    const float v = glm::dot(r.d, q) * inv;
    if (v < -kEps || u + v > 1.0f + kEps) return false;
    t = glm::dot(e2, q) * inv;
    return t >= t_min;
}

PixelRect screen_box(const Box3& b, const glm::mat4& view, const Frustum& f, int width,
                     int height) {
    const glm::mat4 clip = f.matrix() * view;
    float x0 = std::numeric_limits<float>::max(), y0 = x0;
    float x1 = -x0, y1 = -x0;
    for (int k = 0; k < 8; ++k) {
        const glm::vec3 p((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y,
                          (k & 4) ? b.max.z : b.min.z);
        const glm::vec4 c = clip * glm::vec4(p, 1.0f);
        if (c.w <= 1e-6f) return {0, 0, width, height};  // behind the eye: no bound
        const glm::vec2 px = ndc_to_window(c.x / c.w, c.y / c.w, width, height);
        x0 = std::min(x0, px.x);
        x1 = std::max(x1, px.x);
        y0 = std::min(y0, px.y);
        y1 = std::max(y1, px.y);
    }
    // Pixels whose centres may fall inside the projected box, with one pixel of margin.
    const int ix0 = std::clamp(static_cast<int>(std::floor(x0)) - 1, 0, width);
    const int iy0 = std::clamp(static_cast<int>(std::floor(y0)) - 1, 0, height);
    const int ix1 = std::clamp(static_cast<int>(std::ceil(x1)) + 1, 0, width);
    const int iy1 = std::clamp(static_cast<int>(std::ceil(y1)) + 1, 0, height);
    return {ix0, iy0, std::max(0, ix1 - ix0), std::max(0, iy1 - iy0)};
}

}  // namespace isowall
