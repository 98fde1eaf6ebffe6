#pragma once
// The cached-group slots a VisibleMsg names (case 4), on the wire. A slot is a group's
// index in the client's cache of the current generation (GroupMsg::cache_gen), so a list of slots
// costs bits, not the 25 bytes of a GroupKey. Two forms, the encoder picks the smaller (a tie goes
// to the bitmap):
//   form 0, bitmap: bit count u32 n (the highest slot + 1), then ceil(n/8) bytes; bit i is slot i,
//           least significant bit first within a byte; bits >= n in the last byte are zero;
//   form 1, deltas: count u32 k, then k unsigned LEB128 varints: the first slot, then each gap to
//           the next (>= 1); a varint takes at most 5 bytes and holds less than 2^32.
// A dense set (the seed rays name most cached groups) fits the bitmap, a sparse one over a large
// range (a few groups named one by one, GroupSink::seen) the deltas.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "remote/view_protocol.h"  // kMaxVisibleKeys: every slot is below it
#include "wire/wire.h"

namespace isowall::remote {

// The longest varint of a u32: 7 bits a byte.
inline constexpr std::size_t kMaxVarintBytes = 5;

enum class SlotForm : std::uint8_t { bitmap = 0, deltas = 1 };

// Unsigned LEB128: 7 bits a byte, low bits first, the high bit set on every byte but the last.
void put_varint(MessageWriter& w, std::uint32_t v);
std::size_t varint_bytes(std::uint32_t v);
// Throws WireError naming `field` for a varint past the message's end, longer than 5 bytes or
// of 2^32 or more.
std::uint32_t get_varint(MessageReader& r, const std::string& field);

// The bytes each form takes after the version and request id (the form byte included), for
// strictly ascending slots.
std::size_t bitmap_form_bytes(std::span<const std::uint32_t> slots);
std::size_t deltas_form_bytes(std::span<const std::uint32_t> slots);
SlotForm smaller_form(std::span<const std::uint32_t> slots);

// Writes the form byte and the smaller form. `slots` must be strictly ascending (the encoders
// write what they are given: gaps are taken modulo 2^32, and a bitmap merges repeats).
void put_slots(MessageWriter& w, std::span<const std::uint32_t> slots);
// Reads what put_slots writes; strictly ascending, each < kMaxVisibleKeys. Only the encoder's
// bytes are accepted (the smaller form, n = the highest slot + 1, shortest varints), so a set has
// one encoding. Errors name "slots" (or "slots[i]", or "form"), and no count is trusted before
// it is checked against the bytes left.
std::vector<std::uint32_t> get_slots(MessageReader& r);

}  // namespace isowall::remote
