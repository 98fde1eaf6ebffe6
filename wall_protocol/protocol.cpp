// Each message's encoder sits right above its decoder, so a field added to one is seen in the
// other. Decoders check values, not only lengths: a message that decodes is one the receiver can
// use as is (sizes within limits, the region inside its screen, finite camera numbers), so no
// caller repeats the checks and none forgets them.
#include "wall_protocol/protocol.h"

#include "volume/time_steps.h"

#include "wall_protocol/protocol_jobs.h"
#include "wall_protocol/protocol_store.h"
#include "wire/message_fields.h"

#include <cmath>
#include <iterator>
#include <string>
#include <type_traits>
#include <variant>

namespace isowall {

using namespace message_fields;

namespace {

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

std::vector<std::byte> encode(const TileHelloMsg& m) {
    MessageWriter w(TileHelloMsg::kVersion);
    w.put_string(m.host);
    w.put(m.threads);
    w.put(static_cast<std::uint8_t>(m.loaded));
    return w.take();
}

static TileHelloMsg decode_hello(std::span<const std::byte> bytes) {
    MessageReader r(bytes, TileHelloMsg::kVersion, "hello message");
    TileHelloMsg m;
    m.host = r.get_string();
    m.threads = r.get<std::uint32_t>();
    if (m.threads < 1 || m.threads > 1024)
        throw WireError("hello message: threads: expected 1 to 1024, got " +
                        std::to_string(m.threads));
    m.loaded = r.get_bool();
    r.finish();
    return m;
}

std::vector<std::byte> encode(const ViewMsg& m) {
    MessageWriter w(ViewMsg::kVersion);
    w.put(m.generation);
    put_frame_view(w, m.view);
    put_clip(w, m.view.clip);
    put_surfaces(w, m.surfaces);
    w.put(m.step);
    return w.take();
}

static ViewMsg decode_view(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ViewMsg::kVersion, "view message");
    ViewMsg m;
    m.generation = r.get<std::uint64_t>();
    m.view = get_frame_view(r);
    m.view.clip = get_clip(r);
    m.surfaces = get_surfaces(r);
    m.step = r.get<std::uint32_t>();
    if (m.step >= kMaxTimeSteps)
        r.fail("step: expected below " + std::to_string(kMaxTimeSteps) + ", got " +
               std::to_string(m.step));
    r.finish();
    return m;
}

std::vector<std::byte> encode(const ProgressMsg& m) {
    MessageWriter w(ProgressMsg::kVersion);
    w.put(m.generation);
    w.put(m.rays);
    w.put(m.cpu_s);
    return w.take();
}

static ProgressMsg decode_progress(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ProgressMsg::kVersion, "progress message");
    ProgressMsg m;
    m.generation = r.get<std::uint64_t>();
    m.rays = r.get<std::uint64_t>();
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
    put_pixels(w, m.rgba, m.depth);
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
    get_pixels(r, pixels, /*depth_optional=*/true, m.rgba, m.depth);
    r.finish();
    return m;
}

std::vector<std::byte> encode(const PreviewMsg& m) {
    MessageWriter w(PreviewMsg::kVersion);
    w.put(m.generation);
    w.put(m.width);
    w.put(m.height);
    w.put_bytes(std::as_bytes(std::span(m.rgb)));
    return w.take();
}

static PreviewMsg decode_preview(std::span<const std::byte> bytes) {
    MessageReader r(bytes, PreviewMsg::kVersion, "preview message");
    PreviewMsg m;
    m.generation = r.get<std::uint64_t>();
    // At least one pixel: the control window scales a preview to its tile, dividing by its size.
    m.width = get_side(r, "width", 1, kMaxPreviewSide);
    m.height = get_side(r, "height", 1, kMaxPreviewSide);
    const std::uint64_t expected = std::uint64_t(m.width) * std::uint64_t(m.height) * 3;
    const auto rgb = r.get_bytes();  // its length is checked against the message first
    if (rgb.size() != expected)
        r.fail("rgb: expected " + std::to_string(expected) + " bytes, got " +
               std::to_string(rgb.size()));
    const auto* first = reinterpret_cast<const std::uint8_t*>(rgb.data());
    m.rgb.assign(first, first + rgb.size());
    r.finish();
    return m;
}

std::vector<std::byte> encode(const QuitMsg&) {
    return MessageWriter(QuitMsg::kVersion).take();
}

std::vector<std::byte> encode(const FailedMsg& m) {
    MessageWriter w(FailedMsg::kVersion);
    w.put(static_cast<std::uint8_t>(m.input ? 1 : 0));
    w.put_string(m.what.substr(0, kMaxFailedBytes));
    return w.take();
}

static FailedMsg decode_failed(std::span<const std::byte> bytes) {
    MessageReader r(bytes, FailedMsg::kVersion, "failed message");
    FailedMsg m;
    const auto input = r.get<std::uint8_t>();
    if (input > 1) r.fail("input: expected 0 or 1, got " + std::to_string(input));
    m.input = input == 1;
    m.what = r.get_string();
    if (m.what.size() > kMaxFailedBytes)
        r.fail("what: " + std::to_string(m.what.size()) + " bytes, at most " +
               std::to_string(kMaxFailedBytes));
    r.finish();
    return m;
}

static QuitMsg decode_quit(std::span<const std::byte> bytes) {
    MessageReader r(bytes, QuitMsg::kVersion, "quit message");
    r.finish();
    return {};
}

void job_wire::put_curve(MessageWriter& w, const std::vector<CurvePoint>& curve) {
    w.put(static_cast<std::uint64_t>(curve.size()));
    for (const CurvePoint& c : curve) {
        w.put(c.emulated_s);
        w.put(c.final_px);
        w.put(c.squared_error);
    }
}

std::vector<CurvePoint> job_wire::get_curve(MessageReader& r) {
    const std::size_t points = r.get_count(3 * 8);  // checked before the reserve
    std::vector<CurvePoint> curve;
    curve.reserve(points);
    for (std::size_t i = 0; i < points; ++i) {
        CurvePoint c;
        c.emulated_s = get_finite<double>(r, "curve.emulated_s");
        c.final_px = r.get<std::uint64_t>();
        c.squared_error = get_finite<double>(r, "curve.squared_error");
        curve.push_back(c);
    }
    return curve;
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
    w.put(m.jobs_own);
    w.put(m.jobs_helped);
    w.put(m.bytes_sent);
    w.put(m.late_dropped);
    w.put(m.significant);
    job_wire::put_curve(w, m.curve);
    w.put(static_cast<std::uint64_t>(m.earlier.size()));
    for (const FrameCurve& f : m.earlier) {
        w.put(f.generation);
        w.put(f.significant);
        job_wire::put_curve(w, f.points);
    }
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
    m.jobs_own = r.get<std::uint64_t>();
    m.jobs_helped = r.get<std::uint64_t>();
    m.bytes_sent = r.get<std::uint64_t>();
    m.late_dropped = r.get<std::uint64_t>();
    m.significant = r.get<std::uint64_t>();
    m.curve = job_wire::get_curve(r);
    const std::size_t frames = r.get_count(3 * 8);  // checked before the reserve
    m.earlier.reserve(frames);
    for (std::size_t i = 0; i < frames; ++i) {
        FrameCurve f;
        f.generation = r.get<std::uint64_t>();
        f.significant = r.get<std::uint64_t>();
        f.points = job_wire::get_curve(r);
        m.earlier.push_back(std::move(f));
    }
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
        case Tag::release:
            return "release";
        case Tag::start:
            return "start";
        case Tag::alive:
            return "alive";
        case Tag::preview:
            return "preview";
        case Tag::job:
            return "job";
        case Tag::job_done:
            return "job_done";
        case Tag::region:
            return "region";
        case Tag::landed:
            return "landed";
        case Tag::store_ask:
            return "store_ask";
        case Tag::store_meta:
            return "store_meta";
        case Tag::store_part:
            return "store_part";
        case Tag::curve_ask:
            return "curve_ask";
        case Tag::curve:
            return "curve";
        case Tag::failed:
            return "failed";
        case Tag::lost:
            return "lost";
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
        case Tag::release:
            return job_wire::decode_release(bytes);
        case Tag::start:
            return job_wire::decode_start(bytes);
        case Tag::alive:
            return job_wire::decode_alive(bytes);
        case Tag::preview:
            return decode_preview(bytes);
        case Tag::job:
            return job_wire::decode_job(bytes);
        case Tag::job_done:
            return job_wire::decode_job_done(bytes);
        case Tag::region:
            return job_wire::decode_region(bytes);
        case Tag::landed:
            return job_wire::decode_landed(bytes);
        case Tag::store_ask:
            return store_wire::decode_store_ask(bytes);
        case Tag::store_meta:
            return store_wire::decode_store_meta(bytes);
        case Tag::store_part:
            return store_wire::decode_store_part(bytes);
        case Tag::curve_ask:
            return job_wire::decode_curve_ask(bytes);
        case Tag::curve:
            return job_wire::decode_curve(bytes);
        case Tag::failed:
            return decode_failed(bytes);
        case Tag::lost:
            return job_wire::decode_lost(bytes);
    }
    throw WireError("message with tag " + std::to_string(static_cast<std::int32_t>(tag)) +
                    ": unknown tag, expected 1..14 or 16..22");
}

}  // namespace isowall
