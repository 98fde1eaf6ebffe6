// The eyes' off-axis frusta (wall_spec/eyes.h).
#include "wall_spec/eyes.h"

#include <cmath>

#include <glm/trigonometric.hpp>

namespace isowall {
namespace {

// Object units per unit of `head` and of the eye separation: mm on a wall with [physical] (its
// virtual screen's width in mm spans the screen plane), else widths of the virtual screen.
double object_units_per_wall_unit(const Camera& camera, float aspect, const WallSpec& spec) {
    const double plane = screen_plane_width(camera, aspect, spec);
    if (!spec.physical) return plane;
    const double mm =
        virtual_screen_size(spec).width * spec.physical->tile_width_mm / spec.tile_width_px;
    return plane / mm;
}

}  // namespace

double screen_plane_distance(const Camera& camera, const WallSpec& spec) {
    return double(camera.distance()) * (spec.stereo ? spec.stereo->convergence : 1.0);
}

double screen_plane_width(const Camera& camera, float aspect, const WallSpec& spec) {
    return 2.0 * screen_plane_distance(camera, spec) *
           std::tan(glm::radians(double(camera.fovy_deg)) * 0.5) * aspect;
}

glm::dvec3 eye_offset(const Camera& camera, float aspect, const WallSpec& spec, Eye eye,
                      const glm::dvec3& head) {
    glm::dvec3 offset = head;
    if (spec.stereo && eye != Eye::centre)
        offset.x += (eye == Eye::left ? -0.5 : 0.5) * spec.stereo->separation;
    return offset * object_units_per_wall_unit(camera, aspect, spec);
}

std::string head_problem(const Camera& camera, float aspect, const WallSpec& spec,
                         const glm::dvec3& head) {
    const bool moved = spec.stereo || head != glm::dvec3(0);
    if (!moved) return {};
    if (camera.projection != Projection::perspective)
        return spec.stereo ? "stereo needs a perspective view"
                           : "a head position needs a perspective view";
    const double d = screen_plane_distance(camera, spec);
    for (Eye eye : {Eye::left, Eye::right})
        if (!(d + eye_offset(camera, aspect, spec, eye, head).z > 1e-3 * d))
            return "the head must stay in front of the screen plane (z above " +
                   std::to_string(-d / object_units_per_wall_unit(camera, aspect, spec)) + ")";
    return {};
}

EyeView eye_view(const Camera& camera, float aspect, const WallSpec& spec, Eye eye,
                 const glm::dvec3& head, const Box3& bounds) {
    const glm::dvec3 e = eye_offset(camera, aspect, spec, eye, head);
    if (e == glm::dvec3(0)) {
        const Camera c = fit_depth_range(camera, bounds);
        return {c, c.frustum(aspect)};
    }
    const Camera moved = fit_depth_range(translate_in_view(camera, glm::vec3(e)), bounds);
    // The screen's rectangle in the eye's view space, scaled to its near plane.
    const double d = screen_plane_distance(camera, spec);
    const double half_w = 0.5 * screen_plane_width(camera, aspect, spec);
    const double half_h = half_w / aspect;
    const double scale = moved.near_z / (d + e.z);
    Frustum f;
    f.projection = Projection::perspective;
    f.near_z = moved.near_z;
    f.far_z = moved.far_z;
    f.left = float((-half_w - e.x) * scale);
    f.right = float((half_w - e.x) * scale);
    f.bottom = float((-half_h - e.y) * scale);
    f.top = float((half_h - e.y) * scale);
    return {moved, f};
}

}  // namespace isowall
