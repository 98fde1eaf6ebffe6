#pragma once
// The interpolant cache (section 3.3.4): maps a cell edge to the vertex already made on it, so
// neighbouring cells share vertices instead of interpolating them again. Open addressing with
// linear probing: the keys are dense integers and lookups dominate, where std::unordered_map
// would allocate a node per vertex.
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

namespace isowall {

class EdgeVertexCache {
  public:
    explicit EdgeVertexCache(std::size_t expected = 1024) { reset(expected); }

    // The slot for `key` and whether it was just inserted (its value is then for the caller to
    // set).
    std::pair<std::uint32_t*, bool> find_or_insert(std::uint64_t key) {
        if (2 * (size_ + 1) > keys_.size()) grow();
        std::size_t i = hash(key) & mask_;
        for (;;) {
            if (keys_[i] == key) return {&values_[i], false};
            if (keys_[i] == kEmpty) {
                keys_[i] = key;
                ++size_;
                return {&values_[i], true};
            }
            i = (i + 1) & mask_;
        }
    }
    void clear() {
        std::fill(keys_.begin(), keys_.end(), kEmpty);
        size_ = 0;
    }
    void reset(std::size_t expected) {
        std::size_t cap = 16;
        while (cap < 2 * expected) cap <<= 1;
        keys_.assign(cap, kEmpty);
        values_.assign(cap, 0);
        mask_ = cap - 1;
        size_ = 0;
    }
    std::size_t size() const { return size_; }

  private:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
    static std::uint64_t hash(std::uint64_t k) {
        k ^= k >> 33;
        k *= 0xff51afd7ed558ccdULL;
        k ^= k >> 33;
        return k;
    }
    void grow() {
        std::vector<std::uint64_t> keys = std::move(keys_);
        std::vector<std::uint32_t> values = std::move(values_);
        reset(keys.size());
        for (std::size_t i = 0; i < keys.size(); ++i)
            if (keys[i] != kEmpty) *find_or_insert(keys[i]).first = values[i];
    }
    std::vector<std::uint64_t> keys_;
    std::vector<std::uint32_t> values_;
    std::size_t mask_ = 0;
    std::size_t size_ = 0;
};

// Vertex caches hand emit_meta_cell a slot per cell edge: find_or_insert(lower voxel, axis)
// returns the slot and whether it is new (the caller then stores the vertex id in it). The slot
// pointer is valid until the next call.

// Any set of cells (one propagation pass, say): one hash lookup per edge.
class HashEdgeCache {
  public:
    HashEdgeCache(glm::ivec3 dims, std::size_t expected = 1024) : dims_(dims), map_(expected) {}
    // `axis` + 3 * level: up to kKinds kinds of edge per voxel.
    static constexpr std::uint64_t kKinds = 12;
    std::pair<std::uint32_t*, bool> find_or_insert(glm::ivec3 p, int axis) {
        const auto voxel = (static_cast<std::uint64_t>(p.z) * static_cast<std::uint64_t>(dims_.y) +
                            static_cast<std::uint64_t>(p.y)) *
                               static_cast<std::uint64_t>(dims_.x) +
                           static_cast<std::uint64_t>(p.x);
        return map_.find_or_insert(voxel * kKinds + static_cast<std::uint64_t>(axis));
    }
    void clear() { map_.clear(); }
    std::size_t size() const { return map_.size(); }

  private:
    glm::ivec3 dims_;
    EdgeVertexCache map_;
};

// Whole-volume extraction: an edge belongs to the 4x4x4 brick of its lower voxel, and each
// touched brick gets a dense table of its 192 edges. The edges of a brick's cells fall in that
// brick or its seven upper neighbours, so begin_brick() lets the cache resolve those eight tables
// once per brick instead of hashing once per edge (a likely cache miss on a large surface).
class BrickEdgeCache {
  public:
    explicit BrickEdgeCache(glm::ivec3 dims) : bricks_((dims >> kLog2) + 1), index_(1024) {}

    // Cells from now on lie in brick b (a brick of the octree's leaf level).
    void begin_brick(glm::ivec3 b) {
        current_ = b;
        near_.fill(kNone);
    }
    std::pair<std::uint32_t*, bool> find_or_insert(glm::ivec3 p, int axis) {
        const glm::ivec3 d = (p >> kLog2) - current_;  // each component 0 or 1
        const int k = d.x | d.y << 1 | d.z << 2;
        std::uint32_t& table = near_[static_cast<std::size_t>(k)];
        if (table == kNone) table = table_for(current_ + d);
        const glm::ivec3 l = p & (kSide - 1);
        std::uint32_t& e =
            tables_[table]
                   [static_cast<std::size_t>(((l.z * kSide + l.y) * kSide + l.x) * 3 + axis)];
        return {&e, e == kNone};
    }

  private:
    static constexpr int kLog2 = 2;  // matches OctreeShape::kLeafLog2
    static constexpr int kSide = 1 << kLog2;
    static constexpr std::uint32_t kNone = ~std::uint32_t{0};

    std::uint32_t table_for(glm::ivec3 b) {
        const auto id = (static_cast<std::uint64_t>(b.z) * static_cast<std::uint64_t>(bricks_.y) +
                         static_cast<std::uint64_t>(b.y)) *
                            static_cast<std::uint64_t>(bricks_.x) +
                        static_cast<std::uint64_t>(b.x);
        auto [slot, inserted] = index_.find_or_insert(id);
        if (inserted) {
            *slot = static_cast<std::uint32_t>(tables_.size());
            tables_.emplace_back();
            tables_.back().fill(kNone);
        }
        return *slot;
    }

    glm::ivec3 bricks_;
    EdgeVertexCache index_;
    std::vector<std::array<std::uint32_t, kSide * kSide * kSide * 3>> tables_;
    glm::ivec3 current_{0};
    std::array<std::uint32_t, 8> near_{};
};

}  // namespace isowall
