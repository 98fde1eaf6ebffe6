#include "volume/volume.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include "core/error.h"
#include "volume/load_checks.h"
#include "volume/plane_source.h"
#include "volume/teem_util.h"

namespace isowall {
namespace fs = std::filesystem;

std::size_t voxel_size(VoxelType t) {
    return dispatch_voxel_type(t, [](auto v) { return sizeof(v); });
}

std::string_view type_name(VoxelType t) {
    switch (t) {
        case VoxelType::u8:
            return "uint8";
        case VoxelType::i8:
            return "int8";
        case VoxelType::u16:
            return "uint16";
        case VoxelType::i16:
            return "int16";
        case VoxelType::u32:
            return "uint32";
        case VoxelType::i32:
            return "int32";
        case VoxelType::f32:
            return "float32";
        case VoxelType::f64:
            return "float64";
    }
    return "?";
}

std::optional<VoxelType> parse_voxel_type(std::string_view s) {
    struct Alias {
        std::string_view name;
        VoxelType type;
    };
    static constexpr Alias kAliases[] = {
        {"uint8", VoxelType::u8},    {"uchar", VoxelType::u8},   {"u8", VoxelType::u8},
        {"int8", VoxelType::i8},     {"char", VoxelType::i8},    {"i8", VoxelType::i8},
        {"uint16", VoxelType::u16},  {"ushort", VoxelType::u16}, {"u16", VoxelType::u16},
        {"int16", VoxelType::i16},   {"short", VoxelType::i16},  {"i16", VoxelType::i16},
        {"uint32", VoxelType::u32},  {"uint", VoxelType::u32},   {"u32", VoxelType::u32},
        {"int32", VoxelType::i32},   {"int", VoxelType::i32},    {"i32", VoxelType::i32},
        {"float32", VoxelType::f32}, {"float", VoxelType::f32},  {"f32", VoxelType::f32},
        {"float64", VoxelType::f64}, {"double", VoxelType::f64}, {"f64", VoxelType::f64},
    };
    for (const auto& a : kAliases)
        if (a.name == s) return a.type;
    return std::nullopt;
}

void swap_bytes(std::span<std::byte> bytes, std::size_t size) {
    if (size <= 1) return;
    for (std::size_t i = 0; i + size <= bytes.size(); i += size)
        std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(i),
                     bytes.begin() + static_cast<std::ptrdiff_t>(i + size));
}

Volume::Volume(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, std::vector<std::byte> bytes,
               std::string source)
    : dims_(dims),
      spacing_(spacing),
      type_(type),
      source_(std::move(source)),
      owned_(std::move(bytes)) {
    bytes_ = owned_;
}

Volume::Volume(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, MappedFile file,
               std::size_t offset, std::string source)
    : dims_(dims),
      spacing_(spacing),
      type_(type),
      source_(std::move(source)),
      file_(std::move(file)) {
    bytes_ = file_.bytes().subspan(offset, voxel_count() * voxel_size(type));
}

Volume::Volume(glm::ivec3 dims, VoxelType type, glm::vec3 spacing,
               std::shared_ptr<const void> keeper, std::span<const std::byte> bytes,
               std::string source)
    : dims_(dims),
      spacing_(spacing),
      type_(type),
      source_(std::move(source)),
      keeper_(std::move(keeper)),
      bytes_(bytes) {}

void Volume::copy_to_huge_pages() {
    if (bricks_) return;  // a store's bricks: a copy would read every one
    HugePageBuffer buffer(bytes_.size());
    // Part by part, each part of a file's map let go of once copied: the process holds the
    // voxels about once while it copies them, where a whole copy before the unmap held them twice
    // (7.6 GiB at its peak for the 3.9 GB head).
    constexpr std::size_t kPart = std::size_t{64} << 20;
    for (std::size_t at = 0; at < bytes_.size(); at += kPart) {
        const auto part = bytes_.subspan(at, std::min(kPart, bytes_.size() - at));
        std::copy(part.begin(), part.end(),
                  buffer.bytes().begin() + static_cast<std::ptrdiff_t>(at));
        file_.release(part);
    }
    huge_ = std::move(buffer);
    bytes_ = huge_.bytes();
    file_ = MappedFile();
    owned_ = std::vector<std::byte>();
    keeper_.reset();
}

Box3 Volume::bounds() const {
    Box3 b;
    b.merge(glm::vec3(0));
    b.merge(glm::vec3(dims_ - 1) * spacing_);
    return b;
}

namespace {

void check_dims(const std::string& where, const std::string& field, glm::ivec3 dims,
                VoxelType type) {
    const std::uint64_t sizes[3] = {static_cast<std::uint64_t>(std::max(dims.x, 0)),
                                    static_cast<std::uint64_t>(std::max(dims.y, 0)),
                                    static_cast<std::uint64_t>(std::max(dims.z, 0))};
    if (dims.x < 2 || dims.y < 2 || dims.z < 2) {
        std::ostringstream os;
        os << "expected three sizes >= 2, got " << dims.x << " " << dims.y << " " << dims.z;
        throw InputError(where, field, os.str());
    }
    checked_dims(where, field, sizes, type);
}

int to_teem_type(VoxelType t) {
    switch (t) {
        case VoxelType::u8:
            return nrrdTypeUChar;
        case VoxelType::i8:
            return nrrdTypeChar;
        case VoxelType::u16:
            return nrrdTypeUShort;
        case VoxelType::i16:
            return nrrdTypeShort;
        case VoxelType::u32:
            return nrrdTypeUInt;
        case VoxelType::i32:
            return nrrdTypeInt;
        case VoxelType::f32:
            return nrrdTypeFloat;
        case VoxelType::f64:
            return nrrdTypeDouble;
    }
    return nrrdTypeUnknown;
}

}  // namespace

namespace {

// A raw file checked against its spec and mapped.
MappedFile checked_raw(const fs::path& path, const RawSpec& spec, bool populate) {
    const std::string where = path.string();
    check_dims(where, "--dims", spec.dims, spec.type);
    check_regular_file(path, where, "file");
    for (int i = 0; i < 3; ++i)
        if (std::string p = spacing_problem(spec.spacing[i], spec.dims[i], i); !p.empty())
            throw InputError(where, "--spacing", p);
    MappedFile file(path, populate);
    check_size(where, file.size(), spec.header_bytes, voxel_bytes(spec.dims, spec.type));
    return file;
}

}  // namespace

std::unique_ptr<PlaneSource> raw_planes(const fs::path& path, const RawSpec& spec) {
    if (spec.endian == host_endian() || voxel_size(spec.type) == 1) return nullptr;
    auto file = std::make_shared<MappedFile>(checked_raw(path, spec, false));
    const std::size_t plane = std::size_t(spec.dims.x) * spec.dims.y * voxel_size(spec.type);
    const std::size_t at = spec.header_bytes, size = voxel_size(spec.type);
    return std::make_unique<DecodedPlanes>(
        spec.dims, spec.type, spec.spacing, path.string(),
        [file, plane, at, size](int z0, int z1, std::byte* to) {
            const std::size_t n = plane * std::size_t(z1 - z0);
            std::memcpy(to, file->bytes().data() + at + plane * std::size_t(z0), n);
            swap_bytes({to, n}, size);
        });
}

Volume load_raw(const fs::path& path, const RawSpec& spec, bool populate) {
    const std::string where = path.string();
    MappedFile file = checked_raw(path, spec, populate);
    const std::uint64_t need = voxel_bytes(spec.dims, spec.type);
    Volume volume;
    if (spec.endian == host_endian() || voxel_size(spec.type) == 1) {
        volume =
            Volume(spec.dims, spec.type, spec.spacing, std::move(file), spec.header_bytes, where);
    } else {
        std::vector<std::byte> bytes = allocate_voxels(need, where, "--dims");
        const auto data = file.bytes().subspan(spec.header_bytes, bytes.size());
        std::copy(data.begin(), data.end(), bytes.begin());
        swap_bytes(bytes, voxel_size(spec.type));
        volume = Volume(spec.dims, spec.type, spec.spacing, std::move(bytes), where);
    }
    volume.set_files({path});
    return volume;
}

Volume load_volume(const fs::path& path, const std::optional<RawSpec>& raw) {
    if (raw) return load_raw(path, *raw);
    const auto ext = path.extension();
    if (ext == ".nrrd" || ext == ".nhdr") return load_nrrd(path);
    throw InputError(path.string(), "format",
                     "not a .nrrd/.nhdr file; for headerless data give --dims X Y Z and --type T");
}

void save_nrrd(const fs::path& path, const Volume& volume, std::string_view encoding,
               Endian endian) {
    if (endian != host_endian() && voxel_size(volume.type()) > 1)
        throw std::runtime_error("save_nrrd: only host byte order is written");
    std::vector<std::byte> copy(volume.bytes().begin(), volume.bytes().end());
    std::unique_ptr<Nrrd, teem::NrrdDeleter> nrrd(nrrdNew());
    const glm::ivec3 d = volume.dims();
    if (nrrdWrap_va(nrrd.get(), copy.data(), to_teem_type(volume.type()), 3,
                    static_cast<size_t>(d.x), static_cast<size_t>(d.y), static_cast<size_t>(d.z)))
        throw std::runtime_error(path.string() + ": " + teem::error());
    const glm::vec3 s = volume.spacing();
    nrrdAxisInfoSet_va(nrrd.get(), nrrdAxisInfoSpacing, double(s.x), double(s.y), double(s.z));
    std::unique_ptr<NrrdIoState, teem::NioDeleter> nio(nrrdIoStateNew());
    if (encoding == "gzip") {
        nio->encoding = nrrdEncodingGzip;
    } else if (encoding == "raw") {
        nio->encoding = nrrdEncodingRaw;
    } else {
        throw std::runtime_error("save_nrrd: unknown encoding " + std::string(encoding));
    }
    nio->detachedHeader = path.extension() == ".nhdr" ? AIR_TRUE : AIR_FALSE;
    const int rc = nrrdSave(path.c_str(), nrrd.get(), nio.get());
    nrrd->data = nullptr;  // owned by `copy`, not by Teem
    if (rc) throw std::runtime_error(path.string() + ": " + teem::error());
}

}  // namespace isowall
