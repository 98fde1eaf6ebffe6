#pragma once
// A store's octree, built during its import from the slabs the import reads anyway, so that the
// source is read once (a volume past memory would otherwise be read from disk a second time).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

#include "volume/octree.h"
#include "volume/volume.h"

namespace isowall::store {

class SlabOctree {
  public:
    virtual ~SlabOctree() = default;
    // The leaves of the voxel slices [z0, z1) (z0 and z1 multiples of the octree's leaf side, or
    // z1 the volume's depth), on `threads` threads, from `planes`, which holds the planes from z0
    // through z1 (the leaves reach one plane past their cells) in the volume's type; returns the
    // finite range of their voxels.
    virtual FiniteRange add_slab(std::span<const std::byte> planes, int z0, int z1,
                                 int threads) = 0;
    // The upper levels, then the octree file keyed by the store's content key (what
    // `--volume STORE` maps). Returns an empty string, or why the file was not written.
    virtual std::string write(const std::filesystem::path& file, std::uint64_t content_key,
                              const FiniteRange& finite) = 0;
    // After write(): the range of the volume's finite voxels.
    virtual FiniteRange range() const = 0;
};

// For a volume of `dims` voxels of `type`, walked in rows (not bricked).
std::unique_ptr<SlabOctree> make_slab_octree(glm::ivec3 dims, VoxelType type);

}  // namespace isowall::store
