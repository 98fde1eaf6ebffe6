#pragma once
// Where each eye looks from. A wall is a window into the scene: its screen plane sits at the
// convergence distance in front of the camera and spans the camera's field of view there. An eye
// (left or right of the camera by half the eye separation, and wherever a tracked head moves it)
// keeps the camera's orientation, and its frustum is the pyramid from the eye through that fixed
// rectangle: the off-axis frustum of head-tracked and stereo displays. What lies on the screen
// plane projects to the same pixel for every eye (zero parallax); what lies behind it appears
// further right to the right eye, what lies in front further left. Pure functions.
#include <string>

#include <glm/vec3.hpp>

#include "core/box.h"
#include "core/camera.h"
#include "wall_spec/wall.h"

namespace isowall {

struct EyeView {
    Camera camera;  // fitted to the bounds' depth range
    Frustum wall;   // the whole virtual screen's frustum for this eye
};

// `head`: the viewer's offset from the nominal viewing position (x right, y up, z towards the
// viewer), in mm on a wall with [physical], else in widths of the virtual screen. For the centre
// eye at the nominal head this is exactly fit_depth_range(camera) and its symmetric frustum.
// `camera` must be a perspective one (head_problem).
EyeView eye_view(const Camera& camera, float aspect, const WallSpec& spec, Eye eye,
                 const glm::dvec3& head, const Box3& bounds);

// The eye's position relative to the camera's, in the camera's view space (x right, y up, z back
// towards the viewer), object units.
glm::dvec3 eye_offset(const Camera& camera, float aspect, const WallSpec& spec, Eye eye,
                      const glm::dvec3& head);

// The screen plane's width in object units, and its distance in front of the camera.
double screen_plane_width(const Camera& camera, float aspect, const WallSpec& spec);
double screen_plane_distance(const Camera& camera, const WallSpec& spec);

// Why the eyes cannot be placed for `head`, or empty: stereo and head tracking need a
// perspective camera, and every eye must stay in front of the screen plane.
std::string head_problem(const Camera& camera, float aspect, const WallSpec& spec,
                         const glm::dvec3& head);

}  // namespace isowall
