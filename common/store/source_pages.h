#pragma once
// An import's memory-mapped source, a slab at a time: read ahead of the slab being compressed,
// and let go once it is written (store_writer.cpp).
#include <cstddef>

namespace isowall::store {

// Lets the kernel drop a memory-mapped source's pages of [begin, end) from this process.
void release_source_pages(const std::byte* begin, const std::byte* end);
// Reads [begin, end) of a memory-mapped source into memory and maps it.
void populate_source_pages(const std::byte* begin, const std::byte* end);

}  // namespace isowall::store
