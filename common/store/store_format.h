#pragma once
// A volume store (`isowall import`): a Zarr v2 group with OME-Zarr 0.4 metadata, so napari,
// neuroglancer, dask and zarr-python open it as well as isowall.
//
//   STORE/.zgroup          {"zarr_format": 2}
//   STORE/.zattrs          OME-Zarr "multiscales" (axes z, y, x; the spacing as a scale) and an
//                          "isowall" block: format version, source, value range, chunk count
//   STORE/0/.zarray        shape [z, y, x], chunks [cz, cy, x], dtype, zstd, dimension_separator /
//   STORE/0/Z/Y/0          one chunk: cz slices of cy whole rows, zstd with its content checksum
//
// Why chunks of whole rows: the engine reads voxels through a pointer into one x-fastest array
// (common/volume/volume.h: VolumeView), and the pager (paged_voxels.h) fills that array a span
// of pages at a time on first touch. A span is a run of consecutive rows, so with whole-row chunks
// it comes from one or two chunks; with cubic chunks a single 4 KiB page of a 1024-voxel row
// would need 16 of them. The cost is read amplification along x, bounded by the row length.
//
// Every chunk is a zstd frame carrying its content checksum (XXH64): zstd checks it when the
// chunk is decompressed, so a flipped bit is an error naming the chunk, never a voxel value.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "common/volume/volume.h"

namespace isowall::store {

inline constexpr int kFormatVersion = 1;

struct StoreLayout {
    glm::ivec3 dims{0};  // voxels, x y z
    VoxelType type = VoxelType::u8;
    glm::vec3 spacing{1.0f};
    int chunk_rows = 16;    // cy: rows of a chunk in y
    int chunk_slices = 16;  // cz: slices of a chunk in z
    int zstd_level = 3;
    std::string source;                   // what was imported, for `info`
    double value_min = 0, value_max = 0;  // finite range of the voxels

    glm::ivec2 chunk_grid() const {  // chunks in y and z
        return {(dims.y + chunk_rows - 1) / chunk_rows, (dims.z + chunk_slices - 1) / chunk_slices};
    }
    std::size_t chunk_count() const {
        const glm::ivec2 g = chunk_grid();
        return static_cast<std::size_t>(g.x) * static_cast<std::size_t>(g.y);
    }
    std::size_t row_bytes() const { return static_cast<std::size_t>(dims.x) * voxel_size(type); }
    // Rows of chunk (cy, cz) clamped at the volume's edge (edge chunks are short, as Zarr pads
    // only on read; we write them short and read them short).
    glm::ivec2 chunk_extent(int cy, int cz) const;
    std::size_t chunk_bytes(int cy, int cz) const;
};

// The chunk shape for a volume: whole rows, cy = cz a power of two (4..64) that keeps a chunk
// near 1 MiB, where zstd compresses well and a read is one disk request.
StoreLayout layout_for(glm::ivec3 dims, VoxelType type, glm::vec3 spacing);

// Zarr's dtype for a voxel type ("|u1", "<i2", "<f4", ...), and back.
std::string zarr_dtype(VoxelType t);
std::optional<VoxelType> parse_zarr_dtype(std::string_view s);

std::string zgroup_json();
std::string zarray_json(const StoreLayout& l);
std::string zattrs_json(const StoreLayout& l);
// The layout the two metadata texts describe; InputError naming `store`, the file and the field
// when they are not JSON, are not a store isowall wrote (or can read), or disagree.
StoreLayout parse_layout(std::string_view zarray, std::string_view zattrs,
                         const std::string& store);

// "0/Z/Y/0": the chunk's key under the store (Zarr's "/" separator, C order z, y, x).
std::string chunk_key(int cy, int cz);

// A store's path as every part of isowall names it (the octree cache's key and file name depend on
// it): normalised, without a trailing separator.
std::filesystem::path store_path(const std::string& text);

// True when `path` is a folder that looks like a store (holds .zattrs and 0/.zarray).
bool is_store(const std::filesystem::path& path);

// "512M", "8G", "1.5GiB", "1048576": bytes; nullopt for anything else (or zero).
std::optional<std::uint64_t> parse_byte_size(std::string_view text);

}  // namespace isowall::store
