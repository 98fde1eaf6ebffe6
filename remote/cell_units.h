#pragma once
// The units of a `cells` group (remote/cell_codec.h) and how they travel: a unit is a cell or a
// meta-cell of a level (its first cell, a multiple of 2^level), sorted by level and then by index
// in that level's grid of units, sent as LEB128 gaps between those indices. Internal to the codec.
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "remote/byte_io.h"

namespace isowall::remote::cells {

// A meta-cell of level 16 spans 65536 cells a side: past what kMaxCellBoxVoxels lets a group hold.
inline constexpr int kMaxUnitLevel = 16;

struct Unit {
    glm::ivec3 base{0};  // its first cell, a multiple of 2^level on each axis
    int level = 0;
};

// Units per axis at `level` in a volume of `dims` voxels.
glm::ivec3 unit_grid(glm::ivec3 dims, int level);
std::uint64_t linear(glm::ivec3 p, glm::ivec3 d);
glm::ivec3 unlinear(std::uint64_t i, glm::ivec3 d);
// All eight corners inside a volume of `dims` voxels, and aligned to its level.
bool complete(const Unit& u, glm::ivec3 dims);
// Sorted by level, then by index in that level's grid of units: the order both sides triangulate.
void sort_units(std::vector<Unit>& units, glm::ivec3 dims);

// The box of voxels the units read: their extent, one voxel around it, inside the volume.
struct VoxelBox {
    glm::ivec3 origin{0}, size{0};
    std::uint64_t voxels() const {
        return static_cast<std::uint64_t>(size.x) * static_cast<std::uint64_t>(size.y) *
               static_cast<std::uint64_t>(size.z);
    }
};
VoxelBox box_of(const std::vector<Unit>& units, glm::ivec3 dims);

// Sorted units (sort_units) as bucket count u8, then per level: level u8, count u32, the gaps.
void put_units(ByteWriter& w, const std::vector<Unit>& units, glm::ivec3 dims);
// Throws WireError on a level out of order or past kMaxUnitLevel, more than `max_units`, a gap
// past the volume, a meta-cell reaching past it, or no unit at all.
std::vector<Unit> get_units(ByteReader& r, glm::ivec3 dims, std::uint32_t max_units);

}  // namespace isowall::remote::cells
