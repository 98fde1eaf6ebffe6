#pragma once
// A store's voxels as one array of bricks that is filled on first touch, under a memory cap.
//
// The engine reads voxels through a plain pointer (VolumeView, bricked layout), in its hottest
// loops, so the pager does not change how they are read: it reserves the whole array as address
// space and registers it with userfaultfd. The first read of a brick stops that thread in the
// kernel; the pager's thread reads and decompresses the brick's chunk straight into a buffer,
// copies it in (UFFDIO_COPY, which wakes the reader) and counts it. Past the cap, the oldest
// bricks are dropped (MADV_DONTNEED) and fault again if read again. A reader waits only for its
// own brick (behind the faults queued before it); voxels in memory cost nothing extra.
//
// Read-ahead: the first touch of a brick asks the kernel to read the chunks of those of its six
// face neighbours the surface may pass through (want(): the octree's active bricks at the
// frame's isovalue) into the page cache, on a thread of its own (posix_fadvise), since rays and
// propagation go on into the bricks beside the one they are in. It costs no share of the cap: a
// hinted chunk is read from disk but not decompressed until it is touched. Without want(), or
// for a neighbour off the surface, no hint: on the 4x CT head, hinting every face neighbour read
// 2.2 chunks for each one used and made a cold frame slower.
//
// The order of eviction is first-in first-out: a fault is the only access the pager sees (a read
// of a resident page does not reach it), so it cannot know which brick was used last. A brick
// still in use when dropped is read again (counted as a refault).
//
// A chunk that cannot be read or fails its checksum while a frame runs cannot be reported to the
// thread that touched it (it is stopped inside a memory read), so the pager ends the process with
// the chunk's error line (core/fatal.h: exit status 1, or the wall's failure path on a rank): a
// picture is never drawn from garbage.
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "store/store_reader.h"

namespace isowall::store {

struct PagingStats {
    std::uint64_t faults = 0;      // bricks read in (first touches and refaults)
    std::uint64_t refaults = 0;    // bricks read again after being dropped
    std::uint64_t evictions = 0;   // bricks dropped to stay under the cap
    std::uint64_t bytes_read = 0;  // compressed bytes read from disk
    std::uint64_t peak_bytes = 0;  // most bricks' bytes resident at once
    std::uint64_t hinted = 0;      // chunks asked to be read ahead
    std::uint64_t resident_bytes = 0;
    double fill_s = 0;  // time the pager's threads spent reading and installing bricks
    double cpu_s = 0;   // their CPU time (CLOCK_THREAD_CPUTIME_ID), for traces' io stage
};

class PagedVoxels {
  public:
    // Reserves the array and starts the pager's thread. Throws std::runtime_error naming the
    // reason when userfaultfd is not available here (an old kernel, a seccomp filter), and
    // InputError when `cap_bytes` cannot hold a few chunks and spans of this store.
    // read_ahead false: no read-ahead thread (for studies: ISOWALL_READ_AHEAD=off, open_store.h).
    PagedVoxels(std::shared_ptr<const StoreReader> reader, std::uint64_t cap_bytes,
                bool read_ahead = true);
    ~PagedVoxels();
    PagedVoxels(const PagedVoxels&) = delete;
    PagedVoxels& operator=(const PagedVoxels&) = delete;

    std::span<const std::byte> bytes() const { return {base_, map_bytes_}; }
    std::uint64_t cap() const { return cap_; }
    const StoreReader& reader() const { return *reader_; }
    PagingStats stats() const;
    // The bricks worth reading ahead from now on (Volume::hint_bricks), one byte per brick.
    void want(std::vector<std::uint8_t> bricks) const;
    // The least cap that works for `layout`: sixteen bricks.
    static std::uint64_t min_cap(const StoreLayout& layout);

  private:
    struct State;
    // A pager thread: waits for faults, reads and installs their bricks, keeps the cap.
    void serve();
    void install(std::size_t brick, const std::vector<std::byte>& buffer);
    // The read-ahead thread: hints the chunks queued by hint_neighbours().
    void read_ahead();
    void hint_neighbours(std::size_t brick);
    void drop_to_cap(std::size_t keep);

    std::shared_ptr<const StoreReader> reader_;
    std::uint64_t cap_ = 0;
    std::byte* base_ = nullptr;
    std::size_t brick_bytes_ = 0, map_bytes_ = 0;
    int uffd_ = -1, stop_fd_ = -1;
    std::unique_ptr<State> state_;
};

// Empty when this process can page with userfaultfd; otherwise why not (an old kernel, a seccomp
// filter such as a container's default one). Without it a store is read whole (open_store.h).
std::string paging_unavailable();

// A one-line summary of `s` for `render`: "bricks: 312 read (41.2 MiB from disk), ..."
std::string paging_line(const PagingStats& s, std::uint64_t cap);

}  // namespace isowall::store
