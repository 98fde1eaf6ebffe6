#include "store/source_pages.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>

namespace isowall::store {

// Lets the kernel drop a memory-mapped source's pages of [begin, end) from this process, so an
// import's resident memory stays at a slab, not the volume (they are re-read if touched again).
void release_source_pages(const std::byte* begin, const std::byte* end) {
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    const auto b = (reinterpret_cast<std::uintptr_t>(begin) + page - 1) / page * page;
    const auto e = reinterpret_cast<std::uintptr_t>(end) / page * page;
    if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_DONTNEED);
}

// Reads [begin, end) of a memory-mapped source into memory and maps it, in one call rather than
// a fault a page (MADV_POPULATE_READ, Linux 5.14; older kernels fault the pages in as read).
void populate_source_pages(const std::byte* begin, const std::byte* end) {
#ifdef MADV_POPULATE_READ
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    const auto b = reinterpret_cast<std::uintptr_t>(begin) / page * page;
    const auto e = reinterpret_cast<std::uintptr_t>(end);
    if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_POPULATE_READ);
#else
    (void)begin, (void)end;
#endif
}

}  // namespace isowall::store

namespace isowall::store {

VolumePlanes::VolumePlanes(const Volume& volume) : v_(volume) {}

VolumePlanes::~VolumePlanes() {
    if (reading_.joinable()) reading_.join();
    if (v_.mapped()) release_source_pages(at(released_), at(v_.dims().z));
}

std::span<const std::byte> VolumePlanes::planes(int z0, int z1) {
    if (reading_.joinable()) reading_.join();
    if (v_.mapped()) {
        if (z0 > released_) release_source_pages(at(released_), at(z0)), released_ = z0;
        // This slab is read now if the thread has not read it; the next one on the thread.
        populate_source_pages(at(z0), at(z1));
        const int z2 = std::min(z1 + (z1 - z0), v_.dims().z);
        if (z1 < z2) reading_ = std::thread(populate_source_pages, at(z1), at(z2));
    }
    return {at(z0), std::size_t(z1 - z0) * plane_bytes()};
}

}  // namespace isowall::store
