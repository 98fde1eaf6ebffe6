// The screen-region scheduler's messages (tags 16..19), and release, start and alive (8..10), each
// encoder right above its decoder, with the same value checks as the frame messages in
// protocol.cpp.
#include "wall_protocol/protocol_jobs.h"

#include <string>

#include "wire/message_fields.h"

namespace isowall {

using namespace message_fields;

std::vector<std::byte> encode(const ReleaseMsg&) {
    return MessageWriter(ReleaseMsg::kVersion).take();
}

ReleaseMsg job_wire::decode_release(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ReleaseMsg::kVersion, "release message");
    r.finish();
    return {};
}

Image region_image(RegionMsg&& m, int width, int height) {
    if (m.rect.x < 0 || m.rect.y < 0 || m.rect.x + m.rect.width > width ||
        m.rect.y + m.rect.height > height)
        throw WireError("region message: rect: outside this tile's " + std::to_string(width) + "x" +
                        std::to_string(height) + " screen");
    Image img;
    img.width = m.rect.width;
    img.height = m.rect.height;
    img.rgba = std::move(m.rgba);
    img.depth = std::move(m.depth);
    return img;
}

std::vector<std::byte> encode(const LostMsg& m) {
    MessageWriter w(LostMsg::kVersion);
    w.put(m.rank);
    return w.take();
}

LostMsg job_wire::decode_lost(std::span<const std::byte> bytes) {
    MessageReader r(bytes, LostMsg::kVersion, "lost message");
    LostMsg m;
    m.rank = r.get<std::int32_t>();
    if (m.rank < 1) r.fail("rank: expected a tile rank (>= 1), got " + std::to_string(m.rank));
    r.finish();
    return m;
}

std::vector<std::byte> encode(const StartMsg&) {
    return MessageWriter(StartMsg::kVersion).take();
}

StartMsg job_wire::decode_start(std::span<const std::byte> bytes) {
    MessageReader r(bytes, StartMsg::kVersion, "start message");
    r.finish();
    return {};
}

std::vector<std::byte> encode(const AliveMsg&) {
    return MessageWriter(AliveMsg::kVersion).take();
}

AliveMsg job_wire::decode_alive(std::span<const std::byte> bytes) {
    MessageReader r(bytes, AliveMsg::kVersion, "alive message");
    r.finish();
    return {};
}

std::vector<std::byte> encode(const JobMsg& m) {
    MessageWriter w(JobMsg::kVersion);
    w.put(m.generation);
    w.put(m.job);
    w.put(m.owner);
    w.put(m.deliver);
    w.put(static_cast<std::uint8_t>(m.band));
    put_frame_view(w, m.view);
    put_clip(w, m.view.clip);
    put_pixel_rect(w, m.rect);
    return w.take();
}

namespace {

// A rank that paints a region indexes its image with it: it must be a non-empty rectangle of the
// screen, or it would write out of bounds.
PixelRect get_region_rect(MessageReader& r, int width, int height) {
    const PixelRect rect = get_pixel_rect(r);
    if (rect.width <= 0 || rect.height <= 0 || !inside(rect, width, height))
        r.fail("rect: expected a non-empty rectangle inside the " + std::to_string(width) + "x" +
               std::to_string(height) + " screen, got " + to_text(rect));
    return rect;
}

double get_seconds(MessageReader& r, const char* field) {
    const double v = get_finite<double>(r, field);
    if (v < 0) r.fail(std::string(field) + ": expected seconds >= 0, got " + std::to_string(v));
    return v;
}

}  // namespace

JobMsg job_wire::decode_job(std::span<const std::byte> bytes) {
    MessageReader r(bytes, JobMsg::kVersion, "job message");
    JobMsg m;
    m.generation = r.get<std::uint64_t>();
    m.job = r.get<std::uint32_t>();
    m.owner = r.get<std::int32_t>();
    if (m.owner < 1) r.fail("owner: expected a tile rank (>= 1), got " + std::to_string(m.owner));
    m.deliver = r.get<std::int32_t>();
    if (m.deliver != 0 && m.deliver != m.owner)
        r.fail("deliver: expected the owner (" + std::to_string(m.owner) +
               ") or the master (0), got " + std::to_string(m.deliver));
    const auto band = r.get<std::uint8_t>();
    if (band > static_cast<std::uint8_t>(Band::fine))
        r.fail("band: expected 0 (coarse) or 1 (fine), got " + std::to_string(band));
    m.band = static_cast<Band>(band);
    m.view = get_frame_view(r);
    m.view.clip = get_clip(r);
    m.rect = get_region_rect(r, m.view.width, m.view.height);
    r.finish();
    return m;
}

std::vector<std::byte> encode(const JobDoneMsg& m) {
    MessageWriter w(JobDoneMsg::kVersion);
    w.put(m.generation);
    w.put(m.job);
    w.put(m.rays);
    w.put(m.groups);
    w.put(m.triangles);
    w.put(m.cpu_s);
    w.put(m.cpu_end_s);
    w.put(m.start_s);
    w.put(m.end_s);
    w.put(m.bytes);
    return w.take();
}

JobDoneMsg job_wire::decode_job_done(std::span<const std::byte> bytes) {
    MessageReader r(bytes, JobDoneMsg::kVersion, "job_done message");
    JobDoneMsg m;
    m.generation = r.get<std::uint64_t>();
    m.job = r.get<std::uint32_t>();
    m.rays = r.get<std::uint64_t>();
    m.groups = r.get<std::uint64_t>();
    m.triangles = r.get<std::uint64_t>();
    m.cpu_s = get_seconds(r, "cpu_s");
    m.cpu_end_s = get_seconds(r, "cpu_end_s");
    m.start_s = get_finite<double>(r, "start_s");
    m.end_s = get_finite<double>(r, "end_s");
    m.bytes = r.get<std::uint64_t>();
    r.finish();
    return m;
}

std::vector<std::byte> encode(const RegionMsg& m) {
    MessageWriter w(RegionMsg::kVersion);
    w.reserve(64 + m.rgba.size() + 4 * m.depth.size());  // one allocation for the pixels
    w.put(m.generation);
    w.put(m.job);
    w.put(m.layer);
    put_pixel_rect(w, m.rect);
    w.put(m.cpu_end_s);
    put_pixels(w, m.rgba, m.depth);
    return w.take();
}

RegionMsg job_wire::decode_region(std::span<const std::byte> bytes) {
    MessageReader r(bytes, RegionMsg::kVersion, "region message");
    RegionMsg m;
    m.generation = r.get<std::uint64_t>();
    m.job = r.get<std::uint32_t>();
    m.layer = r.get<std::uint8_t>();
    if (m.layer >= kMaxSurfaces)
        r.fail("layer: expected below " + std::to_string(kMaxSurfaces) + ", got " +
               std::to_string(m.layer));
    // The owner checks the rect against its own screen; here it must be a possible image.
    m.rect = get_region_rect(r, kMaxImageSide, kMaxImageSide);
    m.cpu_end_s = get_seconds(r, "cpu_end_s");
    const std::uint64_t pixels =
        static_cast<std::uint64_t>(m.rect.width) * static_cast<std::uint64_t>(m.rect.height);
    get_pixels(r, pixels, /*depth_optional=*/false, m.rgba, m.depth);
    r.finish();
    return m;
}

std::vector<std::byte> encode(const LandedMsg& m) {
    MessageWriter w(LandedMsg::kVersion);
    w.put(m.generation);
    w.put(m.job);
    return w.take();
}

LandedMsg job_wire::decode_landed(std::span<const std::byte> bytes) {
    MessageReader r(bytes, LandedMsg::kVersion, "landed message");
    LandedMsg m;
    m.generation = r.get<std::uint64_t>();
    m.job = r.get<std::uint32_t>();
    r.finish();
    return m;
}

std::vector<std::byte> encode(const CurveAskMsg& m) {
    MessageWriter w(CurveAskMsg::kVersion);
    w.put(m.generation);
    return w.take();
}

CurveAskMsg job_wire::decode_curve_ask(std::span<const std::byte> bytes) {
    MessageReader r(bytes, CurveAskMsg::kVersion, "curve_ask message");
    CurveAskMsg m;
    m.generation = r.get<std::uint64_t>();
    r.finish();
    return m;
}

std::vector<std::byte> encode(const CurveMsg& m) {
    MessageWriter w(CurveMsg::kVersion);
    w.put(m.curve.generation);
    w.put(m.curve.significant);
    job_wire::put_curve(w, m.curve.points);
    return w.take();
}

CurveMsg job_wire::decode_curve(std::span<const std::byte> bytes) {
    MessageReader r(bytes, CurveMsg::kVersion, "curve message");
    CurveMsg m;
    m.curve.generation = r.get<std::uint64_t>();
    m.curve.significant = r.get<std::uint64_t>();
    m.curve.points = get_curve(r);
    r.finish();
    return m;
}

}  // namespace isowall
