#pragma once
// Reading a store's chunks (store_format.h): the metadata once, then any chunk from any thread.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "common/store/store_format.h"

namespace isowall::store {

class StoreReader {
  public:
    // Reads and checks the metadata, and that every chunk file is there and not empty: a store
    // that lost a chunk is refused before the first frame, naming the chunk. InputError otherwise.
    explicit StoreReader(const std::filesystem::path& store);

    const StoreLayout& layout() const { return layout_; }
    const std::filesystem::path& path() const { return path_; }
    // Compressed bytes of every chunk (what the store takes on disk, less its metadata).
    std::uint64_t bytes_on_disk() const { return bytes_on_disk_; }

    // Decompresses brick b's chunk into `out`, which holds exactly layout().brick_bytes().
    // A chunk that cannot be read, is not one zstd frame, fails its checksum or has another size
    // is an InputError naming the store and the chunk: garbage never becomes voxels. Returns the
    // bytes read from disk. Safe from any thread.
    std::size_t read_chunk(glm::ivec3 b, std::span<std::byte> out) const;

  private:
    std::filesystem::path path_;
    StoreLayout layout_;
    std::uint64_t bytes_on_disk_ = 0;
};

}  // namespace isowall::store
