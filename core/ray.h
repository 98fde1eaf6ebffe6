#pragma once
// Rays for seed finding. Rays are cast in voxel space (object space divided by spacing), where
// every cell is a unit cube with integer corners (chapter 2.1.1): box tests are then with
// axis-aligned unit boxes, and the ray parameter t is the same as in object space.
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
