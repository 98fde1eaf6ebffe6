// The messages that carry groups (GroupMsg, VisibleMsg, ExactMsg) and the pieces view_protocol.cpp
// shares with them (view_protocol_parts.h). Each encoder sits right above its decoder.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "remote/slot_list.h"
#include "remote/view_protocol_parts.h"

namespace isowall::remote {

namespace protocol_parts {

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

}  // namespace protocol_parts

using namespace protocol_parts;

// A group's bytes (GroupMsg::encoded, ExactMsg::bits): checked against kMaxGroupBytes before a
// copy is made.
static std::vector<std::byte> get_group_bytes(MessageReader& r, const char* field) {
    const auto b = r.get_bytes();  // checked against the message: no allocation yet
    if (b.size() > kMaxGroupBytes)
        r.fail(std::string(field) + ": " + std::to_string(b.size()) + " bytes, expected at most " +
               std::to_string(kMaxGroupBytes));
    return {b.begin(), b.end()};
}

std::vector<std::byte> encode(const GroupMsg& m) {
    MessageWriter w(GroupMsg::kVersion);
    w.put(m.request_id);
    put_group_key(w, m.key);
    w.put(static_cast<std::uint8_t>(m.draw_from_next_frame));
    w.put(m.cache_gen);
    w.put_bytes(m.encoded);
    return w.take();
}

GroupMsg decode_group_msg(std::span<const std::byte> bytes) {
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

std::vector<std::byte> encode(const VisibleMsg& m) {
    MessageWriter w(VisibleMsg::kVersion);
    w.put(m.request_id);
    put_slots(w, m.slots);
    return w.take();
}

VisibleMsg decode_visible(std::span<const std::byte> bytes) {
    MessageReader r(bytes, VisibleMsg::kVersion, "visible message");
    VisibleMsg m;
    m.request_id = r.get<std::uint64_t>();
    m.slots = get_slots(r);
    r.finish();
    return m;
}

std::vector<std::byte> encode(const ExactMsg& m) {
    MessageWriter w(ExactMsg::kVersion);
    w.put(m.request_id);
    put_group_key(w, m.key);
    w.put_bytes(m.bits);
    return w.take();
}

ExactMsg decode_exact(std::span<const std::byte> bytes) {
    MessageReader r(bytes, ExactMsg::kVersion, "exact message");
    ExactMsg m;
    m.request_id = r.get<std::uint64_t>();
    m.key = get_group_key(r);
    m.bits = get_group_bytes(r, "bits");
    r.finish();
    return m;
}

}  // namespace isowall::remote
