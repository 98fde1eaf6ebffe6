#pragma once
// The units of a `cells` group (remote/cell_codec.h) and how they travel: a unit is a cell or a
// meta-cell of a level (its first cell, a multiple of 2^level), sorted by level and then by index
// in that level's grid of units. Each level's units go as their box in that grid and the box's
// occupancy, a bit a place through the range coder (cell_units.cpp). Internal to the codec.
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "remote/byte_io.h"
#include "remote/range_coder.h"

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

// One level's units as they travel: how many, and their box in that level's grid of units.
struct UnitBucket {
    int level = 0;
    std::uint32_t count = 0;
    glm::ivec3 origin{0}, size{0};
    std::uint64_t places() const;  // the box's
};
// The most places a bucket's box may hold (cell_codec.h's kMaxCellBoxVoxels: a group's voxels
// span no more, so its units at any level neither).
inline constexpr std::uint64_t kMaxUnitBoxPlaces = std::uint64_t{1} << 24;

// Sorted units (sort_units): bucket count u8, then per level its level u8, count u32, the box's
// origin and size as 3 + 3 LEB128 numbers into `w`; the boxes' occupancy into `bits`. False, with
// nothing written, when the boxes with their coding borders hold more than kMaxUnitBoxPlaces
// places in all (a thin box's border is up to 12 times its places), which get_units refuses.
bool put_units(ByteWriter& w, RangeEncoder& bits, const std::vector<Unit>& units);
// The buckets; throws WireError on a level out of order or past kMaxUnitLevel, counts past
// `max_units` in all or past a box, a box past the volume or over kMaxUnitBoxPlaces, no unit.
std::vector<UnitBucket> get_unit_buckets(ByteReader& r, glm::ivec3 dims, std::uint32_t max_units);
// The units, from the boxes' bits; throws WireError (through `r`) when the boxes hold more
// places than `max_places` (what the stream can code) or, with their borders, more than
// kMaxUnitBoxPlaces (both checked before anything is sized from them), a box's bits set other
// than its count, or a meta-cell reaches past the volume.
std::vector<Unit> get_units(const ByteReader& r, RangeDecoder& bits,
                            const std::vector<UnitBucket>& buckets, glm::ivec3 dims,
                            std::uint64_t max_places);

}  // namespace isowall::remote::cells
