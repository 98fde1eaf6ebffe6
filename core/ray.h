#pragma once
// Rays for seed finding. Rays are cast in voxel space (object space divided by spacing), where
// every cell is a unit cube with integer corners (chapter 2.1.1): box tests are then with
// axis-aligned unit boxes, and the ray parameter t is the same as in object space.
#include <cmath>
#include <limits>
#include <ostream>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/camera.h"

namespace isowall {

struct Ray {
    glm::vec3 o{0};         // origin
    glm::vec3 d{0, 0, -1};  // direction (not necessarily unit length)
    glm::vec3 at(float t) const { return o + t * d; }
};

// The ray through the centre of pixel (x, y) (top-left origin) of a width x height screen seen
// through `frustum` and `view` (object -> view space), in object space.
Ray pixel_ray(const glm::mat4& view_inverse, const Frustum& frustum, int width, int height,
              glm::ivec2 pixel);

// Object space -> voxel space.
inline Ray to_voxel_space(const Ray& r, glm::vec3 spacing) {
    return {r.o / spacing, r.d / spacing};
}

// 1 / r.d per axis, for slab tests and cell walks; a huge value of the same sign where r.d is 0.
inline glm::vec3 inverse_direction(const Ray& r) {
    glm::vec3 inv;
    for (int a = 0; a < 3; ++a)
        inv[a] = std::abs(r.d[a]) > 1e-20f ? 1.0f / r.d[a] : std::copysign(1e30f, r.d[a]);
    return inv;
}

// 3D DDA over unit cells (Amanatides and Woo): the cells a ray passes, in its order, from the cell
// it is in at the start; `inv_d` is inverse_direction(r). Shared by the ray caster's walk through a
// leaf brick and a footprint unit's pixel rays.
struct CellWalk {
    glm::ivec3 cell, step;
    glm::vec3 t_next, t_delta;

    CellWalk(const Ray& r, const glm::vec3& inv_d, glm::ivec3 start) : cell(start) {
        for (int a = 0; a < 3; ++a) {
            if (r.d[a] > 0) {
                step[a] = 1;
                t_next[a] = (static_cast<float>(cell[a] + 1) - r.o[a]) * inv_d[a];
                t_delta[a] = inv_d[a];
            } else if (r.d[a] < 0) {
                step[a] = -1;
                t_next[a] = (static_cast<float>(cell[a]) - r.o[a]) * inv_d[a];
                t_delta[a] = -inv_d[a];
            } else {
                step[a] = 0;
                t_next[a] = std::numeric_limits<float>::max();
                t_delta[a] = std::numeric_limits<float>::max();
            }
        }
    }
    // Steps into the next cell; false when the ray leaves the cells [lo, hi) or passes t1 first.
    bool next(glm::ivec3 lo, glm::ivec3 hi, float t1) {
        const int a =
            t_next.x < t_next.y ? (t_next.x < t_next.z ? 0 : 2) : (t_next.y < t_next.z ? 1 : 2);
        if (t_next[a] > t1) return false;
        cell[a] += step[a];
        if (cell[a] < lo[a] || cell[a] >= hi[a]) return false;
        t_next[a] += t_delta[a];
        return true;
    }
};

// Slab test against [lo, hi]: the entry and exit parameters, or false when the ray misses.
bool intersect_box(const Ray& r, const glm::vec3& inv_d, glm::vec3 lo, glm::vec3 hi, float& t0,
                   float& t1);

// Moller-Trumbore: the ray parameter of the hit, or false (two-sided, t >= t_min).
bool intersect_triangle(const Ray& r, glm::vec3 a, glm::vec3 b, glm::vec3 c, float t_min, float& t);

// The pixel rectangle covered by the projection of box `b` (object space), clipped to the screen;
// empty (width 0) when the box is entirely outside. Corners behind the eye make the whole
// screen count (conservative).
PixelRect screen_box(const Box3& b, const glm::mat4& view, const Frustum& frustum, int width,
                     int height);

inline std::ostream& operator<<(std::ostream& os, const Ray& r) {
    return os << "Ray{o=(" << r.o.x << "," << r.o.y << "," << r.o.z << ") d=(" << r.d.x << ","
              << r.d.y << "," << r.d.z << ")}";
}

}  // namespace isowall
