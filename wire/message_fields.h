#pragma once
// Pieces of the wire format shared by several messages (wall_protocol/protocol.cpp and
// wall_protocol/protocol_jobs.cpp): cameras, frustums, frame views and pixel rectangles, each
// written and read with its value checks, so that every message carrying one checks it the same
// way.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/surface_style.h"
#include "core/view.h"
#include "wire/wire.h"

namespace isowall::message_fields {

// A NaN or an infinity in a camera, frustum or isovalue gives a blank or garbage tile with no
// error anywhere, so the wire refuses them and names the field.
template <class F>
F get_finite(MessageReader& r, const char* field) {
    const F v = r.get<F>();
    if (!std::isfinite(v))
        r.fail(std::string(field) + ": expected a finite number, got " + std::to_string(v));
    return v;
}

// A view's camera, frustum, size and isovalue; its clip planes, which the remote protocol does not
// carry, go with put_clip.
void put_frame_view(MessageWriter& w, const FrameView& v);
FrameView get_frame_view(MessageReader& r);
void put_clip(MessageWriter& w, const ClipSet& c);
ClipSet get_clip(MessageReader& r);
// The surfaces of a picture (core/surface_style.h): at most kMaxSurfaces, each a finite isovalue,
// its colour and an opacity in [0, 1]; the field named on failure (`view.surfaces.opacity`).
void put_surfaces(MessageWriter& w, const std::vector<SurfaceStyle>& s);
std::vector<SurfaceStyle> get_surfaces(MessageReader& r);
// A side read from the wire, checked against [min_px, max_px] (by default kMaxImageSide) before
// anything is sized from it.
std::int32_t get_side(MessageReader& r, const char* field, std::int32_t min_px);
std::int32_t get_side(MessageReader& r, const char* field, std::int32_t min_px,
                      std::int32_t max_px);
void put_pixel_rect(MessageWriter& w, const PixelRect& p);
PixelRect get_pixel_rect(MessageReader& r);
// p lies inside a width x height screen (computed in 64 bits).
bool inside(const PixelRect& p, int width, int height);
std::string to_text(const PixelRect& p);
// rgba (4 bytes per pixel) and depth (one float per pixel) of exactly `pixels` pixels: the
// lengths are checked against the message before anything is allocated.
void put_pixels(MessageWriter& w, const std::vector<std::uint8_t>& rgba,
                const std::vector<float>& depth);
void get_pixels(MessageReader& r, std::uint64_t pixels, bool depth_optional,
                std::vector<std::uint8_t>& rgba, std::vector<float>& depth);

}  // namespace isowall::message_fields
