#include "common/volume/volume.h"

#include <teem/nrrd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include "common/core/error.h"

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

Box3 Volume::bounds() const {
    Box3 b;
    b.merge(glm::vec3(0));
    b.merge(glm::vec3(dims_ - 1) * spacing_);
    return b;
}

namespace {

std::size_t expected_bytes(glm::ivec3 dims, VoxelType type) {
    return static_cast<std::size_t>(dims.x) * dims.y * dims.z * voxel_size(type);
}

void check_dims(const std::string& where, const std::string& field, glm::ivec3 dims) {
    if (dims.x < 2 || dims.y < 2 || dims.z < 2) {
        std::ostringstream os;
        os << "expected three sizes >= 2, got " << dims.x << " " << dims.y << " " << dims.z;
        throw InputError(where, field, os.str());
    }
}

// The exact-size rule: a data file shorter or longer than the header says is an error, since a
// wrong size almost always means wrong dims or type, and a silent crop would hide it.
void check_size(const std::string& file, std::size_t have, std::size_t offset, std::size_t need) {
    if (have < offset + need) {
        throw InputError(file, "size",
                         "file is shorter than the header says: expected " +
                             std::to_string(offset + need) + " bytes, found " +
                             std::to_string(have));
    }
    if (have > offset + need) {
        throw InputError(file, "size",
                         "file is longer than the header says: expected " +
                             std::to_string(offset + need) + " bytes, found " +
                             std::to_string(have));
    }
}

Volume read_swapped(const fs::path& path, glm::ivec3 dims, VoxelType type, glm::vec3 spacing,
                    std::size_t offset, std::string source) {
    const std::size_t need = expected_bytes(dims, type);
    std::vector<std::byte> bytes(need);
    std::ifstream in(path, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(need));
    if (!in)
        throw InputError(path.string(), "data", "cannot read " + std::to_string(need) + " bytes");
    swap_bytes(bytes, voxel_size(type));
    return Volume(dims, type, spacing, std::move(bytes), std::move(source));
}

// Teem reports a stack of messages, outermost first; the innermost one says what was wrong.
std::string teem_error() {
    char* raw = biffGetDone(NRRD);
    std::string all = raw ? raw : "unknown error";
    std::free(raw);
    std::string last;
    std::istringstream lines(all);
    for (std::string line; std::getline(lines, line);)
        if (!line.empty()) last = line;
    // Drop the "[nrrd] function: " prefix.
    if (auto p = last.find("] "); p != std::string::npos) last = last.substr(p + 2);
    if (auto p = last.find(": "); p != std::string::npos && p < 40) last = last.substr(p + 2);
    return last;
}

struct NrrdDeleter {
    void operator()(Nrrd* n) const { nrrdNuke(n); }
};
struct NioDeleter {
    void operator()(NrrdIoState* n) const { nrrdIoStateNix(n); }
};

std::optional<VoxelType> from_teem_type(int t) {
    switch (t) {
        case nrrdTypeUChar:
            return VoxelType::u8;
        case nrrdTypeChar:
            return VoxelType::i8;
        case nrrdTypeUShort:
            return VoxelType::u16;
        case nrrdTypeShort:
            return VoxelType::i16;
        case nrrdTypeUInt:
            return VoxelType::u32;
        case nrrdTypeInt:
            return VoxelType::i32;
        case nrrdTypeFloat:
            return VoxelType::f32;
        case nrrdTypeDouble:
            return VoxelType::f64;
        default:
            return std::nullopt;
    }
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

glm::vec3 nrrd_spacing(const Nrrd* n) {
    glm::vec3 s(1.0f);
    for (int i = 0; i < 3; ++i) {
        const NrrdAxisInfo& ax = n->axis[i];
        if (std::isfinite(ax.spacing) && ax.spacing > 0) {
            s[i] = static_cast<float>(ax.spacing);
        } else if (n->spaceDim > 0) {
            double len2 = 0;
            for (unsigned d = 0; d < n->spaceDim; ++d)
                if (std::isfinite(ax.spaceDirection[d]))
                    len2 += ax.spaceDirection[d] * ax.spaceDirection[d];
            if (len2 > 0) s[i] = static_cast<float>(std::sqrt(len2));
        }
    }
    return s;
}

// Offset of the first byte after an attached header's blank line.
std::optional<std::size_t> attached_data_offset(std::span<const std::byte> bytes) {
    for (std::size_t i = 0; i + 1 < bytes.size(); ++i) {
        if (bytes[i] != std::byte{'\n'}) continue;
        if (bytes[i + 1] == std::byte{'\n'}) return i + 2;
        if (bytes[i + 1] == std::byte{'\r'} && i + 2 < bytes.size() &&
            bytes[i + 2] == std::byte{'\n'})
            return i + 3;
    }
    return std::nullopt;
}

}  // namespace

Volume load_raw(const fs::path& path, const RawSpec& spec) {
    const std::string where = path.string();
    check_dims(where, "--dims", spec.dims);
    if (!fs::exists(path)) throw InputError(where, "file", "no such file");
    for (int i = 0; i < 3; ++i)
        if (!(spec.spacing[i] > 0) || !std::isfinite(spec.spacing[i]))
            throw InputError(where, "--spacing", "expected three positive numbers");
    const std::size_t need = expected_bytes(spec.dims, spec.type);
    MappedFile file(path);
    check_size(where, file.size(), spec.header_bytes, need);
    if (spec.endian != host_endian() && voxel_size(spec.type) > 1)
        return read_swapped(path, spec.dims, spec.type, spec.spacing, spec.header_bytes, where);
    return Volume(spec.dims, spec.type, spec.spacing, std::move(file), spec.header_bytes, where);
}

Volume load_nrrd(const fs::path& path) {
    const std::string where = path.string();
    if (!fs::exists(path)) throw InputError(where, "file", "no such file");
    std::unique_ptr<Nrrd, NrrdDeleter> nrrd(nrrdNew());
    std::unique_ptr<NrrdIoState, NioDeleter> nio(nrrdIoStateNew());
    // First pass: the header only, so raw data can be mapped instead of read.
    nio->skipData = AIR_TRUE;
    if (nrrdLoad(nrrd.get(), path.c_str(), nio.get()))
        throw InputError(where, "header", teem_error());
    if (nrrd->dim != 3)
        throw InputError(where, "dimension", "expected 3, got " + std::to_string(nrrd->dim));
    const auto type = from_teem_type(nrrd->type);
    if (!type)
        throw InputError(where, "type",
                         std::string("unsupported voxel type \"") +
                             airEnumStr(nrrdType, nrrd->type) +
                             "\" (expected one of uint8 int8 uint16 int16 uint32 "
                             "int32 float32 float64)");
    const glm::ivec3 dims(static_cast<int>(nrrd->axis[0].size),
                          static_cast<int>(nrrd->axis[1].size),
                          static_cast<int>(nrrd->axis[2].size));
    check_dims(where, "sizes", dims);
    const glm::vec3 spacing = nrrd_spacing(nrrd.get());
    const std::size_t need = expected_bytes(dims, *type);
    const bool raw = nio->encoding == nrrdEncodingRaw;
    const bool host_order = voxel_size(*type) == 1 ||
                            (nio->endian == airEndianLittle) == (host_endian() == Endian::little);
    const unsigned data_files = nio->dataFNArr ? nio->dataFNArr->len : 0;

    if (raw && data_files <= 1 && nio->lineSkip == 0) {
        fs::path data_path = path;
        if (data_files == 1) {
            data_path = nio->dataFN[0];
            if (data_path.is_relative()) data_path = path.parent_path() / data_path;
        }
        const std::string data_where = data_path.string();
        MappedFile file(data_path);
        std::size_t offset = 0;
        if (data_files == 0) {
            auto off = attached_data_offset(file.bytes());
            if (!off) throw InputError(where, "header", "no blank line ends the header");
            offset = *off;
        } else if (nio->byteSkip == -1) {
            // "byte skip: -1" means the data is the last bytes of the file.
            if (file.size() < need) check_size(data_where, file.size(), 0, need);
            offset = file.size() - need;
        } else {
            offset = static_cast<std::size_t>(nio->byteSkip);
        }
        check_size(data_where, file.size(), offset, need);
        if (host_order) return Volume(dims, *type, spacing, std::move(file), offset, where);
        return read_swapped(data_path, dims, *type, spacing, offset, where);
    }

    // Anything else (gzip, bzip2, ascii, hex, multiple files): let Teem decode it.
    std::unique_ptr<Nrrd, NrrdDeleter> full(nrrdNew());
    if (nrrdLoad(full.get(), path.c_str(), nullptr)) throw InputError(where, "data", teem_error());
    const auto* p = static_cast<const std::byte*>(full->data);
    std::vector<std::byte> bytes(p, p + need);
    return Volume(dims, *type, spacing, std::move(bytes), where);
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
    std::unique_ptr<Nrrd, NrrdDeleter> nrrd(nrrdNew());
    const glm::ivec3 d = volume.dims();
    if (nrrdWrap_va(nrrd.get(), copy.data(), to_teem_type(volume.type()), 3,
                    static_cast<size_t>(d.x), static_cast<size_t>(d.y), static_cast<size_t>(d.z)))
        throw std::runtime_error(path.string() + ": " + teem_error());
    const glm::vec3 s = volume.spacing();
    nrrdAxisInfoSet_va(nrrd.get(), nrrdAxisInfoSpacing, double(s.x), double(s.y), double(s.z));
    std::unique_ptr<NrrdIoState, NioDeleter> nio(nrrdIoStateNew());
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
    if (rc) throw std::runtime_error(path.string() + ": " + teem_error());
}

}  // namespace isowall
