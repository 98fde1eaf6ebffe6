// Each message's encoder sits right above its decoder, so a field added to one is seen in the
// other. The decoders are static: callers go through decode_payload, which picks one by type.
#include "remote/view_protocol.h"

#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>
#include <type_traits>

#include "remote/request_checks.h"
#include "remote/slot_list.h"
#include "wire/message_fields.h"

namespace isowall::remote {

using message_fields::get_finite;

namespace {

// Text that ends up in logs and error lines: bounded and printable, so a hostile peer can neither
// make a receiver hold much nor break a log line. Checked on the span before a string is made.
void put_text(MessageWriter& w, std::string_view s) {
    w.put_string(s);
}

std::string get_text(MessageReader& r, const char* field, std::size_t max_bytes,
                     bool may_be_empty) {
    const auto b = r.get_bytes();  // its length is checked against the message first
    if (b.size() > max_bytes)
        r.fail(std::string(field) + ": " + std::to_string(b.size()) + " bytes, expected at most " +
               std::to_string(max_bytes));
    if (b.empty() && !may_be_empty) r.fail(std::string(field) + ": expected a name, got none");
    for (std::size_t i = 0; i < b.size(); ++i) {
        const auto c = static_cast<unsigned>(b[i]);
        if (c < 0x20 || c > 0x7e)
            r.fail(std::string(field) + ": byte " + std::to_string(i) + " is " + std::to_string(c) +
                   ", expected printable ASCII (32..126)");
    }
    return {reinterpret_cast<const char*>(b.data()), b.size()};
}

glm::vec3 get_finite_vec3(MessageReader& r, const std::string& field) {
    glm::vec3 v;
    for (int a = 0; a < 3; ++a) v[a] = get_finite<float>(r, (field + "." + "xyz"[a]).c_str());
    return v;
}

std::int32_t get_int_in(MessageReader& r, const std::string& field, std::int32_t lo,
                        std::int32_t hi) {
    const auto v = r.get<std::int32_t>();
    if (v < lo || v > hi)
        r.fail(field + ": expected " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " +
               std::to_string(v));
    return v;
}

// A group key's fields; errors name them "key.level" and so on.
void put_group_key(MessageWriter& w, const GroupKey& k) {
    for (const int v : {k.seed.x, k.seed.y, k.seed.z, k.level}) w.put(static_cast<std::int32_t>(v));
    w.put(k.iso);
    w.put(static_cast<std::uint8_t>(k.refinement));
}

GroupKey get_group_key(MessageReader& r) {
    const auto name = [](const char* field) { return std::string("key.") + field; };
    GroupKey k;
    int* const ints[] = {&k.seed.x, &k.seed.y, &k.seed.z, &k.level};
    const char* const fields[] = {"seed.x", "seed.y", "seed.z", "level"};
    for (int i = 0; i < 4; ++i) {
        const auto v = r.get<std::int32_t>();
        const std::int32_t hi = i == 3 ? kMaxGroupLevel : std::numeric_limits<std::int32_t>::max();
        if (v < 0 || v > hi)
            r.fail(name(fields[i]) + ": expected 0.." + std::to_string(hi) + ", got " +
                   std::to_string(v));
        *ints[i] = v;
    }
    k.iso = r.get<double>();
    if (!std::isfinite(k.iso))
        r.fail(name("iso") + ": expected a finite number, got " + std::to_string(k.iso));
    const auto refinement = r.get<std::uint8_t>();
    if (refinement > 1)
        r.fail(name("refinement") + ": expected 0 or 1, got " + std::to_string(refinement));
    k.refinement = refinement == 1;
    return k;
}

bool get_flag(MessageReader& r, const char* field) {
    const auto v = r.get<std::uint8_t>();
    if (v > 1) r.fail(std::string(field) + ": expected 0 or 1, got " + std::to_string(v));
    return v == 1;
}

}  // namespace

// ---- one encoder and its decoder per message ---------------------------------------------------

static std::vector<std::byte> encode(const HelloMsg& m) {
    const bool shared = m.role != SessionRole::none;
    const std::uint8_t version = m.takes_exact ? 3 : shared ? 2 : 1;
    MessageWriter w(version);
    w.put(m.protocol_version);
    put_text(w, m.dataset);
    put_text(w, m.token);
    w.put(m.encoding);
    if (version >= 2) {
        w.put(static_cast<std::uint8_t>(m.role));
        put_text(w, m.session);
    }
    if (version >= 3) w.put(static_cast<std::uint8_t>(m.takes_exact));
    return w.take();
}

static HelloMsg decode_hello(std::span<const std::byte> bytes) {
    const std::uint8_t version =
        !bytes.empty() && bytes[0] >= std::byte{1} && bytes[0] <= std::byte{HelloMsg::kVersion}
            ? static_cast<std::uint8_t>(bytes[0])
            : HelloMsg::kVersion;
    MessageReader r(bytes, version, "hello message");
    HelloMsg m;
    m.protocol_version = r.get<std::uint16_t>();
    m.dataset = get_text(r, "dataset", kMaxDatasetNameBytes, false);
    m.token = get_text(r, "token", kMaxTokenBytes, true);
    m.encoding = r.get<std::uint8_t>();
    if (version >= 2) {
        // Version 2 has a role; version 3 may have none (0), and then no session name.
        const auto role = r.get<std::uint8_t>();
        const int least = version == 2 ? 1 : 0;
        if (role < least || role > 2)
            r.fail("role: " + std::to_string(role) + ", expected " +
                   (least == 0 ? "0 (none), " : "") + "1 (presenter) or 2 (follower)");
        m.role = static_cast<SessionRole>(role);
        m.session = get_text(r, "session", kMaxSessionNameBytes, m.role == SessionRole::none);
        if (m.role == SessionRole::none && !m.session.empty())
            r.fail("session: a name without a role");
    }
    if (version >= 3) {
        // Version 3 exists to say 1; a hello without it is version 1 or 2, so that every hello has
        // one encoding.
        m.takes_exact = get_flag(r, "takes_exact");
        if (!m.takes_exact)
            r.fail("takes_exact: 0 in a version 3 hello, which is sent only with 1");
    }
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const SessionMsg& m) {
    MessageWriter w(SessionMsg::kVersion);
    put_text(w, m.session);
    put_text(w, m.presenter);
    w.put(m.members);
    return w.take();
}

static SessionMsg decode_session(std::span<const std::byte> bytes) {
    MessageReader r(bytes, SessionMsg::kVersion, "session message");
    SessionMsg m;
    m.session = get_text(r, "session", kMaxSessionNameBytes, false);
    m.presenter = get_text(r, "presenter", kMaxPeerNameBytes, true);
    m.members = r.get<std::uint32_t>();
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const ReadyMsg& m) {
    MessageWriter w(ReadyMsg::kVersion);
    w.put(m.bounds.min);
    w.put(m.bounds.max);
    w.put(m.value_min);
    w.put(m.value_max);
    for (int a = 0; a < 3; ++a) w.put(static_cast<std::int32_t>(m.dims[a]));
    w.put(m.spacing);
    for (int c = 0; c < 3; ++c) w.put(m.axes[c]);
    return w.take();
}

static ReadyMsg decode_ready(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ReadyMsg::kVersion, "ready message");
    ReadyMsg m;
    m.bounds.min = get_finite_vec3(r, "bounds.min");
    m.bounds.max = get_finite_vec3(r, "bounds.max");
    if (m.bounds.empty()) r.fail("bounds: expected min <= max on every axis");
    // A volume loads only up to 1e7 object units a side (volume/load_checks.h), which
    // any view can frame; a server saying more would end in a view option's error instead.
    for (int a = 0; a < 3; ++a)
        if (!(std::abs(m.bounds.min[a]) <= 1e9 && std::abs(m.bounds.max[a]) <= 1e9 &&
              m.bounds.max[a] - m.bounds.min[a] <= 1e7))
            r.fail("bounds: expected a box at most 1e7 units a side within 1e9 of the origin");
    m.value_min = get_finite<double>(r, "value_min");
    m.value_max = get_finite<double>(r, "value_max");
    if (m.value_min > m.value_max) r.fail("value_max: expected >= value_min");
    const char* dims[] = {"dims.x", "dims.y", "dims.z"};
    for (int a = 0; a < 3; ++a)
        m.dims[a] = get_int_in(r, dims[a], 1, std::numeric_limits<std::int32_t>::max());
    m.spacing = get_finite_vec3(r, "spacing");
    if (!(m.spacing.x > 0 && m.spacing.y > 0 && m.spacing.z > 0))
        r.fail("spacing: expected positive numbers");
    const char* columns[] = {"axes.x", "axes.y", "axes.z"};
    for (int c = 0; c < 3; ++c) {
        m.axes[c] = get_finite_vec3(r, columns[c]);
        if (std::abs(glm::length(m.axes[c]) - 1.0f) > 1e-3f)
            r.fail(std::string(columns[c]) + ": expected a unit vector");
    }
    if (std::abs(glm::determinant(m.axes) - 1.0f) > 1e-2f)
        r.fail("axes: expected a rotation (orthogonal unit columns, determinant 1)");
    r.finish();
    return m;
}

std::string to_string(LodSchedule s) {
    switch (s) {
        case LodSchedule::off:
            return "off";
        case LodSchedule::on:
            return "on";
        case LodSchedule::chosen:
            return "chosen by the server";
    }
    return "lod " + std::to_string(static_cast<int>(s));
}

static std::vector<std::byte> encode(const RequestMsg& m) {
    MessageWriter w(RequestMsg::kVersion);
    w.put(m.request_id);
    message_fields::put_frame_view(w, m.view);
    w.put(static_cast<std::uint8_t>(m.lod));
    w.put(static_cast<std::uint8_t>(m.cached_groups));
    return w.take();
}

static RequestMsg decode_request(std::span<const std::byte> bytes) {
    MessageReader r(bytes, RequestMsg::kVersion, "request message");
    RequestMsg m;
    m.request_id = r.get<std::uint64_t>();
    m.view = message_fields::get_frame_view(r);
    // The server would cast rays from it; a camera that cannot be drawn is the client's error.
    if (const std::string problem = camera_problem(m.view.camera); !problem.empty())
        r.fail("view.camera: " + problem);
    // The rays and the projection come from the frustum: a degenerate or huge one drew nothing
    // and said nothing (request_checks.h).
    if (const std::string problem = frustum_problem(m.view.frustum); !problem.empty())
        r.fail("view.frustum." + problem);
    const auto lod = r.get<std::uint8_t>();
    if (lod > static_cast<std::uint8_t>(LodSchedule::chosen))
        r.fail("lod: expected 0 (off), 1 (on) or 2 (the server chooses), got " +
               std::to_string(lod));
    m.lod = static_cast<LodSchedule>(lod);
    m.cached_groups = get_flag(r, "cached_groups");
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const EndOfFrameMsg& m) {
    MessageWriter w(EndOfFrameMsg::kVersion);
    for (std::uint64_t v : {m.request_id, m.rays, m.groups, m.triangles, m.bytes}) w.put(v);
    return w.take();
}

static EndOfFrameMsg decode_end_of_frame(std::span<const std::byte> bytes) {
    MessageReader r(bytes, EndOfFrameMsg::kVersion, "end_of_frame message");
    EndOfFrameMsg m;
    for (std::uint64_t* v : {&m.request_id, &m.rays, &m.groups, &m.triangles, &m.bytes})
        *v = r.get<std::uint64_t>();
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const DecodeRateMsg& m) {
    MessageWriter w(DecodeRateMsg::kVersion);
    w.put(static_cast<std::uint8_t>(m.entries.size()));
    for (const DecodeRateMsg::Entry& e : m.entries) {
        w.put(e.encoding);
        w.put(e.triangles);
        w.put(e.seconds);
    }
    return w.take();
}

static DecodeRateMsg decode_decode_rate(std::span<const std::byte> bytes) {
    MessageReader r(bytes, DecodeRateMsg::kVersion, "decode_rate message");
    const auto at_most = [&](const char* field, auto v, auto max) {
        if (v > max)
            r.fail(field + (": " + std::to_string(v)) + ", expected at most " +
                   std::to_string(max));
    };
    DecodeRateMsg m;
    const auto count = r.get<std::uint8_t>();
    at_most("entries", count, kDecodeRateEncodings);  // one per encoding
    for (unsigned i = 0; i < count; ++i) {
        DecodeRateMsg::Entry e;
        e.encoding = r.get<std::uint8_t>();
        at_most("entries.encoding", e.encoding, kDecodeRateEncodings - 1);
        if (!m.entries.empty() && e.encoding <= m.entries.back().encoding)
            r.fail("entries.encoding: " + std::to_string(e.encoding) + " after " +
                   std::to_string(m.entries.back().encoding) + ", expected ascending");
        e.triangles = r.get<std::uint64_t>();
        e.seconds = get_finite<double>(r, "entries.seconds");
        if (e.seconds < 0)
            r.fail("entries.seconds: " + std::to_string(e.seconds) + ", expected >= 0");
        m.entries.push_back(e);
    }
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const ErrorMsg& m) {
    MessageWriter w(ErrorMsg::kVersion);
    w.put(static_cast<std::uint16_t>(m.code));
    put_text(w, m.text);
    return w.take();
}

static ErrorMsg decode_error(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ErrorMsg::kVersion, "error message");
    ErrorMsg m;
    const auto code = r.get<std::uint16_t>();
    if (code < 1 || code > kLastErrorCode)
        r.fail("code: expected 1.." + std::to_string(kLastErrorCode) + ", got " +
               std::to_string(code));
    m.code = static_cast<ErrorCode>(code);
    m.text = get_text(r, "text", kMaxErrorTextBytes, true);
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const ByeMsg&) {
    return MessageWriter(ByeMsg::kVersion).take();
}

static ByeMsg decode_bye(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ByeMsg::kVersion, "bye message");
    r.finish();
    return {};
}

// ---- the messages that carry groups ---------------------------------------------------------

// A group's bytes (GroupMsg::encoded, ExactMsg::bits): checked against kMaxGroupBytes before a
// copy is made.
static std::vector<std::byte> get_group_bytes(MessageReader& r, const char* field) {
    const auto b = r.get_bytes();  // checked against the message: no allocation yet
    if (b.size() > kMaxGroupBytes)
        r.fail(std::string(field) + ": " + std::to_string(b.size()) + " bytes, expected at most " +
               std::to_string(kMaxGroupBytes));
    return {b.begin(), b.end()};
}

static std::vector<std::byte> encode(const GroupMsg& m) {
    MessageWriter w(GroupMsg::kVersion);
    w.put(m.request_id);
    put_group_key(w, m.key);
    w.put(static_cast<std::uint8_t>(m.draw_from_next_frame));
    w.put(m.cache_gen);
    w.put_bytes(m.encoded);
    return w.take();
}

static GroupMsg decode_group_msg(std::span<const std::byte> bytes) {
    MessageReader r(bytes, GroupMsg::kVersion, "group message");
    GroupMsg m;
    m.request_id = r.get<std::uint64_t>();
    m.key = get_group_key(r);
    m.draw_from_next_frame = get_flag(r, "draw_from_next_frame");
    m.cache_gen = r.get<std::uint64_t>();
    m.encoded = get_group_bytes(r, "encoded");
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const VisibleMsg& m) {
    MessageWriter w(VisibleMsg::kVersion);
    w.put(m.request_id);
    put_slots(w, m.slots);
    return w.take();
}

static VisibleMsg decode_visible(std::span<const std::byte> bytes) {
    MessageReader r(bytes, VisibleMsg::kVersion, "visible message");
    VisibleMsg m;
    m.request_id = r.get<std::uint64_t>();
    m.slots = get_slots(r);
    r.finish();
    return m;
}

static std::vector<std::byte> encode(const ExactMsg& m) {
    MessageWriter w(ExactMsg::kVersion);
    w.put(m.request_id);
    put_group_key(w, m.key);
    w.put_bytes(m.bits);
    return w.take();
}

static ExactMsg decode_exact(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ExactMsg::kVersion, "exact message");
    ExactMsg m;
    m.request_id = r.get<std::uint64_t>();
    m.key = get_group_key(r);
    m.bits = get_group_bytes(r, "bits");
    r.finish();
    return m;
}

// ---- dispatch ----------------------------------------------------------------------------------

ErrorMsg make_error(ErrorCode code, std::string_view text) {
    ErrorMsg m{code, std::string(text.substr(0, kMaxErrorTextBytes))};
    for (char& c : m.text)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
    return m;
}

const char* to_string(RemoteTag type) {
    static constexpr const char* kNames[] = {"hello",   "ready",        "request", "group",
                                             "visible", "end_of_frame", "error",   "bye",
                                             "session", "decode_rate",  "exact"};
    static_assert(std::size(kNames) == kLastRemoteTag, "a name for every message type");
    const auto t = static_cast<std::size_t>(type);
    return t >= 1 && t <= kLastRemoteTag ? kNames[t - 1] : "unknown";
}

std::vector<std::byte> encode_payload(const RemoteMessage& m) {
    return std::visit([](const auto& msg) { return encode(msg); }, m);
}

RemoteTag type_of(const RemoteMessage& m) {
    return std::visit([](const auto& msg) { return std::decay_t<decltype(msg)>::kTag; }, m);
}

RemoteMessage decode_payload(RemoteTag type, std::span<const std::byte> payload) {
    switch (type) {
        case RemoteTag::hello:
            return decode_hello(payload);
        case RemoteTag::ready:
            return decode_ready(payload);
        case RemoteTag::request:
            return decode_request(payload);
        case RemoteTag::group:
            return decode_group_msg(payload);
        case RemoteTag::visible:
            return decode_visible(payload);
        case RemoteTag::end_of_frame:
            return decode_end_of_frame(payload);
        case RemoteTag::error:
            return decode_error(payload);
        case RemoteTag::bye:
            return decode_bye(payload);
        case RemoteTag::session:
            return decode_session(payload);
        case RemoteTag::decode_rate:
            return decode_decode_rate(payload);
        case RemoteTag::exact:
            return decode_exact(payload);
    }
    throw WireError("view protocol: unknown message type " +
                    std::to_string(static_cast<unsigned>(type)));
}

}  // namespace isowall::remote
