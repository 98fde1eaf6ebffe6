// Each message's encoder sits right above its decoder, so a field added to one is seen in the
// other. Decoders check values, not only lengths: a message that decodes is one the receiver can
// use as is (sizes within limits, the region inside its screen, finite camera numbers), so no
// caller repeats the checks and none forgets them.
#include "comm/protocol.h"

#include <cmath>
#include <iterator>
#include <string>
#include <type_traits>
#include <variant>

namespace isowall {
namespace {

// ---- pieces shared by several messages ------------------------------------------------------

// A NaN or an infinity in a camera, frustum or isovalue gives a blank or garbage tile with no
// error anywhere, so the wire refuses them and names the field.
template <class F>
F get_finite(MessageReader& r, const char* field) {
    const F v = r.get<F>();
    if (!std::isfinite(v))
        r.fail(std::string(field) + ": expected a finite number, got " + std::to_string(v));
    return v;
}

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

// A side read from the wire, checked against [min_px, kMaxImageSide] before anything is sized
// from it.
std::int32_t get_side(MessageReader& r, const char* field, std::int32_t min_px) {
    const auto v = r.get<std::int32_t>();
    if (v < min_px || v > kMaxImageSide)
        r.fail(std::string(field) + ": expected " + std::to_string(min_px) + ".." +
               std::to_string(kMaxImageSide) + ", got " + std::to_string(v));
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

// In 64 bits: x + width of two int32 values may overflow an int.
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

// stage u8 + start_s, wall_s, cpu_s as doubles: the least a span takes on the wire, for counts.
constexpr std::size_t kTraceSpanWireBytes = 1 + 3 * sizeof(double);

void put_trace_span(MessageWriter& w, const TraceSpan& s) {
    w.put(s.stage);
    w.put(s.start_s);
    w.put(s.wall_s);
    w.put(s.cpu_s);
}

TraceSpan get_trace_span(MessageReader& r) {
    TraceSpan s;
    s.stage = r.get<std::uint8_t>();
    // The stage indexes kTraceStages when the trace is written out.
    if (s.stage >= std::size(kTraceStages))
        r.fail("spans.stage: expected 0.." + std::to_string(std::size(kTraceStages) - 1) +
               ", got " + std::to_string(s.stage));
    s.start_s = r.get<double>();
    s.wall_s = r.get<double>();
    s.cpu_s = r.get<double>();
    return s;
}

}  // namespace

// ---- one encoder and its decoder per message --------------------------------------------------
// The decoders are static: callers go through decode_message, which picks one by tag.

std::vector<std::byte> encode(const HelloMsg& m) {
    MessageWriter w(HelloMsg::kVersion);
    w.put_string(m.host);
    return w.take();
}

static HelloMsg decode_hello(std::span<const std::byte> bytes) {
    MessageReader r(bytes, HelloMsg::kVersion, "hello message");
    HelloMsg m;
    m.host = r.get_string();
    r.finish();
    return m;
}

std::vector<std::byte> encode(const ViewMsg& m) {
    MessageWriter w(ViewMsg::kVersion);
    w.put(m.generation);
    put_frame_view(w, m.view);
    put_pixel_rect(w, m.region);
    return w.take();
}

static ViewMsg decode_view(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ViewMsg::kVersion, "view message");
    ViewMsg m;
    m.generation = r.get<std::uint64_t>();
    m.view = get_frame_view(r);
    m.region = get_pixel_rect(r);
    // A tile indexes its image with the region: outside the screen it would write out of bounds.
    if (!inside(m.region, m.view.width, m.view.height))
        r.fail("region: expected a rectangle inside the " + std::to_string(m.view.width) + "x" +
               std::to_string(m.view.height) + " screen, got " + to_text(m.region));
    r.finish();
    return m;
}

std::vector<std::byte> encode(const ProgressMsg& m) {
    MessageWriter w(ProgressMsg::kVersion);
    w.put(m.generation);
    w.put(m.rays);
    w.put(static_cast<std::uint8_t>(m.done ? 1 : 0));
    w.put(m.cpu_s);
    return w.take();
}

static ProgressMsg decode_progress(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ProgressMsg::kVersion, "progress message");
    ProgressMsg m;
    m.generation = r.get<std::uint64_t>();
    m.rays = r.get<std::uint64_t>();
    m.done = r.get_bool();
    m.cpu_s = r.get<double>();
    r.finish();
    return m;
}

std::vector<std::byte> encode(const SnapshotMsg&) {
    return MessageWriter(SnapshotMsg::kVersion).take();
}

static SnapshotMsg decode_snapshot(std::span<const std::byte> bytes) {
    MessageReader r(bytes, SnapshotMsg::kVersion, "snapshot message");
    r.finish();
    return {};
}

std::vector<std::byte> encode(const ImageMsg& m) {
    MessageWriter w(ImageMsg::kVersion);
    w.put(m.generation);
    w.put(m.width);
    w.put(m.height);
    // A length and the bytes: the layout of put_array of u8, written in one copy, not per byte.
    w.put_bytes(std::as_bytes(std::span(m.rgba)));
    w.put_array(std::span<const float>(m.depth));
    return w.take();
}

static ImageMsg decode_image(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ImageMsg::kVersion, "image message");
    ImageMsg m;
    m.generation = r.get<std::uint64_t>();
    m.width = get_side(r, "width", 0);
    m.height = get_side(r, "height", 0);
    // Both sides are at most kMaxImageSide, so the products fit easily in 64 bits.
    const std::uint64_t pixels =
        static_cast<std::uint64_t>(m.width) * static_cast<std::uint64_t>(m.height);
    const auto rgba = r.get_bytes();  // its length is checked against the message first
    if (rgba.size() != pixels * 4)
        r.fail("rgba: expected " + std::to_string(pixels * 4) + " bytes for " +
               std::to_string(m.width) + "x" + std::to_string(m.height) + ", got " +
               std::to_string(rgba.size()));
    const auto* first = reinterpret_cast<const std::uint8_t*>(rgba.data());
    m.rgba.assign(first, first + rgba.size());
    m.depth = r.get_array<float>();
    if (!m.depth.empty() && m.depth.size() != pixels)
        r.fail("depth: expected 0 or " + std::to_string(pixels) + " values for " +
               std::to_string(m.width) + "x" + std::to_string(m.height) + ", got " +
               std::to_string(m.depth.size()));
    r.finish();
    return m;
}

std::vector<std::byte> encode(const QuitMsg&) {
    return MessageWriter(QuitMsg::kVersion).take();
}

static QuitMsg decode_quit(std::span<const std::byte> bytes) {
    MessageReader r(bytes, QuitMsg::kVersion, "quit message");
    r.finish();
    return {};
}

std::vector<std::byte> encode(const TileResultMsg& m) {
    MessageWriter w(TileResultMsg::kVersion);
    w.put_string(m.host);
    w.put(m.cpu_s);
    w.put(m.frame_s);
    w.put(m.rss_mib);
    w.put(m.rays);
    w.put(m.groups);
    w.put(m.triangles);
    w.put(m.frames);
    w.put(m.interrupted);
    w.put(static_cast<std::uint64_t>(m.spans.size()));
    for (const TraceSpan& s : m.spans) put_trace_span(w, s);
    return w.take();
}

static TileResultMsg decode_tile_result(std::span<const std::byte> bytes) {
    MessageReader r(bytes, TileResultMsg::kVersion, "tile_result message");
    TileResultMsg m;
    m.host = r.get_string();
    m.cpu_s = r.get<double>();
    m.frame_s = r.get<double>();
    m.rss_mib = r.get<double>();
    m.rays = r.get<std::uint64_t>();
    m.groups = r.get<std::uint64_t>();
    m.triangles = r.get<std::uint64_t>();
    m.frames = r.get<std::uint64_t>();
    m.interrupted = r.get<std::uint64_t>();
    const std::size_t n = r.get_count(kTraceSpanWireBytes);  // checked before the reserve
    m.spans.reserve(n);
    for (std::size_t i = 0; i < n; ++i) m.spans.push_back(get_trace_span(r));
    r.finish();
    return m;
}

// ---- the variant ------------------------------------------------------------------------------

std::vector<std::byte> encode(const Message& m) {
    return std::visit([](const auto& msg) { return encode(msg); }, m);
}

Tag tag_of(const Message& m) {
    return std::visit([](const auto& msg) { return std::decay_t<decltype(msg)>::kTag; }, m);
}

const char* to_string(Tag tag) {
    switch (tag) {
        case Tag::hello:
            return "hello";
        case Tag::view:
            return "view";
        case Tag::progress:
            return "progress";
        case Tag::snapshot:
            return "snapshot";
        case Tag::image:
            return "image";
        case Tag::quit:
            return "quit";
        case Tag::tile_result:
            return "tile_result";
    }
    // A tag comes off the wire as any int32, so this is reachable.
    return "unknown";
}

Message decode_message(Tag tag, std::span<const std::byte> bytes) {
    switch (tag) {
        case Tag::hello:
            return decode_hello(bytes);
        case Tag::view:
            return decode_view(bytes);
        case Tag::progress:
            return decode_progress(bytes);
        case Tag::snapshot:
            return decode_snapshot(bytes);
        case Tag::image:
            return decode_image(bytes);
        case Tag::quit:
            return decode_quit(bytes);
        case Tag::tile_result:
            return decode_tile_result(bytes);
    }
    throw WireError("message with tag " + std::to_string(static_cast<std::int32_t>(tag)) +
                    ": unknown tag, expected " +
                    std::to_string(static_cast<std::int32_t>(Tag::hello)) + ".." +
                    std::to_string(static_cast<std::int32_t>(kLastTag)));
}

}  // namespace isowall
