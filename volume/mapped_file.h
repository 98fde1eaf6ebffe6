#pragma once
// Read-only memory map of a whole file (RAII). Volumes and octree caches are read through it, so
// ranks on one machine share one copy of the bytes through the page cache.
#include <cstddef>
#include <filesystem>
#include <span>

namespace isowall {

class MappedFile {
  public:
    MappedFile() = default;
    // Throws std::runtime_error naming the file when it cannot be opened or mapped, or is not a
    // regular file (a device or FIFO has no size to map, and may never end).
    // populate: map every page at once (MAP_POPULATE) when the file is at most half the
    // machine's memory, so that the first frame does not take a page fault per page it touches
    // (a 3.9 GB volume took about a million of them in its first frame); the time goes to the
    // load instead, as when a program reads a volume into memory.
    explicit MappedFile(const std::filesystem::path& path, bool populate = false);
    MappedFile(MappedFile&& other) noexcept;
    MappedFile& operator=(MappedFile&& other) noexcept;
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    ~MappedFile();

    std::span<const std::byte> bytes() const { return {data_, size_}; }
    std::size_t size() const { return size_; }
    // Lets go of the pages of `part` (clipped to the map) in this process: the file's pages stay
    // in the page cache, and a later read of them maps them again. A copy of the map taken part
    // by part, each part let go of once copied, holds the file once instead of twice at its peak.
    void release(std::span<const std::byte> part) const;

  private:
    const std::byte* data_ = nullptr;
    std::size_t size_ = 0;
};

}  // namespace isowall
