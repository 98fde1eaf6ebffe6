#pragma once
// Reading a store's chunks (store_format.h): the metadata once, then any chunk from any thread.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "store/store_format.h"

namespace isowall::store {

// Where a reader without the store's folder gets a chunk's compressed bytes (a wall's tile rank
// on a host that cannot see the store asks the master: tile/remote_bricks.h). It may throw.
using ChunkFetch = std::function<std::vector<std::byte>(glm::ivec3 brick)>;

class StoreReader {
  public:
    // Reads and checks the metadata, and that every chunk file is there and not empty: a store
    // that lost a chunk is refused before the first frame, naming the chunk. InputError otherwise.
    explicit StoreReader(const std::filesystem::path& store);
    // A store read elsewhere: `zarray` and `zattrs` are its metadata files' text (checked as
    // above, naming `name`), and every chunk comes from `fetch`, then is checked as if read here.
    StoreReader(const std::string& name, const std::string& zarray, const std::string& zattrs,
                std::uint64_t bytes_on_disk, ChunkFetch fetch);

    const StoreLayout& layout() const { return layout_; }
    // The folder; for a store read elsewhere, its name there.
    const std::filesystem::path& path() const { return path_; }
    // Compressed bytes of every chunk (what the store takes on disk, less its metadata).
    std::uint64_t bytes_on_disk() const { return bytes_on_disk_; }
    // The metadata files as read, to hand to a reader elsewhere.
    const std::string& zarray_text() const { return zarray_; }
    const std::string& zattrs_text() const { return zattrs_; }

    // Brick b's chunk as it is on disk (compressed), for a reader elsewhere. InputError naming
    // the store and chunk when it cannot be read or is larger than its voxels could compress to.
    // Only for a store read here.
    std::vector<std::byte> read_packed(glm::ivec3 b, int level = 0) const;

    // Decompresses brick b's chunk into `out`, which holds exactly layout().brick_bytes().
    // A chunk that cannot be read, is not one zstd frame, fails its checksum or has another size
    // is an InputError naming the store and the chunk: garbage never becomes voxels. Returns the
    // bytes read from disk. Safe from any thread.
    // Level k > 0 (layout().level(k)) only for a store read here.
    std::size_t read_chunk(glm::ivec3 b, std::span<std::byte> out, int level = 0) const;

    // Asks the kernel to start reading brick b's chunk into the page cache and returns at once
    // (read-ahead: a later read_chunk then finds it in memory). Errors are left to that read;
    // nothing for a store read elsewhere.
    void prefetch(glm::ivec3 b) const;

  private:
    void check_chunks(const std::filesystem::path& store, const std::string& where);
    void check_level_chunks(const std::filesystem::path& store, const std::string& where, int k);

    std::filesystem::path path_;
    std::string zarray_, zattrs_;
    StoreLayout layout_;
    std::uint64_t bytes_on_disk_ = 0;
    ChunkFetch fetch_;  // empty: the chunks are files under path_
};

}  // namespace isowall::store
