// load_nrrd: Teem parses the header text (nrrd_header.h keeps the data-location fields from it),
// and we locate and decode the data (nrrd_decode.h), so every size and skip is checked by us.
#include <cfloat>
#include <cmath>
#include <cstring>
#include <memory>

#include "core/error.h"
#include "volume/inflate_stream.h"
#include "volume/load_checks.h"
#include "volume/nrrd_decode.h"
#include "volume/nrrd_header.h"
#include "volume/plane_source.h"
#include "volume/teem_util.h"
#include "volume/volume.h"

namespace isowall {
namespace fs = std::filesystem;
namespace {

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

enum class Encoding { raw, gzip, bzip2, ascii, hex };

// What the loader needs from a header, every number checked.
struct NrrdInfo {
    glm::ivec3 dims{0};
    VoxelType type = VoxelType::u8;
    glm::vec3 spacing{1.0f};
    Encoding encoding = Encoding::raw;
    bool host_order = true;  // the file's byte order is ours (or it does not matter)
};

Encoding encoding_of(const NrrdIoState& nio, const std::string& where) {
    const std::string name = nio.encoding ? nio.encoding->name : "?";
    if (nio.encoding == nrrdEncodingRaw) return Encoding::raw;
    if (nio.encoding == nrrdEncodingGzip) return Encoding::gzip;
    if (nio.encoding == nrrdEncodingBzip2) return Encoding::bzip2;
    if (nio.encoding == nrrdEncodingAscii) return Encoding::ascii;
    if (nio.encoding == nrrdEncodingHex) return Encoding::hex;
    throw InputError(where, "encoding",
                     "\"" + name + "\" is not supported (expected raw, gzip, bzip2, ascii or hex)");
}

// The length of an axis's space direction; an InputError naming "space directions" when the axis
// has none ("none", or a NaN or infinite entry) or a zero vector: a space axis of a scalar volume
// has a direction.
double direction_length(const Nrrd& n, int axis, const std::string& where) {
    const NrrdAxisInfo& ax = n.axis[axis];
    double len2 = 0;
    for (unsigned d = 0; d < n.spaceDim; ++d) {
        if (!std::isfinite(ax.spaceDirection[d]))
            throw InputError(where, "space directions",
                             "axis " + std::to_string(axis) +
                                 " has no direction (\"none\" or a non-finite entry); each of the "
                                 "three space axes needs a vector");
        len2 += ax.spaceDirection[d] * ax.spaceDirection[d];
    }
    if (!(len2 > 0))
        throw InputError(where, "space directions",
                         "axis " + std::to_string(axis) + " is the zero vector");
    return std::sqrt(len2);
}

// An axis's spacing: `spacings` (its magnitude: negative means the axis runs backwards), else the
// length of its space direction, else 1. A `spacings` value must be a non-zero number: Teem reads
// "nan" as a missing value, which would silently become 1. It must survive as a positive float32
// and keep the volume's extent finite: geometry is float, and an infinite or zero spacing turns
// it into NaN.
float axis_spacing(const Nrrd& n, bool spacings_given, int axis, int size,
                   const std::string& where) {
    const NrrdAxisInfo& ax = n.axis[axis];
    double s = 1;
    const char* field = "spacings";
    if (spacings_given && !(std::isfinite(ax.spacing) && ax.spacing != 0)) {
        char msg[160];
        std::snprintf(msg, sizeof(msg), "axis %d: spacing %g (expected a finite non-zero number)",
                      axis, ax.spacing);
        throw InputError(where, field, msg);
    }
    if (spacings_given) {
        s = std::abs(ax.spacing);
    } else if (n.spaceDim > 0) {
        s = direction_length(n, axis, where);
        field = "space directions";
    }
    if (std::string p = spacing_problem(s, size, axis); !p.empty())
        throw InputError(where, field, p);
    return static_cast<float>(s);
}

NrrdInfo parse_info(const NrrdHeaderText& text, const std::string& where) {
    std::unique_ptr<Nrrd, teem::NrrdDeleter> nrrd(nrrdNew());
    std::unique_ptr<NrrdIoState, teem::NioDeleter> nio(nrrdIoStateNew());
    nio->skipData = AIR_TRUE;  // the text names no data file, so Teem opens nothing
    // Sizes whose bytes overflow are ours to name (Teem's words for it are vaguer).
    if (text.sizes.size() == 3) checked_dims(where, "sizes", text.sizes, VoxelType::u8);
    if (nrrdStringRead(nrrd.get(), text.teem_text.c_str(), nio.get()))
        throw InputError(where, "header", teem::error());
    if (nrrd->dim != 3)
        throw InputError(where, "dimension", "expected 3, got " + std::to_string(nrrd->dim));
    NrrdInfo info;
    const auto type = from_teem_type(nrrd->type);
    if (!type)
        throw InputError(where, "type",
                         std::string("unsupported voxel type \"") +
                             airEnumStr(nrrdType, nrrd->type) +
                             "\" (expected one of uint8 int8 uint16 int16 uint32 "
                             "int32 float32 float64)");
    info.type = *type;
    for (unsigned a = 0; a < 3; ++a) {
        const int kind = nrrd->axis[a].kind;
        if (kind != nrrdKindUnknown && !nrrdKindIsDomain(kind))
            throw InputError(where, "kinds",
                             "axis " + std::to_string(a) + " is \"" + airEnumStr(nrrdKind, kind) +
                                 "\", not a space axis (a scalar volume has three)");
    }
    // Our own reading of the sizes: Teem wraps numbers past 64 bits.
    info.dims = checked_dims(where, "sizes", text.sizes, info.type);
    for (int a = 0; a < 3; ++a)
        info.spacing[a] = axis_spacing(*nrrd, text.spacings_given, a, info.dims[a], where);
    info.encoding = encoding_of(*nio, where);
    info.host_order = voxel_size(info.type) == 1 || info.encoding == Encoding::ascii ||
                      (nio->endian == airEndianLittle) == (host_endian() == Endian::little);
    return info;
}

// The data file a detached header names, relative to the header's folder unless absolute.
fs::path data_path_of(const fs::path& header, const std::string& name) {
    fs::path p = name;
    return p.is_relative() ? header.parent_path() / p : p;
}

// The first byte of the data: after the line skip, then the byte skip (-1: the last `need` bytes,
// for raw data only, since only raw data has a known length).
std::size_t data_start(std::span<const std::byte> bytes, std::size_t offset,
                       const NrrdHeaderText& h, const NrrdInfo& info, std::uint64_t need,
                       const std::string& where, const std::string& data_where) {
    offset = skip_lines(bytes, offset, h.line_skip, data_where);
    if (h.byte_skip == -1) {
        if (info.encoding != Encoding::raw)
            throw InputError(where, "byte skip",
                             "-1 (data at the end of the file) needs raw encoding");
        if (bytes.size() - offset < need) check_size(data_where, bytes.size(), offset, need);
        return bytes.size() - static_cast<std::size_t>(need);
    }
    const auto skip = static_cast<std::uint64_t>(h.byte_skip);
    if (skip > bytes.size() - offset)
        throw InputError(data_where, "byte skip",
                         "skips " + std::to_string(skip) + " bytes, but only " +
                             std::to_string(bytes.size() - offset) + " are left in the file");
    return offset + static_cast<std::size_t>(skip);
}

std::vector<std::byte> decode(Encoding e, std::span<const std::byte> data, const NrrdInfo& info,
                              std::uint64_t need, const std::string& data_where) {
    switch (e) {
        case Encoding::gzip:
            return decode_gzip(data, need, data_where);
        case Encoding::bzip2:
            return decode_bzip2(data, need, data_where);
        case Encoding::hex:
            return decode_hex(data, need, data_where);
        case Encoding::ascii:
            return decode_ascii(data, info.type, need / voxel_size(info.type), data_where);
        case Encoding::raw:
            break;
    }
    std::vector<std::byte> bytes = allocate_voxels(need, data_where, "sizes");
    std::copy(data.begin(), data.end(), bytes.begin());
    return bytes;
}

}  // namespace

namespace {

// A NRRD file's header read and its data located (the data file mapped, not read).
struct NrrdData {
    NrrdInfo info;
    fs::path data_path;
    MappedFile file;
    std::size_t offset = 0;
    std::uint64_t need = 0;
};

NrrdData locate(const fs::path& path, bool populate) {
    const std::string where = path.string();
    check_regular_file(path, where, "file");
    MappedFile header_file(path);
    const NrrdHeaderText text = split_nrrd_header(header_file.bytes(), where);
    NrrdData d;
    d.info = parse_info(text, where);
    d.need = voxel_bytes(d.info.dims, d.info.type);
    d.data_path = path;
    if (text.data_file) {
        d.data_path = data_path_of(path, *text.data_file);
        check_regular_file(d.data_path, where, "data file");
        d.file = MappedFile(d.data_path, populate);
    } else {
        if (!text.data_offset)
            throw InputError(where, "header",
                             "no blank line ends the header and no data file is named");
        d.file = std::move(header_file);
        d.offset = *text.data_offset;
    }
    d.offset =
        data_start(d.file.bytes(), d.offset, text, d.info, d.need, where, d.data_path.string());
    if (d.info.encoding == Encoding::raw)
        check_size(d.data_path.string(), d.file.size(), d.offset, d.need);
    return d;
}

std::vector<fs::path> files_of(const fs::path& path, const NrrdData& d) {
    std::vector<fs::path> files{path};
    if (d.data_path != path) files.push_back(d.data_path);
    return files;
}

}  // namespace

Volume load_nrrd(const fs::path& path, bool populate) {
    const std::string where = path.string();
    NrrdData d = locate(path, populate);
    const NrrdInfo& info = d.info;
    const std::vector<fs::path> files = files_of(path, d);
    Volume volume;
    if (info.encoding == Encoding::raw && info.host_order) {
        volume = Volume(info.dims, info.type, info.spacing, std::move(d.file), d.offset, where);
    } else {
        std::vector<std::byte> bytes = decode(info.encoding, d.file.bytes().subspan(d.offset), info,
                                              d.need, d.data_path.string());
        if (!info.host_order) swap_bytes(bytes, voxel_size(info.type));
        volume = Volume(info.dims, info.type, info.spacing, std::move(bytes), where);
    }
    volume.set_files(files);
    return volume;
}

std::unique_ptr<PlaneSource> nrrd_planes(const fs::path& path, bool read_ahead) {
    auto d = std::make_shared<NrrdData>(locate(path, false));
    const NrrdInfo& info = d->info;
    const bool gzip = info.encoding == Encoding::gzip;
    if (!gzip && !(info.encoding == Encoding::raw && !info.host_order)) return nullptr;
    const std::size_t plane = std::size_t(info.dims.x) * info.dims.y * voxel_size(info.type);
    std::shared_ptr<InflateStream> inflate;
    if (gzip)
        inflate = std::make_shared<InflateStream>(d->file.bytes().subspan(d->offset), d->need,
                                                  d->data_path.string(), "data");
    auto decode = [d, inflate, plane](int z0, int z1, std::byte* to) {
        const std::size_t n = plane * std::size_t(z1 - z0);
        if (inflate)
            inflate->read(to, n);
        else
            std::memcpy(to, d->file.bytes().data() + d->offset + plane * std::size_t(z0), n);
        if (!d->info.host_order) swap_bytes({to, n}, voxel_size(d->info.type));
    };
    return std::make_unique<DecodedPlanes>(info.dims, info.type, info.spacing, path.string(),
                                           std::move(decode), read_ahead);
}

}  // namespace isowall
