#pragma once
// An import's source held by a Volume, a slab at a time: a memory-mapped file is read ahead of the
// slab being compressed and let go once it is written (store_writer.cpp).
#include <cstddef>
#include <thread>

#include "volume/plane_source.h"
#include "volume/volume.h"

namespace isowall::store {

// Lets the kernel drop a memory-mapped source's pages of [begin, end) from this process.
void release_source_pages(const std::byte* begin, const std::byte* end);
// Reads [begin, end) of a memory-mapped source into memory and maps it.
void populate_source_pages(const std::byte* begin, const std::byte* end);

// The planes of `volume` (which must outlive it, and be walked in rows, not bricked) as views of
// its bytes. A mapped volume's next slab, as long as the one asked, is read on a thread while
// the caller works on this one, and the planes before each call's z0 are let go.
class VolumePlanes final : public PlaneSource {
  public:
    explicit VolumePlanes(const Volume& volume);
    ~VolumePlanes() override;
    VolumePlanes(const VolumePlanes&) = delete;
    VolumePlanes& operator=(const VolumePlanes&) = delete;
    glm::ivec3 dims() const override { return v_.dims(); }
    VoxelType type() const override { return v_.type(); }
    glm::vec3 spacing() const override { return v_.spacing(); }
    const std::string& source() const override { return v_.source(); }
    std::span<const std::byte> planes(int z0, int z1) override;

  private:
    const std::byte* at(int z) const { return v_.bytes().data() + std::size_t(z) * plane_bytes(); }
    const Volume& v_;
    std::thread reading_;
    int released_ = 0;  // planes [0, released_) are let go
};

}  // namespace isowall::store
