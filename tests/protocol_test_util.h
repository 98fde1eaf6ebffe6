// Shared by the protocol tests (protocol_roundtrip_test.cpp, protocol_malformed_test.cpp):
// equality and printing for the wire messages, a sample of each message with every field set,
// hex dumps, and the two checks: expect_round_trip and expect_wire_error. Everything is inline and
// in a named namespace, so a test file that uses only some of it draws no unused-function warning.
#pragma once

#include "wall_protocol/protocol.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <limits>
#include <ostream>
#include <span>
#include <string>
#include <variant>
#include <vector>

namespace isowall {

// ---- equality and printing for the tests only (wall_protocol/protocol.h stays free of them)
// ----------

inline bool operator==(const Camera& a, const Camera& b) {
    return a.eye == b.eye && a.target == b.target && a.up == b.up && a.projection == b.projection &&
           a.fovy_deg == b.fovy_deg && a.ortho_height == b.ortho_height && a.near_z == b.near_z &&
           a.far_z == b.far_z;
}
inline bool operator==(const Frustum& a, const Frustum& b) {
    return a.left == b.left && a.right == b.right && a.bottom == b.bottom && a.top == b.top &&
           a.near_z == b.near_z && a.far_z == b.far_z && a.projection == b.projection;
}
inline bool operator==(const FrameView& a, const FrameView& b) {
    return a.camera == b.camera && a.frustum == b.frustum && a.width == b.width &&
           a.height == b.height && a.iso == b.iso && a.clip == b.clip;
}
inline bool operator==(const PixelRect& a, const PixelRect& b) {
    return a.x == b.x && a.y == b.y && a.width == b.width && a.height == b.height;
}
inline bool operator==(const CurvePoint& a, const CurvePoint& b) {
    return a.emulated_s == b.emulated_s && a.final_px == b.final_px &&
           a.squared_error == b.squared_error;
}
inline bool operator==(const FrameCurve& a, const FrameCurve& b) {
    return a.generation == b.generation && a.significant == b.significant && a.points == b.points;
}
inline bool operator==(const TraceSpan& a, const TraceSpan& b) {
    return a.stage == b.stage && a.start_s == b.start_s && a.wall_s == b.wall_s &&
           a.cpu_s == b.cpu_s;
}
inline bool operator==(const TileHelloMsg& a, const TileHelloMsg& b) {
    return a.host == b.host && a.threads == b.threads && a.loaded == b.loaded;
}
inline bool operator==(const ViewMsg& a, const ViewMsg& b) {
    return a.generation == b.generation && a.view == b.view && a.surfaces == b.surfaces &&
           a.step == b.step;
}
inline bool operator==(const ProgressMsg& a, const ProgressMsg& b) {
    return a.generation == b.generation && a.rays == b.rays && a.cpu_s == b.cpu_s;
}
inline bool operator==(const SnapshotMsg&, const SnapshotMsg&) {
    return true;
}
inline bool operator==(const ImageMsg& a, const ImageMsg& b) {
    return a.generation == b.generation && a.width == b.width && a.height == b.height &&
           a.rgba == b.rgba && a.depth == b.depth;
}
inline bool operator==(const QuitMsg&, const QuitMsg&) {
    return true;
}
inline bool operator==(const TileResultMsg& a, const TileResultMsg& b) {
    return a.host == b.host && a.cpu_s == b.cpu_s && a.frame_s == b.frame_s &&
           a.rss_mib == b.rss_mib && a.rays == b.rays && a.groups == b.groups &&
           a.triangles == b.triangles && a.frames == b.frames && a.interrupted == b.interrupted &&
           a.jobs_own == b.jobs_own && a.jobs_helped == b.jobs_helped &&
           a.bytes_sent == b.bytes_sent && a.late_dropped == b.late_dropped &&
           a.significant == b.significant && a.curve == b.curve && a.earlier == b.earlier &&
           a.spans == b.spans;
}
inline bool operator==(const ReleaseMsg&, const ReleaseMsg&) {
    return true;
}
inline bool operator==(const StartMsg&, const StartMsg&) {
    return true;
}
inline bool operator==(const AliveMsg&, const AliveMsg&) {
    return true;
}
inline bool operator==(const PreviewMsg& a, const PreviewMsg& b) {
    return a.generation == b.generation && a.width == b.width && a.height == b.height &&
           a.rgb == b.rgb;
}
inline bool operator==(const JobMsg& a, const JobMsg& b) {
    return a.generation == b.generation && a.job == b.job && a.owner == b.owner &&
           a.deliver == b.deliver && a.band == b.band && a.view == b.view && a.rect == b.rect;
}
inline bool operator==(const JobDoneMsg& a, const JobDoneMsg& b) {
    return a.generation == b.generation && a.job == b.job && a.rays == b.rays &&
           a.groups == b.groups && a.triangles == b.triangles && a.cpu_s == b.cpu_s &&
           a.cpu_end_s == b.cpu_end_s && a.start_s == b.start_s && a.end_s == b.end_s &&
           a.bytes == b.bytes;
}
inline bool operator==(const RegionMsg& a, const RegionMsg& b) {
    return a.generation == b.generation && a.job == b.job && a.layer == b.layer &&
           a.rect == b.rect && a.cpu_end_s == b.cpu_end_s && a.rgba == b.rgba && a.depth == b.depth;
}
inline bool operator==(const LandedMsg& a, const LandedMsg& b) {
    return a.generation == b.generation && a.job == b.job;
}
inline bool operator==(const LostMsg& a, const LostMsg& b) {
    return a.rank == b.rank;
}
inline bool operator==(const CurveAskMsg& a, const CurveAskMsg& b) {
    return a.generation == b.generation;
}
inline bool operator==(const CurveMsg& a, const CurveMsg& b) {
    return a.curve == b.curve;
}
inline bool operator==(const FailedMsg& a, const FailedMsg& b) {
    return a.input == b.input && a.what == b.what;
}

inline bool operator==(const StoreAskMsg& a, const StoreAskMsg& b) {
    return a.part == b.part && a.index == b.index;
}
inline bool operator==(const StoreMetaMsg& a, const StoreMetaMsg& b) {
    return a.is_store == b.is_store && a.zarray == b.zarray && a.zattrs == b.zattrs &&
           a.octree_bytes == b.octree_bytes && a.bytes_on_disk == b.bytes_on_disk;
}
inline bool operator==(const StorePartMsg& a, const StorePartMsg& b) {
    return a.part == b.part && a.index == b.index && a.bytes == b.bytes;
}
inline std::ostream& operator<<(std::ostream& os, const PixelRect& p) {
    return os << "PixelRect{" << p.x << ", " << p.y << ", " << p.width << "x" << p.height << "}";
}
inline std::ostream& operator<<(std::ostream& os, const TraceSpan& s) {
    return os << "TraceSpan{stage " << int{s.stage} << ", start " << s.start_s << ", wall "
              << s.wall_s << ", cpu " << s.cpu_s << "}";
}
inline void PrintTo(const TileHelloMsg& m, std::ostream* os) {
    *os << "TileHelloMsg{" << m.host << ", " << m.threads << " threads"
        << (m.loaded ? ", loaded}" : "}");
}
inline void PrintTo(const ViewMsg& m, std::ostream* os) {
    *os << "ViewMsg{generation " << m.generation << ", " << m.view << "}";
}
inline void PrintTo(const ProgressMsg& m, std::ostream* os) {
    *os << "ProgressMsg{generation " << m.generation << ", rays " << m.rays << ", cpu_s " << m.cpu_s
        << "}";
}
inline void PrintTo(const SnapshotMsg&, std::ostream* os) {
    *os << "SnapshotMsg{}";
}
inline void PrintTo(const ImageMsg& m, std::ostream* os) {
    *os << "ImageMsg{generation " << m.generation << ", " << m.width << "x" << m.height << ", "
        << m.rgba.size() << " rgba bytes, " << m.depth.size() << " depths}";
}
inline void PrintTo(const QuitMsg&, std::ostream* os) {
    *os << "QuitMsg{}";
}
inline void PrintTo(const TileResultMsg& m, std::ostream* os) {
    *os << "TileResultMsg{" << m.host << ", cpu_s " << m.cpu_s << ", frame_s " << m.frame_s
        << ", rss_mib " << m.rss_mib << ", rays " << m.rays << ", groups " << m.groups
        << ", triangles " << m.triangles << ", frames " << m.frames << ", interrupted "
        << m.interrupted << ", spans";
    for (const TraceSpan& s : m.spans) *os << " " << s;
    *os << ", jobs " << m.jobs_own << "+" << m.jobs_helped << ", bytes " << m.bytes_sent
        << ", late dropped " << m.late_dropped << ", significant " << m.significant << ", "
        << m.curve.size() << " curve points}";
}
inline void PrintTo(const ReleaseMsg&, std::ostream* os) {
    *os << "ReleaseMsg{}";
}
inline void PrintTo(const StartMsg&, std::ostream* os) {
    *os << "StartMsg{}";
}
inline void PrintTo(const AliveMsg&, std::ostream* os) {
    *os << "AliveMsg{}";
}
inline void PrintTo(const PreviewMsg& m, std::ostream* os) {
    *os << "PreviewMsg{generation " << m.generation << ", " << m.width << "x" << m.height << ", "
        << m.rgb.size() << " rgb bytes}";
}
inline void PrintTo(const JobMsg& m, std::ostream* os) {
    *os << "JobMsg{generation " << m.generation << ", job " << m.job << ", owner " << m.owner
        << ", band " << int(m.band) << ", " << m.view << ", rect " << m.rect << "}";
}
inline void PrintTo(const JobDoneMsg& m, std::ostream* os) {
    *os << "JobDoneMsg{generation " << m.generation << ", job " << m.job << ", rays " << m.rays
        << ", cpu " << m.cpu_s << ", cpu_end " << m.cpu_end_s << ", bytes " << m.bytes << "}";
}
inline void PrintTo(const RegionMsg& m, std::ostream* os) {
    *os << "RegionMsg{generation " << m.generation << ", job " << m.job << ", rect " << m.rect
        << ", " << m.rgba.size() << " rgba bytes, " << m.depth.size() << " depths}";
}
inline void PrintTo(const StoreAskMsg& m, std::ostream* os) {
    *os << "StoreAskMsg{part " << int(m.part) << ", index " << m.index << "}";
}
inline void PrintTo(const StoreMetaMsg& m, std::ostream* os) {
    *os << "StoreMetaMsg{" << m.is_store << ", " << m.zarray.size() << "+" << m.zattrs.size()
        << " bytes, octree " << m.octree_bytes << "}";
}
inline void PrintTo(const StorePartMsg& m, std::ostream* os) {
    *os << "StorePartMsg{part " << int(m.part) << ", index " << m.index << ", " << m.bytes.size()
        << " bytes}";
}
inline void PrintTo(const LandedMsg& m, std::ostream* os) {
    *os << "LandedMsg{generation " << m.generation << ", job " << m.job << "}";
}

namespace protocol_testing {

using Bytes = std::vector<std::byte>;

inline std::string hex(std::span<const std::byte> bytes) {
    std::string s;
    char buf[4];
    for (std::byte b : bytes) {
        std::snprintf(buf, sizeof buf, "%02x ", static_cast<unsigned>(b));
        s += buf;
    }
    return s;
}

// ---- samples with a value other than the default in every field -----------------------------

inline TileHelloMsg sample_hello() {
    using namespace std::string_literals;
    return {"rank\0host-\xc3\xa9"s, 24, true};  // an inner NUL and UTF-8: the length is on the wire
}

inline ViewMsg sample_view() {
    ViewMsg m;
    m.generation = 0x0123456789abcdefULL;  // every byte differs, so byte order shows
    m.view.camera.eye = {1.5f, -2.25f, 30.0f};
    m.view.camera.target = {0.5f, 0.25f, -1.0f};
    m.view.camera.up = {0.1f, 0.2f, 0.97f};
    m.view.camera.projection = Projection::orthographic;
    m.view.camera.fovy_deg = 47.5f;
    m.view.camera.ortho_height = 3.75f;
    m.view.camera.near_z = 0.5f;
    m.view.camera.far_z = 250.0f;
    m.view.frustum = {-0.3f, 0.7f, -0.2f, 0.45f, 0.25f, 500.0f, Projection::orthographic};
    m.view.width = 1920;
    m.view.height = 1080;
    m.view.iso = 117.25;
    m.view.clip.add({{0, -1, 0}, -40.5f});  // y < 40.5
    m.view.clip.add({{0.6f, 0, 0.8f}, 12});
    m.surfaces = {{117.25, {177, 122, 101}, 0.3f, true}, {160.5, kDefaultSurfaceColour, 1, false}};
    m.step = 0x00010203;  // 66051: below kMaxTimeSteps, its bytes differ
    return m;
}

inline ProgressMsg sample_progress() {
    return {42, 1234567890123ULL, 3.25};
}

inline JobMsg sample_job() {
    JobMsg m;
    m.generation = 0x1122334455667788ULL;
    m.job = 0xa1b2c3d4u;
    m.owner = 17;
    m.deliver = 17;
    m.band = Band::fine;
    m.view = sample_view().view;
    m.rect = {640, 360, 320, 240};
    return m;
}

inline JobDoneMsg sample_job_done() {
    return {9, 77, 123456789012ULL, 33, 44444, 0.125, 2.5, 1.7e9, 1.7e9 + 0.25, 98765};
}

inline RegionMsg sample_region() {
    RegionMsg m;
    m.generation = 11;
    m.job = 5;
    m.layer = 3;
    m.rect = {100, 50, 3, 2};
    m.cpu_end_s = 0.75;
    for (int i = 0; i < 3 * 2 * 4; ++i) m.rgba.push_back(static_cast<std::uint8_t>(7 * i + 1));
    m.depth = {0.0f, 0.25f, 0.5f, 0.75f, 0.875f, 1.0f};
    return m;
}

inline ImageMsg sample_image() {
    ImageMsg m;
    m.generation = 7;
    m.width = 3;
    m.height = 2;
    for (int i = 0; i < 3 * 2 * 4; ++i) m.rgba.push_back(static_cast<std::uint8_t>(11 * i + 3));
    m.depth = {0.0f, 0.125f, 0.5f, 0.75f, 0.999f, 1.0f};
    return m;
}

inline PreviewMsg sample_preview() {
    PreviewMsg m;
    m.generation = 0x0807060504030201ULL;
    m.width = 3;
    m.height = 2;
    m.rgb.clear();
    for (int i = 0; i < 3 * 2 * 3; ++i) m.rgb.push_back(static_cast<std::uint8_t>(13 * i + 5));
    return m;
}

inline TileResultMsg sample_tile_result() {
    TileResultMsg m;
    m.host = "tile-07.cluster";
    m.cpu_s = 12.5;
    m.frame_s = 20.25;
    m.rss_mib = 512.75;
    m.rays = 9000000001ULL;
    m.groups = 17;
    m.triangles = 123456;
    m.frames = 3;
    m.interrupted = 2;
    m.jobs_own = 31;
    m.jobs_helped = 12;
    m.bytes_sent = 1u << 30;
    m.late_dropped = 5;
    m.significant = 209000;
    m.curve = {{0.125, 1000, 512.5}, {0.5, 208000, 3.25}};
    m.earlier = {{1, 207000, {{0.25, 5, 100.5}}}, {2, 0, {}}};
    const std::uint8_t last_stage = std::size(kTraceStages) - 1;
    m.spans = {
        {0, 1.7e9, 0.5, 0.25}, {3, 1.7e9 + 0.5, 0.125, 0.0625}, {last_stage, 1.7e9 + 1, 2, 1}};
    return m;
}

struct Sample {
    const char* name;
    Tag tag;
    Bytes bytes;
};

inline StoreMetaMsg sample_store_meta() {
    return {true, R"({"zarr_format": 2})", R"({"isowall": {}})", 123456, 7890};
}

inline StorePartMsg sample_store_part() {
    return {StorePart::octree, 3, {std::byte{1}, std::byte{2}, std::byte{0xff}}};
}

inline std::vector<Sample> samples() {
    return {{"hello", Tag::hello, encode(sample_hello())},
            {"view", Tag::view, encode(sample_view())},
            {"progress", Tag::progress, encode(sample_progress())},
            {"snapshot", Tag::snapshot, encode(SnapshotMsg{})},
            {"image", Tag::image, encode(sample_image())},
            {"quit", Tag::quit, encode(QuitMsg{})},
            {"tile_result", Tag::tile_result, encode(sample_tile_result())},
            {"release", Tag::release, encode(ReleaseMsg{})},
            {"start", Tag::start, encode(StartMsg{})},
            {"alive", Tag::alive, encode(AliveMsg{})},
            {"preview", Tag::preview, encode(sample_preview())},
            {"job", Tag::job, encode(sample_job())},
            {"job_done", Tag::job_done, encode(sample_job_done())},
            {"region", Tag::region, encode(sample_region())},
            {"landed", Tag::landed, encode(LandedMsg{3, 4})},
            {"store_ask", Tag::store_ask, encode(StoreAskMsg{StorePart::chunk, 77})},
            {"store_meta", Tag::store_meta, encode(sample_store_meta())},
            {"store_part", Tag::store_part, encode(sample_store_part())},
            {"failed", Tag::failed, encode(FailedMsg{true, "a.nrrd: sizes: bad"})}};
}

// decode_message must throw a WireError whose text names the message and `field`.
inline void expect_wire_error(Tag tag, std::span<const std::byte> bytes, const std::string& field) {
    const std::string message = std::string(to_string(tag)) + " message";
    try {
        decode_message(tag, bytes);
        ADD_FAILURE() << message << " decoded, expected a WireError naming " << field
                      << "; bytes: " << hex(bytes);
    } catch (const WireError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(message), std::string::npos) << what;
        EXPECT_NE(what.find(field), std::string::npos) << "expected " << field << " in: " << what;
    }
}

inline constexpr std::uint64_t kHugeCount = std::uint64_t{1} << 62;
inline constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
inline constexpr float kInf = std::numeric_limits<float>::infinity();

template <class T>
void expect_round_trip(const T& m) {
    const Bytes bytes = encode(m);
    const T back = decode_as<T>(T::kTag, bytes);
    EXPECT_EQ(back, m) << "bytes: " << hex(bytes);
    // The variant path gives the same bytes and the same message.
    const Message as_variant = m;
    EXPECT_EQ(tag_of(as_variant), T::kTag);
    EXPECT_EQ(encode(as_variant), bytes);
    const Message decoded = decode_message(T::kTag, bytes);
    ASSERT_TRUE(std::holds_alternative<T>(decoded)) << "index " << decoded.index();
    EXPECT_EQ(std::get<T>(decoded), m);
}

}  // namespace protocol_testing
}  // namespace isowall
