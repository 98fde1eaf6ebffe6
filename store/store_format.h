#pragma once
// A volume store (`isowall import`): a Zarr v2 group with OME-Zarr 0.4 metadata, so napari,
// neuroglancer, dask and zarr-python open it as well as isowall.
//
//   STORE/.zgroup          {"zarr_format": 2}
//   STORE/.zattrs          OME-Zarr "multiscales" (axes z, y, x; the spacing as a scale) and an
//                          "isowall" block: format version, source, value range, chunk count
//   STORE/0/.zarray        shape [z, y, x], chunks [B, B, B], dtype, zstd, dimension_separator /
//   STORE/0/Z/Y/X          one chunk: a cubic brick of B^3 voxels (edge bricks padded with
//                          zeros, as Zarr stores them), zstd with its content checksum
//   STORE/K/...            level K >= 1 of the multiscale pyramid, the same way: every 2^K-th
//                          voxel along each axis (ceil(side / 2^K) a side), down to the level
//                          whose sides fit one brick. OME-Zarr lists each with its scale, so
//                          napari and neuroglancer show the coarse levels first.
//
// Why the levels keep voxels rather than average them: isowall's meta-cell of level K (chapter
// 2.1.3: a coarse level of detail) has its corners at every 2^K-th voxel, so level K holds
// exactly the voxels it reads, and no value between two materials is made up that the volume
// does not hold (an average of air and bone is skin).
//
// Why cubic bricks: a surface passes near few of them, so a frame reads what its rays and its
// propagation touch (the dissertation's 5.2.1: propagation has strong data locality). In memory
// the voxels keep the same bricks (VolumeView's bricked layout), so a brick on disk is one span
// of the pager (paged_voxels.h), decompressed straight into place.
//
// Every chunk is a zstd frame carrying its content checksum (XXH64): zstd checks it when the
// chunk is decompressed, so a flipped bit is an error naming the chunk, never a voxel value.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "volume/volume.h"

namespace isowall::store {

inline constexpr int kFormatVersion = 1;

struct StoreLayout {
    glm::ivec3 dims{0};  // voxels, x y z
    VoxelType type = VoxelType::u8;
    glm::vec3 spacing{1.0f};
    int brick_log2 = 5;  // bricks of 2^brick_log2 voxels a side (the Zarr chunk)
    int zstd_level = 1;
    std::string id;                       // 16 hex digits, new at each import: the content's key
    std::string source;                   // what was imported, for `info`
    double value_min = 0, value_max = 0;  // finite range of the voxels
    std::uint64_t bytes = 0;  // level 0's chunks' compressed bytes, as written (0: not recorded)
    int levels = 1;           // arrays 0 .. levels-1 (older stores: level 0 only)

    int brick() const { return 1 << brick_log2; }
    glm::ivec3 grid() const {  // in 64 bits first: a side near 2^31 must not wrap
        auto n = [&](int d) {
            return static_cast<int>((std::int64_t{d} + brick() - 1) >> brick_log2);
        };
        return {n(dims.x), n(dims.y), n(dims.z)};
    }
    std::size_t chunk_count() const {
        const glm::ivec3 g = grid();
        return static_cast<std::size_t>(g.x) * static_cast<std::size_t>(g.y) *
               static_cast<std::size_t>(g.z);
    }
    // Level k's array: the same bricks over every 2^k-th voxel, its spacing 2^k times as wide.
    StoreLayout level(int k) const {
        StoreLayout l = *this;
        auto side = [&](int d) { return static_cast<int>(((std::int64_t{d} - 1) >> k) + 1); };
        l.dims = {side(dims.x), side(dims.y), side(dims.z)};
        l.spacing = spacing * static_cast<float>(1 << k);
        return l;
    }
    std::size_t brick_bytes() const {
        return (std::size_t{1} << (3 * brick_log2)) * voxel_size(type);
    }
    // Brick b's place in the grid, x fastest (the bricks' order in memory).
    std::size_t brick_index(glm::ivec3 b) const {
        const glm::ivec3 g = grid();
        return (static_cast<std::size_t>(b.z) * static_cast<std::size_t>(g.y) +
                static_cast<std::size_t>(b.y)) *
                   static_cast<std::size_t>(g.x) +
               static_cast<std::size_t>(b.x);
    }
    glm::ivec3 brick_at(std::size_t i) const {
        const glm::ivec3 g = grid();
        const std::size_t gx = static_cast<std::size_t>(g.x), gy = static_cast<std::size_t>(g.y);
        return {static_cast<int>(i % gx), static_cast<int>(i / gx % gy),
                static_cast<int>(i / gx / gy)};
    }
};

// The brick side for a volume: 32 voxels (32 KiB to 256 KiB a brick: a page multiple, small
// enough that a surface's bricks are few), 64 when 32 would make more than 65,536 chunk files.
StoreLayout layout_for(glm::ivec3 dims, VoxelType type, glm::vec3 spacing);

// How many levels an import writes: halving until every side fits one brick (the 4x CT head,
// 2048x2048x936 in bricks of 64: levels 0-5), at most 12.
int levels_for(glm::ivec3 dims, int brick_log2);

// Zarr's dtype for a voxel type ("|u1", "<i2", "<f4", ...), and back.
std::string zarr_dtype(VoxelType t);
std::optional<VoxelType> parse_zarr_dtype(std::string_view s);

std::string zgroup_json();
std::string zarray_json(const StoreLayout& l);  // of level 0; l.level(k) for level k
std::string zattrs_json(const StoreLayout& l);
// The layout the two metadata texts describe; InputError naming `store`, the file and the field
// when they are not JSON, are not a store isowall wrote (or can read), or disagree.
StoreLayout parse_layout(std::string_view zarray, std::string_view zattrs,
                         const std::string& store);

// The whole of a store's small metadata file `file` (`name` in errors); an InputError naming
// `store` and `name` when it cannot be read, is not a regular file, or passes 1 MiB.
std::string read_metadata(const std::filesystem::path& file, const std::string& store,
                          const std::string& name);

// Level k's metadata (K/.zarray) checked against level 0's layout `l`: an InputError naming
// the store, the file and the field when its shape, chunks or dtype are not l.level(k)'s.
void check_level(std::string_view zarray, const StoreLayout& l, int k, const std::string& store);

// The store's own octree (built by `import`, beside the array; Zarr readers pass over it), and
// the key of the content it describes: from the store's id, so it holds wherever the store lies.
std::filesystem::path octree_file(const std::filesystem::path& store);
std::uint64_t content_key(const StoreLayout& l);
// A fresh id for an import: 64 random bits as 16 hex digits.
std::string new_store_id();

// "K/Z/Y/X": brick b's chunk key of level K under the store (Zarr's "/" separator, C order z,
// y, x).
std::string chunk_key(glm::ivec3 b, int level = 0);

// A store's path as every part of isowall names it (the octree cache's key and file name depend on
// it): normalised, without a trailing separator.
std::filesystem::path store_path(const std::string& text);

// True when `path` is a folder that looks like a store (holds .zattrs and 0/.zarray).
bool is_store(const std::filesystem::path& path);

}  // namespace isowall::store
