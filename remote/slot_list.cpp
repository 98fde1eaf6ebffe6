#include "remote/slot_list.h"

#include <bit>

namespace isowall::remote {
namespace {

std::string slot_name(std::size_t i) {
    std::string s = "slots[";
    s += std::to_string(i);
    s += ']';
    return s;
}

void check_slot(MessageReader& r, std::uint64_t slot, const std::string& field) {
    if (slot >= kMaxVisibleKeys)
        r.fail(field + ": slot " + std::to_string(slot) + ", expected less than " +
               std::to_string(kMaxVisibleKeys));
}

std::vector<std::uint32_t> get_bitmap(MessageReader& r) {
    const auto n = r.get<std::uint32_t>();
    if (n > kMaxVisibleKeys)
        r.fail("slots: bit count " + std::to_string(n) + ", expected at most " +
               std::to_string(kMaxVisibleKeys));
    const std::size_t bytes = (std::size_t{n} + 7) / 8;
    if (bytes > r.remaining())
        r.fail("slots: a bitmap of " + std::to_string(n) + " bits takes " + std::to_string(bytes) +
               " bytes, " + std::to_string(r.remaining()) + " left");
    std::vector<std::uint32_t> slots;
    for (std::size_t b = 0; b < bytes; ++b) {
        const auto byte = r.get<std::uint8_t>();
        for (unsigned bit = 0; bit < 8; ++bit) {
            if (!(byte >> bit & 1u)) continue;
            const std::size_t slot = b * 8 + bit;
            if (slot >= n)
                r.fail("slots: bit " + std::to_string(slot) + " is set, expected none at or past " +
                       "the bit count " + std::to_string(n));
            slots.push_back(static_cast<std::uint32_t>(slot));
        }
    }
    // One encoding per set (the harness and the byte counts rely on it): n is the highest slot + 1.
    if (n > 0 && (slots.empty() || slots.back() != n - 1))
        r.fail("slots: bit count " + std::to_string(n) + " but bit " + std::to_string(n - 1) +
               " is clear, expected the highest slot + 1");
    return slots;
}

std::vector<std::uint32_t> get_deltas(MessageReader& r) {
    const auto k = r.get<std::uint32_t>();
    if (k > r.remaining())  // a varint takes at least a byte
        r.fail("slots: count " + std::to_string(k) + " is larger than the " +
               std::to_string(r.remaining()) + " bytes left");
    std::vector<std::uint32_t> slots;
    slots.reserve(k);
    std::uint64_t slot = 0;
    for (std::size_t i = 0; i < k; ++i) {
        const std::string field = slot_name(i);
        const std::uint32_t v = get_varint(r, field);
        if (i > 0 && v == 0) r.fail(field + ": gap 0, expected at least 1");
        slot = i == 0 ? v : slot + v;
        check_slot(r, slot, field);
        slots.push_back(static_cast<std::uint32_t>(slot));
    }
    return slots;
}

}  // namespace

void put_varint(MessageWriter& w, std::uint32_t v) {
    while (v >= 0x80) {
        w.put(static_cast<std::uint8_t>((v & 0x7f) | 0x80));
        v >>= 7;
    }
    w.put(static_cast<std::uint8_t>(v));
}

std::size_t varint_bytes(std::uint32_t v) {
    return v == 0 ? 1 : (static_cast<std::size_t>(std::bit_width(v)) + 6) / 7;
}

std::uint32_t get_varint(MessageReader& r, const std::string& field) {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < kMaxVarintBytes; ++i) {
        if (r.remaining() == 0) r.fail(field + ": the varint runs past the end of the message");
        const auto byte = r.get<std::uint8_t>();
        v |= std::uint64_t{byte & 0x7fu} << (7 * i);
        if (!(byte & 0x80)) {
            if (i > 0 && byte == 0)
                r.fail(field + ": varint of " + std::to_string(i + 1) +
                       " bytes ends in a zero byte, expected the shortest form");
            if (v > UINT32_MAX)
                r.fail(field + ": varint " + std::to_string(v) + ", expected less than 2^32");
            return static_cast<std::uint32_t>(v);
        }
    }
    r.fail(field + ": varint longer than " + std::to_string(kMaxVarintBytes) + " bytes");
}

std::size_t bitmap_form_bytes(std::span<const std::uint32_t> slots) {
    const std::size_t n = slots.empty() ? 0 : std::size_t{slots.back()} + 1;
    return 1 + 4 + (n + 7) / 8;
}

std::size_t deltas_form_bytes(std::span<const std::uint32_t> slots) {
    std::size_t bytes = 1 + 4;
    for (std::size_t i = 0; i < slots.size(); ++i)
        bytes += varint_bytes(i == 0 ? slots[0] : slots[i] - slots[i - 1]);
    return bytes;
}

SlotForm smaller_form(std::span<const std::uint32_t> slots) {
    return bitmap_form_bytes(slots) <= deltas_form_bytes(slots) ? SlotForm::bitmap
                                                                : SlotForm::deltas;
}

void put_slots(MessageWriter& w, std::span<const std::uint32_t> slots) {
    const SlotForm form = smaller_form(slots);
    w.put(static_cast<std::uint8_t>(form));
    if (form == SlotForm::deltas) {
        w.put(static_cast<std::uint32_t>(slots.size()));
        for (std::size_t i = 0; i < slots.size(); ++i)
            put_varint(w, i == 0 ? slots[0] : slots[i] - slots[i - 1]);
        return;
    }
    const std::size_t n = slots.empty() ? 0 : std::size_t{slots.back()} + 1;
    w.put(static_cast<std::uint32_t>(n));
    std::vector<std::uint8_t> bits((n + 7) / 8, 0);
    for (const std::uint32_t s : slots) bits[s / 8] |= static_cast<std::uint8_t>(1u << (s % 8));
    for (const std::uint8_t b : bits) w.put(b);
}

std::vector<std::uint32_t> get_slots(MessageReader& r) {
    const auto form = r.get<std::uint8_t>();
    std::vector<std::uint32_t> slots;
    if (form == static_cast<std::uint8_t>(SlotForm::bitmap))
        slots = get_bitmap(r);
    else if (form == static_cast<std::uint8_t>(SlotForm::deltas))
        slots = get_deltas(r);
    else
        r.fail("form: expected 0 (bitmap) or 1 (deltas), got " + std::to_string(form));
    // The encoder's choice only, so that a set has one encoding.
    if (static_cast<std::uint8_t>(smaller_form(slots)) != form)
        r.fail("form: " + std::to_string(form) + ", but the slots take " +
               std::to_string(bitmap_form_bytes(slots)) + " bytes as a bitmap and " +
               std::to_string(deltas_form_bytes(slots)) +
               " as deltas: expected the smaller (a tie: the bitmap)");
    return slots;
}

}  // namespace isowall::remote
