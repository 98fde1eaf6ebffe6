#pragma once
// The levels of a store's multiscale pyramid (store_format.h), made from level 0 as it passes.
#include <cstddef>
#include <span>

#include <glm/vec3.hpp>

#include "volume/volume.h"

namespace isowall::store {

// Level k's plane of voxels at level-0 plane `plane0` (a z that is a multiple of 2^k): every
// 2^k-th voxel of every 2^k-th row, into `to` (dims_k.x * dims_k.y voxels, x fastest).
void decimate_plane(std::span<const std::byte> plane0, glm::ivec3 dims0, VoxelType type, int k,
                    glm::ivec3 dims_k, std::byte* to);

}  // namespace isowall::store
