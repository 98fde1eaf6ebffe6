#pragma once
// Camera and frustum value types. A Frustum is the general off-axis form (the extents of the
// near plane in view space), so a wall tile is just a sub-rectangle of the wall's frustum.
#include <optional>
#include <ostream>
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/box.h"

namespace isowall {

enum class Projection { perspective, orthographic };

struct Frustum {
    // View-space extents at the near plane (perspective) or of the view box (orthographic).
    float left = -1, right = 1, bottom = -1, top = 1;
    float near_z = 0.1f, far_z = 100.0f;  // positive distances along -z of view space
    Projection projection = Projection::perspective;

    glm::mat4 matrix() const;  // OpenGL clip-space projection matrix
    float width() const { return right - left; }
    float height() const { return top - bottom; }
};

// A pixel rectangle with (x, y) at the top-left, as images are stored.
struct PixelRect {
    int x = 0, y = 0, width = 0, height = 0;
};

// The window position, in pixels with (0, 0) at the top-left corner of the screen's top-left
// pixel, of a point at normalised device coordinates (x, y) on a width x height screen: the one
// projection to a pixel (ray.cpp's screen_box, the coverage rasteriser, the remote server's seeds).
inline glm::vec2 ndc_to_window(float x, float y, int width, int height) {
    return {(x + 1.0f) * 0.5f * static_cast<float>(width),
            (1.0f - y) * 0.5f * static_cast<float>(height)};
}

// The pixel whose centre's ray passes nearest the point at `clip` (clip space) on a width x
// height screen; nullopt behind the eye (w at most 1e-6) or off the screen. A point's pixel
// everywhere a point is turned into one (the engine's beside and frontier seeds, the remote
// server's seed rays).
std::optional<glm::ivec2> clip_to_pixel(const glm::vec4& clip, int width, int height);

// The frustum of `rect` when the whole of `full` maps onto a screen of screen_w x screen_h pixels.
Frustum sub_frustum(const Frustum& full, int screen_w, int screen_h, const PixelRect& rect);

struct Camera {
    glm::vec3 eye{0, 0, 10};
    glm::vec3 target{0, 0, 0};
    glm::vec3 up{0, 1, 0};
    Projection projection = Projection::perspective;
    float fovy_deg = 30.0f;     // vertical field of view (perspective)
    float ortho_height = 2.0f;  // full view height in object units (orthographic)
    float near_z = 0.1f;
    float far_z = 100.0f;

    glm::mat4 view() const;  // object -> view space (look-at)
    // The symmetric frustum for a screen of the given aspect (width / height).
    Frustum frustum(float aspect) const;
    float distance() const;
};

// Front full view: looking along +y of the volume (front of a head scan) with +z up, at the
// nearest distance where every corner of `bounds` is in view (4% margin).
Camera front_full_view(const Box3& bounds, float aspect,
                       Projection projection = Projection::perspective);

// A rotation made from the columns of `m` by Gram-Schmidt (x kept, y made perpendicular, z their
// cross product), so a sheared or scaled frame still gives one; the identity when a column is
// zero or x and y are parallel.
glm::mat3 frame_rotation(const glm::mat3& m);

// The front full view of a volume whose x, y and z run along the columns of `axes` in patient
// space (volume/volume.h: Orientation, LPS): the eye in front of the patient (-y), the
// head (+z) up, the patient's left (+x) on the screen's right, as front_full_view shows a volume
// stored in that order. `axes` is made orthonormal first; with the identity this is
// front_full_view itself.
Camera front_full_view(const Box3& bounds, const glm::mat3& axes, float aspect,
                       Projection projection = Projection::perspective);

// Rotate the eye around the target: yaw about the up vector, pitch about the right vector. The
// angles are reduced modulo 360 in double precision first, so 720.5 turns exactly as 0.5 does.
Camera orbit(const Camera& c, double yaw_deg, double pitch_deg);
// Moves eye and target together in the view plane by dx screen widths (positive: the view moves
// right, so the scene moves left) and dy screen heights (positive: the view moves up), measured
// at the target's distance on a screen of the given aspect (width / height).
Camera pan(const Camera& c, float dx, float dy, float aspect);
// Moves eye and target together by `offset` in the camera's view space (x right, y up, z back
// towards the viewer), object units: a pan, a dolly, or a stereo eye beside the camera.
Camera translate_in_view(const Camera& c, const glm::vec3& offset);
// factor > 1 moves closer (perspective) or narrows the view (orthographic).
Camera zoom(const Camera& c, float factor);

// The up vector a view uses: `up` when it is at least about 0.06 degrees off the view direction
// `forward`; otherwise (a look-at straight along `up`, or an up of zero length) the object's +z,
// or +y when the view itself runs along z. Never parallel to a non-zero `forward`.
glm::vec3 valid_up(const glm::vec3& forward, const glm::vec3& up);

// Why the eye and target cannot make a view, or empty: they must be finite and apart by at
// least 1e-4 of their distance from the origin (at least 1e-4), or float precision leaves the view
// direction undefined (eye == target is the extreme case).
std::string eye_target_problem(const glm::vec3& eye, const glm::vec3& target);
// Why `c` cannot be drawn, or empty: eye_target_problem, and everything within 1e9 object units
// of the origin, an orthographic height within [1e-4 * scale, 1e9], where scale is the target's
// distance from the origin (at least 1): what a run of zooms and pans must keep.
std::string camera_problem(const Camera& c);

// Set near/far so that `bounds` lies between them, with a small margin.
Camera fit_depth_range(const Camera& c, const Box3& bounds);

std::ostream& operator<<(std::ostream& os, const Frustum& f);
std::ostream& operator<<(std::ostream& os, const Camera& c);

}  // namespace isowall
