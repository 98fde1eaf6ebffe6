#pragma once
// A store's octree, built during its import from the slabs the import reads anyway, so that the
// source is read once (a volume past memory would otherwise be read from disk a second time).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "common/volume/octree.h"
#include "common/volume/volume.h"

namespace isowall::store {

class SlabOctree {
  public:
    virtual ~SlabOctree() = default;
    // The leaves of the voxel slices [z0, z1) (z0 and z1 multiples of the octree's leaf side, or
    // z1 the volume's depth), on `threads` threads; returns the finite range of their voxels.
    virtual FiniteRange add_slab(int z0, int z1, int threads) = 0;
    // The upper levels, then the octree file keyed by the store's content key (what
    // `--volume STORE` maps). Returns an empty string, or why the file was not written.
    virtual std::string write(const std::filesystem::path& file, std::uint64_t content_key,
                              const FiniteRange& finite) = 0;
    // After write(): the range of the volume's finite voxels.
    virtual FiniteRange range() const = 0;
};

// For `volume`, which must outlive it and be walked in rows (not bricked).
std::unique_ptr<SlabOctree> make_slab_octree(const Volume& volume);

}  // namespace isowall::store
