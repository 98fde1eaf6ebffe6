#pragma once
// The interpolant cache (section 3.3.4): maps a cell edge to the vertex already made on it, so
// neighbouring cells share vertices instead of interpolating them again. Open addressing with
// linear probing: the keys are dense integers and lookups dominate, where std::unordered_map
// would allocate a node per vertex.
#include <cstdint>
#include <utility>
#include <vector>

namespace isowall {

class EdgeVertexCache {
public:
    explicit EdgeVertexCache(std::size_t expected = 1024) { reset(expected); }

    // The slot for `key` and whether it was just inserted (its value is then for the caller to set).
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

}  // namespace isowall
