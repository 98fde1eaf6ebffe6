#pragma once
// One Zarr array as its metadata describes it, and its chunks decoded (zarr_reader.h reads the
// volume from them): Zarr v2 (.zarray: a compressor, C or F order) and Zarr v3 (zarr.json: a
// codec chain of transpose, bytes, and blosc, gzip or zstd, with crc32c; or sharding_indexed,
// whose shards hold inner chunks under an index). Every error is an InputError naming the
// metadata file and the field, or the chunk's key.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "readers/zarr_reader.h"
#include "volume/volume.h"

namespace isowall::formats::zarr {

inline constexpr std::size_t kMaxMetadataBytes = std::size_t{1} << 20;
// A chunk (a shard) decoded at most: larger ones are not a volume's (and would be a claim to
// check before any allocation).
inline constexpr std::size_t kMaxChunkBytes = std::size_t{1} << 30;

struct ZarrArray {
    int version = 2;
    std::string prefix;                       // the array's keys start with this ("" or "0/")
    std::string where;                        // its metadata file, for messages
    std::vector<std::int64_t> shape, chunks;  // slowest axis first; chunks: the grid's (shards)
    VoxelType type = VoxelType::u8;
    bool big_endian = false;
    // The axes from slowest to fastest in a chunk's bytes: 0, 1, .. for C order; reversed for F
    // order; a v3 transpose's permutation. A sharded array's inner chunks are laid out so; its
    // shards, once decoded, are in C order.
    std::vector<std::size_t> order;
    std::string key_prefix;          // before a chunk key's indices: "c/" (v3's default) or ""
    std::string separator = ".";     // between them: "." or "/"
    nlohmann::json compressor;       // {"id": "blosc"|"zstd"|"gzip"|"zlib"|"lz4"}, or null
    bool crc32c = false;             // a CRC-32C of the chunk's bytes follows them (v3)
    nlohmann::json fill;             // null: 0
    std::vector<std::string> names;  // v3's dimension_names (empty where it gives none)
    std::vector<std::int64_t> pick;  // the element taken on each axis before z, y, x
    struct Shard {
        std::vector<std::int64_t> inner;  // an inner chunk's shape, dividing a shard's
        bool index_at_start = false;
        bool index_big_endian = false;
        bool index_crc32c = false;
    };
    std::optional<Shard> shard;

    std::size_t item() const { return voxel_size(type); }
    std::size_t chunk_elements() const {
        std::size_t n = 1;
        for (std::int64_t c : chunks) n *= static_cast<std::size_t>(c);
        return n;
    }
    // The axes' order in a decoded chunk of the grid (a shard's is C order).
    std::vector<std::size_t> grid_order() const;
};

nlohmann::json parse_json(const std::string& text, const std::string& where);
// `key`'s JSON; an InputError where the store has none.
nlohmann::json read_json(const ZarrSource& source, const std::string& key);

ZarrArray read_v2_array(const ZarrSource& source, const std::string& prefix);  // PREFIX.zarray
ZarrArray read_v3_array(const ZarrSource& source, const std::string& prefix);  // PREFIX/zarr.json

// The fill value as `a.type`'s bytes, host order.
std::vector<std::byte> fill_bytes(const ZarrArray& a);

// One chunk of the grid (a shard: its inner chunks, a missing one the fill value) decoded into
// `out`, exactly its size, in the file's byte order, laid out as grid_order() says.
void decode_chunk(const ZarrArray& a, const std::string& in, const std::string& where,
                  std::vector<std::byte>& out);

// The key of the chunk at grid index (z, y, x) of the picked time point and channel.
std::string chunk_key(const ZarrArray& a, std::int64_t z, std::int64_t y, std::int64_t x);

// CRC-32C (Castagnoli), as Zarr v3's crc32c codec appends it.
std::uint32_t crc32c(const void* data, std::size_t size);

}  // namespace isowall::formats::zarr
