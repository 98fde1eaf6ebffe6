#pragma once
// A group: what one propagation pass (or one refinement) hands the renderer, and the key that
// names it for caches.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <ostream>
#include <vector>

#include <glm/vec3.hpp>

#include "core/mesh.h"

namespace isowall {

// Names a group by what started it: the seed unit, its level and the isovalue. Stable across
// frames and ranks (no group id, no pointer), so a cache can find a group again. It names the
// pass, not its contents: which cells a pass takes also depends on the cells earlier passes took
// and on the propagation parameters, and a cache that keeps meshes must allow for that.
// `refinement` tells a meta-cell's refinement from the pass seeded at the same meta-cell, which
// has the same seed, level and isovalue but other triangles.
struct GroupKey {
    glm::ivec3 seed{0};
    int level = 0;
    double iso = 0;
    bool refinement = false;
};

inline bool operator==(const GroupKey& a, const GroupKey& b) {
    return a.seed == b.seed && a.level == b.level && a.iso == b.iso && a.refinement == b.refinement;
}

// Hashes the fields an operator== compares; -0.0 and 0.0 compare equal, so they hash alike.
inline std::size_t hash_value(const GroupKey& k) {
    const double iso = k.iso == 0 ? 0.0 : k.iso;
    std::uint64_t h = std::bit_cast<std::uint64_t>(iso);
    auto mix = [&h](std::uint64_t x) {
        // boost::hash_combine's constant, widened: spreads small integers over every bit.
        h ^= x + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    };
    mix(static_cast<std::uint32_t>(k.seed.x));
    mix(static_cast<std::uint32_t>(k.seed.y));
    mix(static_cast<std::uint32_t>(k.seed.z));
    mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.level)) << 1 |
        (k.refinement ? 1u : 0u));
    return static_cast<std::size_t>(h);
}

inline std::ostream& operator<<(std::ostream& os, const GroupKey& k) {
    return os << "GroupKey{seed=(" << k.seed.x << "," << k.seed.y << "," << k.seed.z
              << ") level=" << k.level << " iso=" << k.iso << (k.refinement ? " refinement" : "")
              << "}";
}

struct Group {
    std::uint32_t id = 0;
    glm::ivec3 seed{0};
    int level = 0;   // the resolution of the pass: 0 cells, i >= 1 meta-cells of 2^i cells per side
    double iso = 0;  // the isovalue the group was extracted at
    Mesh mesh;       // object space
    // The cells this pass took, in BFS order; at level >= 1 the first cell of each meta-cell.
    std::vector<glm::ivec3> cells;
    // The level of each unit in `cells` where a pass went on into units of other levels
    // (adaptive resolution's boundaries); empty: every unit is at `level`.
    std::vector<std::uint8_t> cell_levels;
    int level_of_cell(std::size_t i) const { return cell_levels.empty() ? level : cell_levels[i]; }
    // A refinement (adaptive resolution): the full-resolution triangles of the meta-cell of
    // `level` at `seed`, drawn over its own because a ray saw the surface there that they miss.
    // It takes no cells: they stay with the pass that took the meta-cell, if any.
    bool refinement = false;
    // The units the pass left out because it was full (PropagationParams::keep_frontier): the
    // rim it would have gone on over, unvisited when the pass ended. Not part of the mesh.
    std::vector<glm::ivec3> frontier;

    GroupKey key() const { return {seed, level, iso, refinement}; }
};

}  // namespace isowall

template <>
struct std::hash<isowall::GroupKey> {
    std::size_t operator()(const isowall::GroupKey& k) const { return isowall::hash_value(k); }
};
