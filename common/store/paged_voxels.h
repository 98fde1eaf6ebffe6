#pragma once
// A store's voxels as one x-fastest array that is filled on first touch, under a memory cap.
//
// The engine reads voxels through a plain pointer (VolumeView), in its hottest loops, so the
// pager does not change how they are read: it reserves the whole array as address space and
// registers it with userfaultfd. The first read of a span (kSpanBytes of consecutive rows) stops
// that thread in the kernel; the pager's thread decompresses the chunks the span needs, copies
// the span in (UFFDIO_COPY, which wakes the reader) and counts it. When the spans and the chunk
// cache pass the cap, the oldest spans are dropped (MADV_DONTNEED) and fault again if read
// again. A reader waits only for its own span; voxels already in memory cost nothing extra.
//
// The order of eviction is first-in first-out: a fault is the only access the pager sees (a read
// of a resident page does not reach it), so it cannot know which span was used last. A span that
// is still in use when dropped is read again (counted as a refault).
//
// A chunk that cannot be read or fails its checksum while a frame runs cannot be reported to the
// thread that touched it (it is stopped inside a memory read), so the pager prints the chunk's
// error line and ends the process with exit status 1: a picture is never drawn from garbage.
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "common/store/store_reader.h"

namespace isowall::store {

struct PagingStats {
    std::uint64_t faults = 0;       // spans filled (first touches and refaults)
    std::uint64_t refaults = 0;     // spans filled again after being dropped
    std::uint64_t evictions = 0;    // spans dropped to stay under the cap
    std::uint64_t chunks_read = 0;  // chunks read from disk and decompressed
    std::uint64_t chunk_hits = 0;   // chunk needs met by the chunk cache
    std::uint64_t bytes_read = 0;   // compressed bytes read from disk
    std::uint64_t peak_bytes = 0;   // most resident at once: spans + chunk cache
    std::uint64_t resident_bytes = 0;
    double fill_s = 0;  // time the pager's thread spent filling spans
};

class PagedVoxels {
  public:
    static constexpr std::size_t kSpanBytes = 256 * 1024;

    // Reserves the array and starts the pager's thread. Throws std::runtime_error naming the
    // reason when userfaultfd is not available here (an old kernel, a seccomp filter), and
    // InputError when `cap_bytes` cannot hold a few chunks and spans of this store.
    PagedVoxels(std::shared_ptr<const StoreReader> reader, std::uint64_t cap_bytes);
    ~PagedVoxels();
    PagedVoxels(const PagedVoxels&) = delete;
    PagedVoxels& operator=(const PagedVoxels&) = delete;

    std::span<const std::byte> bytes() const { return {base_, voxel_bytes_}; }
    std::uint64_t cap() const { return cap_; }
    const StoreReader& reader() const { return *reader_; }
    PagingStats stats() const;
    // The least cap that works for `layout`: eight of its largest chunks and eight spans.
    static std::uint64_t min_cap(const StoreLayout& layout);

  private:
    struct State;
    void serve();

    std::shared_ptr<const StoreReader> reader_;
    std::uint64_t cap_ = 0;
    std::byte* base_ = nullptr;
    std::size_t voxel_bytes_ = 0, map_bytes_ = 0;
    int uffd_ = -1, stop_fd_ = -1;
    std::unique_ptr<State> state_;
};

// A one-line summary of `s` for `render`: "bricks: 312 read (41.2 MiB from disk), 2 cached ..."
std::string paging_line(const PagingStats& s, std::uint64_t cap);

}  // namespace isowall::store
