#include "core/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtx/rotate_vector.hpp>

namespace isowall {

std::optional<glm::ivec2> clip_to_pixel(const glm::vec4& clip, int width, int height) {
    if (!(clip.w > 1e-6f)) return std::nullopt;
    const glm::vec2 w = ndc_to_window(clip.x / clip.w, clip.y / clip.w, width, height);
    if (!(w.x >= 0 && w.y >= 0 && w.x < float(width) && w.y < float(height))) return std::nullopt;
    return glm::ivec2(int(w.x), int(w.y));
}

glm::mat4 Frustum::matrix() const {
    if (projection == Projection::perspective)
        return glm::frustum(left, right, bottom, top, near_z, far_z);
    return glm::ortho(left, right, bottom, top, near_z, far_z);
}

Frustum sub_frustum(const Frustum& full, int screen_w, int screen_h, const PixelRect& rect) {
    Frustum f = full;
    const float sx = full.width() / static_cast<float>(screen_w);
    const float sy = full.height() / static_cast<float>(screen_h);
    f.left = full.left + sx * static_cast<float>(rect.x);
    f.right = full.left + sx * static_cast<float>(rect.x + rect.width);
    // Pixel rows count down from the top edge.
    f.top = full.top - sy * static_cast<float>(rect.y);
    f.bottom = full.top - sy * static_cast<float>(rect.y + rect.height);
    return f;
}

glm::mat4 Camera::view() const {
    return glm::lookAt(eye, target, valid_up(target - eye, up));
}

glm::vec3 valid_up(const glm::vec3& forward, const glm::vec3& up) {
    const float f = glm::length(forward), u = glm::length(up);
    // sin(0.06 degrees) ~ 1e-3: closer to parallel, the right vector is mostly rounding error.
    if (f > 0 && u > 0 && glm::length(glm::cross(forward / f, up / u)) >= 1e-3f) return up;
    if (!(f > 0) || std::abs(forward.z / f) < 0.9f) return {0, 0, 1};
    return {0, 1, 0};
}

namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string format(double v) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%g", v);
    return buf;
}

constexpr double kMaxReach = 1e9;        // object units from the origin
constexpr double kMinSeparation = 1e-4;  // of the scale (the distance from the origin, >= 1)

}  // namespace

std::string eye_target_problem(const glm::vec3& eye, const glm::vec3& target) {
    if (!finite(eye) || !finite(target)) return "the eye or the target is not a finite point";
    const double scale = std::max({1.0, double(glm::length(eye)), double(glm::length(target))});
    const double apart = glm::length(glm::dvec3(eye) - glm::dvec3(target));
    if (apart < kMinSeparation * scale)
        return apart == 0
                   ? "the eye and the target are the same point"
                   : "the eye and the target are " + format(apart) + " apart; expected at least " +
                         format(kMinSeparation * scale) + " at this distance from the origin";
    return {};
}

std::string camera_problem(const Camera& c) {
    if (!finite(c.up) || !std::isfinite(c.fovy_deg) || !std::isfinite(c.ortho_height))
        return "the view is not finite";
    if (std::string p = eye_target_problem(c.eye, c.target); !p.empty()) return p;
    const double reach = std::max(glm::length(c.eye), glm::length(c.target));
    if (reach > kMaxReach)
        return "the view would be " + format(reach) + " from the origin; expected at most " +
               format(kMaxReach);
    const double scale = std::max(1.0, double(glm::length(c.target)));
    if (c.projection == Projection::orthographic &&
        (c.ortho_height < kMinSeparation * scale || c.ortho_height > kMaxReach))
        return "the view would be " + format(c.ortho_height) + " high; expected " +
               format(kMinSeparation * scale) + " to " + format(kMaxReach);
    return {};
}

float Camera::distance() const {
    return glm::length(eye - target);
}

Frustum Camera::frustum(float aspect) const {
    Frustum f;
    f.projection = projection;
    f.near_z = near_z;
    f.far_z = far_z;
    float half_h = projection == Projection::perspective
                       ? near_z * std::tan(glm::radians(fovy_deg) * 0.5f)
                       : ortho_height * 0.5f;
    f.top = half_h;
    f.bottom = -half_h;
    f.right = half_h * aspect;
    f.left = -half_h * aspect;
    return f;
}

Camera fit_depth_range(const Camera& c, const Box3& bounds) {
    Camera out = c;
    const float radius = 0.5f * glm::length(bounds.extent());
    const float d = glm::length(bounds.center() - c.eye);
    // Keep near positive and not too small: depth precision falls with far/near.
    out.near_z = std::max(d - radius * 1.05f, radius * 0.01f);
    out.far_z = d + radius * 1.05f;
    return out;
}

Camera front_full_view(const Box3& bounds, float aspect, Projection projection) {
    Camera c;
    c.projection = projection;
    c.target = bounds.center();
    c.up = glm::vec3(0, 0, 1);
    const glm::vec3 half = 0.5f * bounds.extent();
    // Looking along +y: x is screen-right, z is screen-up, y is depth. Place the eye at the
    // smallest distance where all eight corners project inside the view, with a 4% margin.
    const float tan_y = std::tan(glm::radians(c.fovy_deg) * 0.5f);
    const float tan_x = tan_y * aspect;
    float dist = 0;
    float ortho_half_h = 0;
    for (float sy : {-1.0f, 1.0f}) {
        const float depth_offset = sy * half.y;  // corner depth relative to the target
        dist = std::max({dist, half.x / tan_x - depth_offset, half.z / tan_y - depth_offset});
        ortho_half_h = std::max({ortho_half_h, half.z, half.x / aspect});
    }
    dist = std::max(dist * 1.04f, half.y * 1.1f + 1e-3f);
    c.eye = c.target - glm::vec3(0, dist, 0);
    c.ortho_height = 2.0f * ortho_half_h * 1.04f;
    return fit_depth_range(c, bounds);
}

glm::mat3 frame_rotation(const glm::mat3& m) {
    const glm::vec3 x = m[0];
    const glm::vec3 y = m[1] - glm::dot(m[1], x) / std::max(glm::dot(x, x), 1e-30f) * x;
    if (!(glm::length(x) > 1e-6f) || !(glm::length(y) > 1e-6f)) return glm::mat3(1.0f);
    const glm::vec3 nx = glm::normalize(x), ny = glm::normalize(y);
    return glm::mat3(nx, ny, glm::cross(nx, ny));
}

Camera front_full_view(const Box3& bounds, const glm::mat3& axes, float aspect,
                       Projection projection) {
    const glm::mat3 r = frame_rotation(axes);
    if (r == glm::mat3(1.0f)) return front_full_view(bounds, aspect, projection);
    // The front view of the box the volume fills in patient space, about its centre, then
    // carried back into the volume's own axes (r is a rotation: its inverse is its transpose).
    const glm::vec3 centre = bounds.center();
    Box3 patient;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? bounds.max.x : bounds.min.x,
                               (i & 2) ? bounds.max.y : bounds.min.y,
                               (i & 4) ? bounds.max.z : bounds.min.z);
        patient.merge(r * (corner - centre));
    }
    const Camera p = front_full_view(patient, aspect, projection);
    const glm::mat3 back = glm::transpose(r);
    Camera c = p;
    c.target = centre + back * (p.target - patient.center());
    c.eye = centre + back * (p.eye - patient.center());
    c.up = back * p.up;
    return fit_depth_range(c, bounds);
}

Camera orbit(const Camera& c, double yaw_deg, double pitch_deg) {
    Camera out = c;
    glm::vec3 offset = c.eye - c.target;
    const glm::vec3 up = glm::normalize(valid_up(-offset, c.up));
    const auto radians = [](double deg) {
        return static_cast<float>(glm::radians(std::fmod(deg, 360.0)));
    };
    offset = glm::rotate(offset, radians(yaw_deg), up);
    const glm::vec3 right = glm::normalize(glm::cross(-offset, up));
    offset = glm::rotate(offset, radians(pitch_deg), right);
    out.eye = c.target + offset;
    // Keep up orthogonal to the view direction so that lookAt never degenerates.
    out.up = glm::normalize(glm::cross(right, -offset));
    return out;
}

Camera translate_in_view(const Camera& c, const glm::vec3& offset) {
    const glm::vec3 forward = glm::normalize(c.target - c.eye);
    const glm::vec3 right = glm::normalize(glm::cross(forward, valid_up(forward, c.up)));
    const glm::vec3 up = glm::cross(right, forward);
    const glm::vec3 move = right * offset.x + up * offset.y - forward * offset.z;
    Camera out = c;
    out.eye += move;
    out.target += move;
    return out;
}

Camera pan(const Camera& c, float dx, float dy, float aspect) {
    const float height = c.projection == Projection::perspective
                             ? 2.0f * c.distance() * std::tan(glm::radians(c.fovy_deg) * 0.5f)
                             : c.ortho_height;
    return translate_in_view(c, {dx * height * aspect, dy * height, 0.0f});
}

Camera zoom(const Camera& c, float factor) {
    Camera out = c;
    if (c.projection == Projection::perspective) {
        out.eye = c.target + (c.eye - c.target) / factor;
    } else {
        out.ortho_height = c.ortho_height / factor;
    }
    return out;
}

std::ostream& operator<<(std::ostream& os, const Frustum& f) {
    return os << "Frustum{l=" << f.left << " r=" << f.right << " b=" << f.bottom << " t=" << f.top
              << " n=" << f.near_z << " f=" << f.far_z
              << (f.projection == Projection::perspective ? " persp}" : " ortho}");
}

std::ostream& operator<<(std::ostream& os, const Camera& c) {
    return os << "Camera{eye=" << c.eye << " target=" << c.target << " up=" << c.up
              << " fovy=" << c.fovy_deg << "}";
}

}  // namespace isowall
