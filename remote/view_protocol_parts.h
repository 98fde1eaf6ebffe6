#pragma once
// Internal to the view protocol (view_protocol.cpp, view_protocol_groups.cpp): the pieces the
// messages of both files read and write, and the group messages' encoders and decoders, which
// view_protocol.cpp's dispatch calls.
#include <cstddef>
#include <span>
#include <vector>

#include "extract/group.h"
#include "remote/view_protocol.h"
#include "wire/wire.h"

namespace isowall::remote {

namespace protocol_parts {
void put_group_key(MessageWriter& w, const GroupKey& k);
// A group key's fields; errors name them "key.level" and so on.
GroupKey get_group_key(MessageReader& r);
// A u8 of 0 or 1; WireError naming `field` otherwise.
bool get_flag(MessageReader& r, const char* field);
}  // namespace protocol_parts

std::vector<std::byte> encode(const GroupMsg& m);
GroupMsg decode_group_msg(std::span<const std::byte> bytes);
std::vector<std::byte> encode(const VisibleMsg& m);
VisibleMsg decode_visible(std::span<const std::byte> bytes);
std::vector<std::byte> encode(const ExactMsg& m);
ExactMsg decode_exact(std::span<const std::byte> bytes);

}  // namespace isowall::remote
