#pragma once
// Cells taken by propagation in the current frame, with the id of the group that took each:
// a bitset for the hot "visited?" test (one bit per cell: 7.6 MB for 512x512x234), and a hash map
// only for the ids of the visited cells, which are few.
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "common/extract/edge_cache.h"

namespace isowall {

class VisitedCells {
  public:
    explicit VisitedCells(glm::ivec3 cell_dims = glm::ivec3(0)) { reset(cell_dims); }

    void reset(glm::ivec3 cell_dims) {
        dims_ = cell_dims;
        const std::size_t n = static_cast<std::size_t>(cell_dims.x) * cell_dims.y * cell_dims.z;
        bits_.assign((n + 63) / 64, 0);
        groups_.reset(1024);
        count_ = 0;
    }
    std::uint64_t index(glm::ivec3 c) const {
        return (static_cast<std::uint64_t>(c.z) * static_cast<std::uint64_t>(dims_.y) +
                static_cast<std::uint64_t>(c.y)) *
                   static_cast<std::uint64_t>(dims_.x) +
               static_cast<std::uint64_t>(c.x);
    }
    bool contains(glm::ivec3 c) const {
        const auto i = index(c);
        return (bits_[i >> 6] >> (i & 63)) & 1;
    }
    // Marks c as taken by `group`; false when it was already taken.
    bool insert(glm::ivec3 c, std::uint32_t group) {
        const auto i = index(c);
        std::uint64_t& word = bits_[i >> 6];
        const std::uint64_t bit = std::uint64_t{1} << (i & 63);
        if (word & bit) return false;
        word |= bit;
        *groups_.find_or_insert(i).first = group;
        ++count_;
        return true;
    }
    // The group that took c (c must be visited).
    std::uint32_t group_of(glm::ivec3 c) { return *groups_.find_or_insert(index(c)).first; }
    std::size_t size() const { return count_; }
    glm::ivec3 dims() const { return dims_; }

  private:
    glm::ivec3 dims_{0};
    std::vector<std::uint64_t> bits_;
    EdgeVertexCache groups_;
    std::size_t count_ = 0;
};

}  // namespace isowall
