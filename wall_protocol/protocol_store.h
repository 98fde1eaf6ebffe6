#pragma once
// The decoders of the store messages (wall_protocol/protocol_store.cpp), for decode_message only:
// callers decode through decode_message, which picks one by tag.
#include <cstddef>
#include <span>

#include "wall_protocol/protocol.h"

namespace isowall::store_wire {

StoreAskMsg decode_store_ask(std::span<const std::byte> bytes);
StoreMetaMsg decode_store_meta(std::span<const std::byte> bytes);
StorePartMsg decode_store_part(std::span<const std::byte> bytes);

}  // namespace isowall::store_wire
