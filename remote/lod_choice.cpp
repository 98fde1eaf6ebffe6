#include "remote/lod_choice.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "core/ray.h"
#include "extract/marching_cubes.h"
#include "render/headlight.h"

namespace isowall::remote {
namespace {

// The corner voxel and the weights of trilinear interpolation at voxel-space point `q`, clamped
// to the volume.
struct Trilinear {
    glm::ivec3 base;
    glm::vec3 f;
};
template <class T>
Trilinear trilinear(const VolumeView<T>& v, glm::vec3 q) {
    const glm::vec3 c = glm::clamp(q, glm::vec3(0), glm::vec3(v.dims - 1));
    const glm::ivec3 b =
        glm::clamp(glm::ivec3(glm::floor(c)), glm::ivec3(0), glm::max(v.dims - 2, glm::ivec3(0)));
    return {b, glm::clamp(c - glm::vec3(b), 0.0f, 1.0f)};
}
// Calls f(voxel, weight) for the eight voxels around `q`.
template <class T, class F>
void around(const VolumeView<T>& v, glm::vec3 q, F&& f) {
    const Trilinear t = trilinear(v, q);
    for (int k = 0; k < 8; ++k) {
        const glm::ivec3 o((k & 1), (k >> 1) & 1, (k >> 2) & 1);
        const glm::vec3 w = glm::mix(1.0f - t.f, t.f, glm::vec3(o));
        f(glm::min(t.base + o, v.dims - 1), w.x * w.y * w.z);
    }
}

template <class T>
float value_at(const VolumeView<T>& v, glm::vec3 q) {
    float sum = 0;
    around(v, q,
           [&](glm::ivec3 p, float w) { sum += w * static_cast<float>(v.at(p.x, p.y, p.z)); });
    return sum;
}

// The fine gradient at `q`, trilinear between the gradients of the eight voxels around it (as a
// vertex's normal mixes those of its edge's two voxels).
template <class T>
glm::vec3 gradient_at(const VolumeView<T>& v, glm::vec3 q) {
    const glm::vec3 inv_step = 0.5f / v.spacing;
    glm::vec3 g(0);
    around(v, q, [&](glm::ivec3 p, float w) { g += w * gradient(v, p, inv_step); });
    return g;
}

// The gradient the client's shading shows at `q` on a unit of `level`: at full resolution the
// fine gradient there; on a meta-cell of 2^level cells a side, whose vertices carry the fine
// gradients at its edges' crossings and whose triangles blend them linearly, about the fine
// gradient averaged over 2^level voxels, which central differences 2^level apart give.
template <class T>
glm::vec3 shown_gradient(const VolumeView<T>& v, glm::vec3 q, int level) {
    if (level == 0) return gradient_at(v, q);
    const float s = float(1 << level);
    glm::vec3 g;
    for (int a = 0; a < 3; ++a) {
        glm::vec3 d(0);
        d[a] = s;
        g[a] = (value_at(v, q + d) - value_at(v, q - d)) / (2 * s * v.spacing[a]);
    }
    return g;
}

// The colour the client shows where `ray` (object space) hits a unit of `level` at parameter t.
template <class T>
glm::vec3 shown_colour(const VolumeView<T>& v, const Ray& ray, float t, int level) {
    const glm::vec3 to_eye = -glm::normalize(ray.d);
    const glm::vec3 g = shown_gradient(v, ray.at(t) / v.spacing, level);
    // The surface faces the low side: its normal is the negated gradient (marching_cubes.h);
    // a flat spot (no gradient) is lit as if it faced the eye.
    const float len = glm::length(g);
    const float cosine = len > 0 && std::isfinite(len) ? glm::dot(-g / len, to_eye) : 1.0f;
    return glm::clamp(headlight::colour(cosine), glm::vec3(0), glm::vec3(1));
}

// Whether C = 1 - sqrt(mean) of these `count` errors lies 3 standard errors from kCoarsePaysFrom.
// The errors' variance is taken at its bound for values in [0, 1], mean (1 - mean): a few rays
// that all agree say nothing of the misses a hundred more may meet. Through dC/dmean =
// -1 / (2 sqrt(mean)), C's standard error is then sqrt((1 - mean) / count) / 2.
bool clear(double sum, std::size_t count) {
    const double mean = std::clamp(sum / double(count), 0.0, 1.0);
    const double se = 0.5 * std::sqrt((1.0 - mean) / double(count));
    return std::abs(1.0 - std::sqrt(mean) - kCoarsePaysFrom) >= 3.0 * se;
}

template <class T>
CoarseForecast forecast(std::span<SurfaceExtractor* const> levels, const FrameView& view,
                        bool decide, std::size_t rays) {
    const VolumeView<T> v = levels[0]->volume().view<T>();
    const glm::mat4 view_inv = glm::inverse(view.camera.view());
    // A grid of about `rays` pixels with the aspect of the volume's box on the screen, over it:
    // where the surface may be.
    const PixelRect box = screen_box(levels[0]->volume().bounds(), view.camera.view(), view.frustum,
                                     view.width, view.height);
    CoarseForecast f;
    if (box.width <= 0 || box.height <= 0) return f;
    const double aspect = double(box.width) / double(box.height);
    const int nx = std::clamp(int(std::lround(std::sqrt(double(rays) * aspect))), 1, box.width);
    const int ny = std::clamp(int(std::lround(double(rays) / nx)), 1, box.height);
    // The grid's cells in the order k * stride mod n, stride a prime that divides no n here:
    // every prefix spreads over the grid.
    const std::size_t n = std::size_t(nx) * std::size_t(ny);
    constexpr std::size_t kStride = 7919;
    const std::size_t stride = n % kStride == 0 ? 1 : kStride % n;
    double sum = 0;  // of e(P)^2 over the significant rays
    for (std::size_t k = 0, cell = 0; k < n; ++k, cell = (cell + stride) % n) {
        const int i = int(cell % std::size_t(nx)), j = int(cell / std::size_t(nx));
        const glm::ivec2 px(box.x + (2 * i + 1) * box.width / (2 * nx),
                            box.y + (2 * j + 1) * box.height / (2 * ny));
        const Ray ray = pixel_ray(view_inv, view.frustum, view.width, view.height, px);
        ++f.rays;
        const RayHit fine = levels[0]->cast(ray, IntersectMode::exact);
        ++f.casts;
        if (!fine.found) continue;
        ++f.significant;
        const glm::vec3 want = shown_colour(v, ray, fine.t, 0);
        double e2 = 1;  // nothing drawn here by the coarse passes
        for (std::size_t l = 1; l < levels.size(); ++l) {
            const RayHit h = levels[l]->cast(ray, IntersectMode::exact);
            ++f.casts;
            // A refinement hit is the full resolution's (the level's own surface missed), and
            // a border cell finer than the level is left to it (adaptive.h: finer_units).
            if (!h.found || h.refine || h.level < int(l)) continue;
            const glm::vec3 d = shown_colour(v, ray, h.t, int(l)) - want;
            e2 = double(glm::dot(d, d)) / 3.0;
            break;
        }
        sum += e2;
        if (decide && f.significant >= kDecideAfter && clear(sum, f.significant)) break;
    }
    if (f.significant > 0) f.c = 1.0 - std::sqrt(sum / double(f.significant));
    return f;
}

}  // namespace

CoarseForecast forecast_coarse_correctness(std::span<SurfaceExtractor* const> levels,
                                           const FrameView& view, bool decide, std::size_t rays) {
    if (levels.size() < 2)
        throw std::invalid_argument("forecast_coarse_correctness: no coarse level");
    if (view.width <= 0 || view.height <= 0 || rays == 0) return {};
    return dispatch_voxel_type(levels[0]->volume().type(), [&](auto tag) {
        return forecast<decltype(tag)>(levels, view, decide, rays);
    });
}

}  // namespace isowall::remote
