#include "wire/message_fields.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "core/image.h"

namespace isowall::message_fields {
namespace {

glm::vec3 get_finite_vec3(MessageReader& r, const char* field) {
    const glm::vec3 v = r.get_vec3();
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        r.fail(std::string(field) + ": expected finite numbers, got (" + std::to_string(v.x) +
               ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")");
    return v;
}

// Written as an int32 whatever the compiler picks for the enum, so the wire does not change
// with the header; read back by hand (not get_enum) so the error names the field.
void put_projection(MessageWriter& w, Projection p) {
    w.put(static_cast<std::int32_t>(p));
}

Projection get_projection(MessageReader& r, const char* field) {
    const auto v = r.get<std::int32_t>();
    constexpr auto kLast = static_cast<std::int32_t>(Projection::orthographic);
    if (v < 0 || v > kLast)
        r.fail(std::string(field) + ": expected 0 (perspective) or 1 (orthographic), got " +
               std::to_string(v));
    return static_cast<Projection>(v);
}

void put_camera(MessageWriter& w, const Camera& c) {
    w.put(c.eye);
    w.put(c.target);
    w.put(c.up);
    put_projection(w, c.projection);
    w.put(c.fovy_deg);
    w.put(c.ortho_height);
    w.put(c.near_z);
    w.put(c.far_z);
}

Camera get_camera(MessageReader& r) {
    Camera c;
    c.eye = get_finite_vec3(r, "camera.eye");
    c.target = get_finite_vec3(r, "camera.target");
    c.up = get_finite_vec3(r, "camera.up");
    c.projection = get_projection(r, "camera.projection");
    c.fovy_deg = get_finite<float>(r, "camera.fovy_deg");
    c.ortho_height = get_finite<float>(r, "camera.ortho_height");
    c.near_z = get_finite<float>(r, "camera.near_z");
    c.far_z = get_finite<float>(r, "camera.far_z");
    return c;
}

void put_frustum(MessageWriter& w, const Frustum& f) {
    w.put(f.left);
    w.put(f.right);
    w.put(f.bottom);
    w.put(f.top);
    w.put(f.near_z);
    w.put(f.far_z);
    put_projection(w, f.projection);
}

Frustum get_frustum(MessageReader& r) {
    Frustum f;
    f.left = get_finite<float>(r, "frustum.left");
    f.right = get_finite<float>(r, "frustum.right");
    f.bottom = get_finite<float>(r, "frustum.bottom");
    f.top = get_finite<float>(r, "frustum.top");
    f.near_z = get_finite<float>(r, "frustum.near_z");
    f.far_z = get_finite<float>(r, "frustum.far_z");
    f.projection = get_projection(r, "frustum.projection");
    return f;
}

}  // namespace

std::int32_t get_side(MessageReader& r, const char* field, std::int32_t min_px) {
    return get_side(r, field, min_px, kMaxImageSide);
}

std::int32_t get_side(MessageReader& r, const char* field, std::int32_t min_px,
                      std::int32_t max_px) {
    const auto v = r.get<std::int32_t>();
    if (v < min_px || v > max_px)
        r.fail(std::string(field) + ": expected " + std::to_string(min_px) + ".." +
               std::to_string(max_px) + ", got " + std::to_string(v));
    return v;
}

void put_frame_view(MessageWriter& w, const FrameView& v) {
    put_camera(w, v.camera);
    put_frustum(w, v.frustum);
    w.put(static_cast<std::int32_t>(v.width));
    w.put(static_cast<std::int32_t>(v.height));
    w.put(v.iso);
}

FrameView get_frame_view(MessageReader& r) {
    FrameView v;
    v.camera = get_camera(r);
    v.frustum = get_frustum(r);
    // A frame of no pixels has nothing to draw; a tile would divide by its size.
    v.width = get_side(r, "view.width", 1);
    v.height = get_side(r, "view.height", 1);
    v.iso = get_finite<double>(r, "view.iso");
    return v;
}

// At most kMaxClipPlanes, each with a unit normal (the planes a parser makes) and a finite offset.
void put_clip(MessageWriter& w, const ClipSet& c) {
    w.put(static_cast<std::uint8_t>(c.count));
    for (const ClipPlane& p : c) {
        w.put(p.normal);
        w.put(p.at);
    }
}

ClipSet get_clip(MessageReader& r) {
    const auto n = r.get<std::uint8_t>();
    if (n > kMaxClipPlanes)
        r.fail("view.clip: expected at most " + std::to_string(kMaxClipPlanes) + " planes, got " +
               std::to_string(n));
    ClipSet c;
    for (std::uint8_t i = 0; i < n; ++i) {
        ClipPlane p;
        p.normal = get_finite_vec3(r, "view.clip.normal");
        const float len = glm::length(p.normal);
        if (std::abs(len - 1.0f) > 1e-3f)
            r.fail("view.clip.normal: expected a unit vector, got length " + std::to_string(len));
        p.at = get_finite<float>(r, "view.clip.at");
        c.add(p);
    }
    return c;
}

void put_surfaces(MessageWriter& w, const std::vector<SurfaceStyle>& s) {
    w.put(static_cast<std::uint8_t>(s.size()));
    for (const SurfaceStyle& one : s) {
        w.put(one.iso);
        for (int c = 0; c < 3; ++c) w.put(one.colour[c]);
        w.put(one.opacity);
        w.put(static_cast<std::uint8_t>(one.coloured ? 1 : 0));  // get_bool's byte
    }
}

std::vector<SurfaceStyle> get_surfaces(MessageReader& r) {
    const auto n = r.get<std::uint8_t>();
    if (n > kMaxSurfaces)
        r.fail("view.surfaces: expected at most " + std::to_string(kMaxSurfaces) +
               " surfaces, got " + std::to_string(n));
    std::vector<SurfaceStyle> out(n);
    for (SurfaceStyle& one : out) {
        one.iso = get_finite<double>(r, "view.surfaces.iso");
        for (int c = 0; c < 3; ++c) one.colour[c] = r.get<std::uint8_t>();
        one.opacity = get_finite<float>(r, "view.surfaces.opacity");
        if (one.opacity < 0 || one.opacity > 1)
            r.fail("view.surfaces.opacity: expected a number in [0, 1], got " +
                   std::to_string(one.opacity));
        one.coloured = r.get_bool();
    }
    return out;
}

void put_pixel_rect(MessageWriter& w, const PixelRect& p) {
    w.put(static_cast<std::int32_t>(p.x));
    w.put(static_cast<std::int32_t>(p.y));
    w.put(static_cast<std::int32_t>(p.width));
    w.put(static_cast<std::int32_t>(p.height));
}

PixelRect get_pixel_rect(MessageReader& r) {
    PixelRect p;
    p.x = r.get<std::int32_t>();
    p.y = r.get<std::int32_t>();
    p.width = r.get<std::int32_t>();
    p.height = r.get<std::int32_t>();
    return p;
}

bool inside(const PixelRect& p, int width, int height) {
    if (p.x < 0 || p.y < 0 || p.width < 0 || p.height < 0) return false;
    return std::int64_t{p.x} + p.width <= width && std::int64_t{p.y} + p.height <= height;
}

// Appended piece by piece: `"(" + std::string&&` trips GCC 12's false -Wrestrict (PR 105329).
std::string to_text(const PixelRect& p) {
    std::string s = "(";
    s += std::to_string(p.x) + ", " + std::to_string(p.y) + ") ";
    s += std::to_string(p.width) + "x" + std::to_string(p.height);
    return s;
}

void put_pixels(MessageWriter& w, const std::vector<std::uint8_t>& rgba,
                const std::vector<float>& depth) {
    // A length and the bytes: the layout of put_array of u8, written in one copy, not per byte.
    w.put_bytes(std::as_bytes(std::span(rgba)));
    w.put_array(std::span<const float>(depth));
}

void get_pixels(MessageReader& r, std::uint64_t pixels, bool depth_optional,
                std::vector<std::uint8_t>& rgba, std::vector<float>& depth) {
    const auto bytes = r.get_bytes();  // its length is checked against the message first
    if (bytes.size() != pixels * 4)
        r.fail("rgba: expected " + std::to_string(pixels * 4) + " bytes, got " +
               std::to_string(bytes.size()));
    const auto* first = reinterpret_cast<const std::uint8_t*>(bytes.data());
    rgba.assign(first, first + bytes.size());
    depth = r.get_array<float>();
    if (depth.size() != pixels && !(depth_optional && depth.empty()))
        r.fail("depth: expected " + std::string(depth_optional ? "0 or " : "") +
               std::to_string(pixels) + " values, got " + std::to_string(depth.size()));
}

}  // namespace isowall::message_fields
