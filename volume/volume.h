#pragma once
// A scalar volume: dims, spacing, voxel type, and read-only bytes that are either a memory map of
// the file (raw encoding in host byte order: no copy) or an owned decoded buffer (gzip, swapped
// endianness, generated volumes). Algorithms read it through a typed VolumeView<T>.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "core/box.h"
#include "volume/huge_pages.h"
#include "volume/mapped_file.h"

namespace isowall {

enum class VoxelType { u8, i8, u16, i16, u32, i32, f32, f64 };
enum class Endian { little, big };

std::size_t voxel_size(VoxelType t);
std::string_view type_name(VoxelType t);  // "uint8", "int16", "float32", ...
// Accepts our names and the common NRRD/C spellings (uchar, short, float, double, ...).
std::optional<VoxelType> parse_voxel_type(std::string_view s);
constexpr Endian host_endian() {
    return Endian::little;
}  // x86-64 and aarch64 Linux

// Voxels are x-fastest (`bricks` 0), or in cubic bricks of 2^bricks voxels a side, each brick
// x-fastest inside and the bricks x-fastest in their grid (a store's voxels, paged in a brick at a
// time: store/paged_voxels.h). Code that walks voxels with pointer strides checks
// bricked() first and takes index() per voxel for a bricked volume.
template <class T>
struct VolumeView {
    const T* data = nullptr;
    glm::ivec3 dims{0};
    glm::vec3 spacing{1.0f};
    int bricks = 0;            // log2 of the brick side; 0: one x-fastest array
    glm::ivec3 brick_grid{0};  // bricks per axis, when bricked

    bool bricked() const { return bricks != 0; }
    std::size_t index(int x, int y, int z) const {
        if (bricks == 0) return (static_cast<std::size_t>(z) * dims.y + y) * dims.x + x;
        const int m = (1 << bricks) - 1;
        const std::size_t brick =
            (static_cast<std::size_t>(z >> bricks) * brick_grid.y + (y >> bricks)) * brick_grid.x +
            (x >> bricks);
        const std::size_t inner = (static_cast<std::size_t>(z & m) << (2 * bricks)) |
                                  (static_cast<std::size_t>(y & m) << bricks) |
                                  static_cast<std::size_t>(x & m);
        return (brick << (3 * bricks)) | inner;
    }
    T at(int x, int y, int z) const { return data[index(x, y, z)]; }
    glm::ivec3 cell_dims() const { return glm::max(dims - 1, glm::ivec3(0)); }
    std::size_t voxel_count() const { return static_cast<std::size_t>(dims.x) * dims.y * dims.z; }
    // Object-space bounds: voxel index times spacing.
    Box3 bounds() const {
        Box3 b;
        b.merge(glm::vec3(0));
        b.merge(glm::vec3(dims - 1) * spacing);
        return b;
    }
};

// Where the voxels lie in the patient's (or the scanner's) space: DICOM's LPS millimetres (x
// toward the patient's left, y posterior, z superior). The columns of `axes` are the unit
// directions of the volume's x, y and z there; `origin` is where voxel (0, 0, 0) is. The readers
// keep `axes` a rotation (determinant +1: a mirrored file has its x reversed when read), so the
// front view of a patient is the patient's front (core/camera.h: front_full_view with
// axes). Identity and `known` false when the file says nothing (raw, most NRRD).
struct Orientation {
    glm::mat3 axes{1.0f};
    glm::vec3 origin{0.0f};
    bool known = false;
};

// One thing a file carried that a user checks (`isowall info`): "modality" "MR", "scaling"
// "value = 2.5 * stored + 0 (applied)".
struct VolumeFact {
    std::string name, value;
};

class Volume {
  public:
    Volume() = default;
    // A volume over an owned buffer (must hold dims.x*dims.y*dims.z voxels of `type`).
    Volume(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, std::vector<std::byte> bytes,
           std::string source);
    // A volume over `count` bytes at `offset` of a mapped file.
    Volume(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, MappedFile file, std::size_t offset,
           std::string source);
    // A volume over bytes someone else owns and keeps alive through `keeper` (a store's pager,
    // store/paged_voxels.h: the bytes are filled on first touch, so nothing may copy or
    // scan them all behind the user's back).
    Volume(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, std::shared_ptr<const void> keeper,
           std::span<const std::byte> bytes, std::string source);
    // The voxels in cubic bricks of 2^log2_side (VolumeView); `bytes` must hold every brick of the
    // grid that covers dims.
    void set_bricks(int log2_side) { bricks_ = log2_side; }
    // Which bricks a frame may touch (one byte per brick of brick_grid(), x fastest: 1 where the
    // surface at the frame's isovalue may pass), for a paged volume's read-ahead; the extractor
    // tells it at each frame's start. A volume without the hook ignores it.
    using BrickHint = std::function<void(std::vector<std::uint8_t>)>;
    void set_brick_hint(BrickHint hint) { brick_hint_ = std::move(hint); }
    bool wants_brick_hint() const { return static_cast<bool>(brick_hint_); }
    void hint_bricks(std::vector<std::uint8_t> wanted) const {
        if (brick_hint_) brick_hint_(std::move(wanted));
    }
    int bricks() const { return bricks_; }
    glm::ivec3 brick_grid() const {
        if (!bricks_) return glm::ivec3(0);
        auto n = [&](int d) {
            return static_cast<int>((std::int64_t{d} + (1 << bricks_) - 1) >> bricks_);
        };
        return {n(dims_.x), n(dims_.y), n(dims_.z)};
    }

    glm::ivec3 dims() const { return dims_; }
    glm::vec3 spacing() const { return spacing_; }
    VoxelType type() const { return type_; }
    const std::string& source() const { return source_; }  // file name or "phantom"
    // Every file the voxels were read from (a detached header and its data file); empty for a
    // generated volume. The octree cache key covers each.
    const std::vector<std::filesystem::path>& files() const { return files_; }
    void set_files(std::vector<std::filesystem::path> files) { files_ = std::move(files); }
    // Where a volume that carries its own octree keeps it, and the key of its content (a store:
    // store/open_store.h); empty and 0 otherwise (the octree cache's folder and key).
    const std::filesystem::path& own_octree() const { return own_octree_; }
    std::uint64_t content_key() const { return content_key_; }
    void set_own_octree(std::filesystem::path file, std::uint64_t content_key) {
        own_octree_ = std::move(file);
        content_key_ = content_key;
    }
    const Orientation& orientation() const { return orientation_; }
    void set_orientation(const Orientation& o) { orientation_ = o; }
    const std::vector<VolumeFact>& facts() const { return facts_; }
    void add_fact(std::string name, std::string value) {
        facts_.push_back({std::move(name), std::move(value)});
    }
    std::span<const std::byte> bytes() const { return bytes_; }
    bool mapped() const { return file_.size() > 0; }
    bool paged() const { return keeper_ != nullptr; }
    bool in_huge_pages() const { return huge_.size() > 0; }
    // Moves the voxels into a HugePageBuffer (volume/huge_pages.h says why) and lets go of
    // the file's map or the owned bytes. The voxels and everything else stay as they were.
    void copy_to_huge_pages();
    std::size_t voxel_count() const {
        return static_cast<std::size_t>(dims_.x) * dims_.y * dims_.z;
    }
    Box3 bounds() const;

    template <class T>
    VolumeView<T> view() const {
        return {reinterpret_cast<const T*>(bytes_.data()), dims_, spacing_, bricks_, brick_grid()};
    }

  private:
    glm::ivec3 dims_{0};
    glm::vec3 spacing_{1.0f};
    VoxelType type_ = VoxelType::u8;
    std::string source_;
    std::vector<std::filesystem::path> files_;
    std::filesystem::path own_octree_;
    std::uint64_t content_key_ = 0;
    Orientation orientation_;
    std::vector<VolumeFact> facts_;
    MappedFile file_;
    std::vector<std::byte> owned_;
    HugePageBuffer huge_;
    std::shared_ptr<const void> keeper_;
    BrickHint brick_hint_;
    int bricks_ = 0;
    std::span<const std::byte> bytes_;
};

// Calls f(T{}) with the C++ type of t, so one templated body serves every voxel type.
template <class F>
decltype(auto) dispatch_voxel_type(VoxelType t, F&& f) {
    switch (t) {
        case VoxelType::u8:
            return f(std::uint8_t{});
        case VoxelType::i8:
            return f(std::int8_t{});
        case VoxelType::u16:
            return f(std::uint16_t{});
        case VoxelType::i16:
            return f(std::int16_t{});
        case VoxelType::u32:
            return f(std::uint32_t{});
        case VoxelType::i32:
            return f(std::int32_t{});
        case VoxelType::f32:
            return f(float{});
        case VoxelType::f64:
            return f(double{});
    }
    return f(std::uint8_t{});
}

template <class T>
constexpr VoxelType voxel_type_of() {
    if constexpr (std::is_same_v<T, std::uint8_t>)
        return VoxelType::u8;
    else if constexpr (std::is_same_v<T, std::int8_t>)
        return VoxelType::i8;
    else if constexpr (std::is_same_v<T, std::uint16_t>)
        return VoxelType::u16;
    else if constexpr (std::is_same_v<T, std::int16_t>)
        return VoxelType::i16;
    else if constexpr (std::is_same_v<T, std::uint32_t>)
        return VoxelType::u32;
    else if constexpr (std::is_same_v<T, std::int32_t>)
        return VoxelType::i32;
    else if constexpr (std::is_same_v<T, float>)
        return VoxelType::f32;
    else
        return VoxelType::f64;
}

struct RawSpec {
    glm::ivec3 dims{0};
    VoxelType type = VoxelType::u8;
    glm::vec3 spacing{1.0f};
    Endian endian = Endian::little;
    std::size_t header_bytes = 0;  // bytes to skip at the start of the file
};

// Headerless voxels, x fastest. The file must be a regular file holding exactly
// header_bytes + voxels * size bytes.
// populate (here and in load_nrrd): a mapped file is read into the page cache at once when it
// fits in half the memory, so the first frame does not wait on the disk ray by ray; false: mapped
// only (a reader that streams the file in its own order, as `isowall import`).
Volume load_raw(const std::filesystem::path& path, const RawSpec& spec, bool populate = true);
// NRRD: Teem parses the header text; we locate the data (one regular data file, line and byte
// skips checked against its size) and decode it: raw, gzip, bzip2, ascii, hex, each with the
// exact count the header gives. Raw data in host byte order is memory-mapped, everything else
// decoded into memory. Every failure is an InputError naming the file and the field.
Volume load_nrrd(const std::filesystem::path& path, bool populate = true);
// Picks the loader by extension (.nrrd/.nhdr -> NRRD, anything else needs a RawSpec).
Volume load_volume(const std::filesystem::path& path, const std::optional<RawSpec>& raw);

// Writes through Teem (for tests and conversions): encoding "raw" or "gzip"; detached when the
// path ends in .nhdr (data beside it as NAME.raw or NAME.raw.gz).
void save_nrrd(const std::filesystem::path& path, const Volume& volume, std::string_view encoding,
               Endian endian);

// Reverses the byte order of every voxel in place.
void swap_bytes(std::span<std::byte> bytes, std::size_t voxel_size);

}  // namespace isowall
