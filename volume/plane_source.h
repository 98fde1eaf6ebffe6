#pragma once
// A volume's planes in z order, a slab at a time: what `isowall import` reads its source through,
// so that a volume larger than memory is never held whole. A memory-mapped file hands out views
// of its map (store/source_pages.h); a format decoded by a library hands out planes it
// decodes into a buffer of a slab (readers/plane_stack.h).
#include <cstddef>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <glm/vec3.hpp>

#include "volume/volume.h"

namespace isowall {

class PlaneSource {
  public:
    virtual ~PlaneSource() = default;
    virtual glm::ivec3 dims() const = 0;
    virtual VoxelType type() const = 0;
    virtual glm::vec3 spacing() const = 0;
    virtual const std::string& source() const = 0;  // the file or folder, for errors and the store
    // Planes [z0, z1) (x fastest), valid until the next call. Calls come in z order: each call's
    // z0 is at least the last one's z0 and at most its z1 (a slab may ask again for the plane the
    // last one ended on: a leaf of the octree spans its slab's last plane and the next one's
    // first). Errors are InputErrors naming the source.
    virtual std::span<const std::byte> planes(int z0, int z1) = 0;

    std::size_t plane_bytes() const {
        return static_cast<std::size_t>(dims().x) * dims().y * voxel_size(type());
    }
};

// Planes decoded into a buffer by `decode(z0, z1, to)`, which is called with z0 rising from 0,
// each call starting where the last one ended (one call at a time, not always on one thread), so
// a decoder may stream its file once. Planes a call asks for again are kept from the last call,
// whose end a call never comes before. With `read_ahead`, as many planes as a call asked for are
// decoded after it on a thread of their own while the caller works on them: the buffer holds two
// calls' planes. A decoder's error on that thread is thrown by the next call.
class DecodedPlanes final : public PlaneSource {
  public:
    using Decode = std::function<void(int z0, int z1, std::byte* to)>;
    DecodedPlanes(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, std::string source,
                  Decode decode, bool read_ahead = true);
    ~DecodedPlanes() override;
    DecodedPlanes(const DecodedPlanes&) = delete;
    DecodedPlanes& operator=(const DecodedPlanes&) = delete;
    glm::ivec3 dims() const override { return dims_; }
    VoxelType type() const override { return type_; }
    glm::vec3 spacing() const override { return spacing_; }
    const std::string& source() const override { return source_; }
    std::span<const std::byte> planes(int z0, int z1) override;
    // The most bytes the buffer held at once (tests: memory stays at a slab).
    std::size_t peak_bytes() const { return peak_; }
    // What makes a decode under way return early (with an error) when the planes are dropped
    // before their end: a decoder waiting on another process ends it. Called by the destructor
    // before it waits for the read-ahead thread.
    void set_cancel(std::function<void()> cancel) { cancel_ = std::move(cancel); }

  private:
    void finish_ahead();  // waits for the planes read ahead; throws the decoder's error
    glm::ivec3 dims_;
    VoxelType type_;
    glm::vec3 spacing_;
    std::string source_;
    Decode decode_;
    bool read_ahead_;
    std::vector<std::byte> buffer_;  // planes [z0_, have_), then those read ahead
    int z0_ = 0, z1_ = 0;            // the last call's planes
    int have_ = 0;                   // planes decoded
    std::thread ahead_;              // decoding [have_, ahead_end_)
    int ahead_end_ = 0;
    std::exception_ptr ahead_error_;
    std::function<void()> cancel_;
    std::size_t peak_ = 0;
};

// The planes of a NRRD file whose data is not mapped as it is (load_nrrd copies it): gzip, inflated
// a slab at a time, and raw data of the other byte order. Null for raw data in host order (map it:
// load_nrrd) and for bzip2, hex and ascii, which are decoded whole.
// The planes of a raw file of the other byte order (load_raw copies it), swapped a slab at a
// time; null for one in host order (map it: load_raw). The spec is checked as load_raw checks it.
std::unique_ptr<PlaneSource> raw_planes(const std::filesystem::path& path, const RawSpec& spec);

// `read_ahead` as DecodedPlanes'.
std::unique_ptr<PlaneSource> nrrd_planes(const std::filesystem::path& path, bool read_ahead = true);

}  // namespace isowall
