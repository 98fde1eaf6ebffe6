#pragma once
// Units (cells, or meta-cells of adaptive resolution) taken by propagation in the current frame,
// with the id of the group that took each. A unit of level L (2^L cells a side, its first cell a
// multiple of 2^L) is recorded once, in the grid of level L at its first cell >> L: units
// partition the volume (extract/adaptive.h), so whoever asks about a unit asks about its
// first cell and level, and marking a meta-cell of 4^3 cells costs one write, not 64.
//
// Each level's grid is paged by bricks of 8^3 units: a table with one page number per brick
// (4 bytes per 512 units: 31 MB for the cells of 2048x2048x936, 245 MB for 4096x4096x1872, an
// eighth of that per level up), made when a frame first uses the level, and a page of 512 group
// ids for each brick that holds a taken unit. The table holds page + 1, so that 0 is "no page"
// and a new table is calloc's zero pages: the kernel maps them as the frame first writes them,
// where filling a table with a free mark wrote all of it before the first ray (0.3-0.45 s at
// 4096x4096x1872) and kept it resident. A lookup is two loads and no hash. Pages come from a pool
// kept across frames, and a new frame forgets only the bricks the last one touched, where a bit per
// cell would clear 490 MB at 2048^2 x 936 and a hash would cost a probe per cell.
//
// Threads: insert(), contains() and group_of() may run on any number of threads at once (the
// workers of one frame). A unit is claimed by a compare-and-swap of its slot, so exactly one
// insert of it returns true; a brick's page is added under a lock (once per brick), published by
// a release store of its number that readers acquire. reset() runs alone, between frames.
#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <new>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace isowall {

class VisitedCells {
  public:
    // Never a group id: the mark of a free slot.
    static constexpr std::uint32_t kFree = ~std::uint32_t{0};
    static constexpr int kLevels = 4;  // 0 .. kMaxMetaLevel (adaptive.h)

    explicit VisitedCells(glm::ivec3 cell_dims = glm::ivec3(0), int max_level = 0) {
        reset(cell_dims, max_level);
    }

    // Forgets every unit; `cell_dims` may differ from the last frame's. Units of levels up to
    // `max_level` may be inserted until the next reset.
    void reset(glm::ivec3 cell_dims, int max_level = 0) {
        if (cell_dims != dims_) {
            dims_ = cell_dims;
            for (Grid& g : grids_) g = Grid{};
        } else {
            for (Grid& g : grids_) {
                for (const std::size_t b : g.touched) g.pages[b] = kNoPage;
                g.touched.clear();
            }
        }
        for (int l = 0; l <= max_level && l < kLevels; ++l)
            if (grid(l).pages.empty()) make(grid(l), l);
        used_ = 0;
        count_.store(0, std::memory_order_relaxed);
    }
    // A cell's index in x-fastest order (a key for per-cell sets).
    std::uint64_t index(glm::ivec3 c) const {
        return (static_cast<std::uint64_t>(c.z) * static_cast<std::uint64_t>(dims_.y) +
                static_cast<std::uint64_t>(c.y)) *
                   static_cast<std::uint64_t>(dims_.x) +
               static_cast<std::uint64_t>(c.x);
    }
    // Whether the unit of `level` whose first cell is `c` was taken.
    bool contains(glm::ivec3 c, int level = 0) const { return slot(c, level) != kFree; }
    // Marks the unit of `level` (at most the last reset's max_level) whose first cell is c as
    // taken by `group` (not kFree) and counts it; false when it was taken already.
    bool insert(glm::ivec3 c, std::uint32_t group, int level = 0) {
        if (!claim(c, group, level)) return false;
        add_count(std::size_t{1} << (3 * level));
        return true;
    }
    // insert() without the count, for a caller that claims many units (a propagation pass) and
    // adds its count once with add_count(): one counter bumped by every thread at every unit
    // would move its cache line between the cores each time.
    bool claim(glm::ivec3 c, std::uint32_t group, int level = 0) {
        Grid& g = grid(level);
        const glm::ivec3 u = c >> level;
        const std::size_t b = g.brick(u);
        std::atomic_ref<std::uint32_t> page_ref(g.pages[b]);
        std::uint32_t entry = page_ref.load(std::memory_order_acquire);
        if (entry == kNoPage) {
            const std::lock_guard<std::mutex> lock(grow_);
            entry = page_ref.load(std::memory_order_relaxed);
            if (entry == kNoPage) {
                entry = take_page() + 1;
                g.touched.push_back(b);
                page_ref.store(entry, std::memory_order_release);
            }
        }
        std::atomic_ref<std::uint32_t> id(page_at(entry - 1)[local(u)]);
        std::uint32_t expected = kFree;
        return id.compare_exchange_strong(expected, group, std::memory_order_acq_rel);
    }
    // Adds `cells` to size(): the cells of units that claim() took.
    void add_count(std::size_t cells) { count_.fetch_add(cells, std::memory_order_relaxed); }
    // The group that took the unit of `level` whose first cell is c, or kFree.
    std::uint32_t group_of(glm::ivec3 c, int level = 0) const { return slot(c, level); }
    // Cells covered by the taken units (a meta-cell counts all of its cells), as counted so far.
    std::size_t size() const { return count_.load(std::memory_order_relaxed); }
    glm::ivec3 dims() const { return dims_; }

  private:
    static constexpr int kLog2 = 3;
    static constexpr int kSide = 1 << kLog2;
    static constexpr std::size_t kPage = std::size_t{1} << (3 * kLog2);
    using Page = std::array<std::uint32_t, kPage>;
    // The pool: chunks of pages that never move once made, found through a fixed directory
    // (16 M pages at most: 32 GB of ids, more than any frame takes).
    static constexpr std::size_t kChunkPages = 1024;
    static constexpr std::size_t kChunks = 16384;

    static constexpr std::uint32_t kNoPage = 0;  // in a table: the brick has no page

    // A table of zeros from calloc: large ones come as untouched zero pages.
    struct Table {
        struct Free {
            void operator()(std::uint32_t* p) const { std::free(p); }
        };
        std::unique_ptr<std::uint32_t[], Free> entries;
        std::size_t size = 0;
        bool empty() const { return size == 0; }
        std::uint32_t& operator[](std::size_t i) { return entries[i]; }
        const std::uint32_t& operator[](std::size_t i) const { return entries[i]; }
    };

    struct Grid {
        glm::ivec3 bricks{0};
        Table pages;                       // per brick: its page in the pool + 1, or kNoPage
        std::vector<std::size_t> touched;  // bricks with a page, to forget at reset
        std::size_t brick(glm::ivec3 u) const {
            const glm::ivec3 b = u >> kLog2;
            return (static_cast<std::size_t>(b.z) * static_cast<std::size_t>(bricks.y) +
                    static_cast<std::size_t>(b.y)) *
                       static_cast<std::size_t>(bricks.x) +
                   static_cast<std::size_t>(b.x);
        }
    };

    Grid& grid(int level) { return grids_[static_cast<std::size_t>(level)]; }
    const Grid& grid(int level) const { return grids_[static_cast<std::size_t>(level)]; }
    void make(Grid& g, int level) const {
        const int side = kSide << level;  // cells a brick of this level spans
        g.bricks = (glm::max(dims_, glm::ivec3(0)) + side - 1) / side;
        const std::size_t n = static_cast<std::size_t>(g.bricks.x) *
                              static_cast<std::size_t>(g.bricks.y) *
                              static_cast<std::size_t>(g.bricks.z);
        auto* p = static_cast<std::uint32_t*>(std::calloc(std::max<std::size_t>(n, 1), 4));
        if (!p) throw std::bad_alloc();
        g.pages.entries.reset(p);
        g.pages.size = n;
    }
    Page& page_at(std::uint32_t page) const {
        return chunks_[page / kChunkPages][page % kChunkPages];
    }
    // Under grow_.
    std::uint32_t take_page() {
        const std::size_t chunk = used_ / kChunkPages;
        // Not zeroed: each page is filled with kFree as it is taken, so a chunk costs only the
        // pages a frame takes (zeroing 2 MB per chunk, and faulting all of it in, was most of a
        // wall rank's first propagation pass: about 5 ms on every rank that helps).
        if (!chunks_[chunk]) chunks_[chunk] = std::make_unique_for_overwrite<Page[]>(kChunkPages);
        const auto page = static_cast<std::uint32_t>(used_++);
        page_at(page).fill(kFree);
        return page;
    }
    static std::size_t local(glm::ivec3 u) {
        const glm::ivec3 l = u & (kSide - 1);
        return static_cast<std::size_t>((l.z << (2 * kLog2)) | (l.y << kLog2) | l.x);
    }
    std::uint32_t slot(glm::ivec3 c, int level) const {
        const Grid& g = grid(level);
        if (g.pages.empty()) return kFree;
        const glm::ivec3 u = c >> level;
        // atomic_ref needs a non-const object; the load does not write.
        auto& entry = const_cast<std::uint32_t&>(g.pages[g.brick(u)]);
        const std::uint32_t page_plus_1 =
            std::atomic_ref<std::uint32_t>(entry).load(std::memory_order_acquire);
        if (page_plus_1 == kNoPage) return kFree;
        return std::atomic_ref<std::uint32_t>(page_at(page_plus_1 - 1)[local(u)])
            .load(std::memory_order_acquire);
    }

    glm::ivec3 dims_{-1};
    std::array<Grid, kLevels> grids_;
    std::unique_ptr<std::unique_ptr<Page[]>[]> chunks_ =
        std::make_unique<std::unique_ptr<Page[]>[]>(kChunks);
    std::size_t used_ = 0;  // pages handed out this frame (under grow_)
    std::atomic<std::size_t> count_{0};
    std::mutex grow_;
};

}  // namespace isowall
