// MetaImage (ITK's .mhd/.mha), read by hand: Debian has no MetaIO outside ITK and VTK, and the
// format is a few "Key = Value" lines ending with ElementDataFile, then raw or zlib voxels. The
// header is read as MetaIO reads it (the keys of its MetaImage, ElementDataFile last; HeaderSize
// -1 puts the data at the end of the file, and a positive HeaderSize counts from the start of the
// data file, LOCAL ones included); unknown keys are skipped, as MetaIO keeps them as user fields.
// Stricter than MetaIO: a line that is not "Key = Value", a key given twice, or data longer or
// shorter than the header says is an error, since each almost always means a damaged file.
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/geometric.hpp>

#include "core/error.h"
#include "core/number.h"
#include "readers/readers.h"
#include "readers/voxel_ops.h"
#include "volume/inflate_stream.h"
#include "volume/load_checks.h"
#include "volume/mapped_file.h"

namespace isowall::formats {
namespace fs = std::filesystem;
namespace {

// No MetaImage header comes near this; a file without ElementDataFile by then is not one.
constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
// Deflate inflates at most 1032 bytes per byte (zlib's FAQ); a header asking for more from its
// compressed bytes is refused before the voxels are allocated, so a small file cannot claim a
// buffer of gigabytes.
constexpr std::uint64_t kMaxInflateRatio = 1032;

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return out;
}

std::string_view trimmed(std::string_view s) {
    const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    while (!s.empty() && space(s.front())) s.remove_prefix(1);
    while (!s.empty() && space(s.back())) s.remove_suffix(1);
    return s;
}

// The header's lines as key -> value (keys matched without case, as people type them), and
// where the data of a LOCAL file starts: after the line of ElementDataFile, which ends a header.
struct HeaderText {
    std::map<std::string, std::string> values;  // lower-case key -> value
    std::size_t data_offset = 0;
};

// `text` is the start of the file; `whole` says whether it is all of it.
HeaderText split_lines(std::string_view text, bool whole, const std::string& where) {
    HeaderText h;
    std::map<std::string, int> line_of;
    std::size_t at = 0;
    for (int line = 1; at < text.size(); ++line) {
        std::size_t end = text.find('\n', at);
        if (end == std::string_view::npos && !whole) break;  // cut by the limit: no line
        if (end == std::string_view::npos) end = text.size();
        const std::string_view raw = text.substr(at, end - at);
        at = std::min(end + 1, text.size());
        if (trimmed(raw).empty()) continue;
        const std::size_t eq = raw.find('=');
        const std::string_view key = trimmed(raw.substr(0, eq == raw.npos ? 0 : eq));
        if (eq == raw.npos || key.empty())
            throw InputError(where, "line " + std::to_string(line),
                             "expected Key = Value, got " + quote(raw));
        const std::string k = lower(key);
        if (line_of.count(k))
            throw InputError(where, std::string(key),
                             "given twice (lines " + std::to_string(line_of[k]) + " and " +
                                 std::to_string(line) + ")");
        line_of[k] = line;
        h.values[k] = std::string(trimmed(raw.substr(eq + 1)));
        if (k == "elementdatafile") {
            h.data_offset = at;
            return h;
        }
    }
    throw InputError(where, "ElementDataFile",
                     whole ? std::string("missing (a MetaImage header ends with it)")
                           : "not within the first " + std::to_string(kMaxHeaderBytes) +
                                 " bytes (a header that long is not a MetaImage header)");
}

// One key's value, read into what the reader needs; every failure names the key.
class Keys {
  public:
    Keys(HeaderText h, std::string where) : h_(std::move(h)), where_(std::move(where)) {}

    const std::string* find(std::string_view key) const {
        const auto it = h_.values.find(lower(key));
        return it == h_.values.end() ? nullptr : &it->second;
    }
    const std::string& required(std::string_view key) const {
        if (const std::string* v = find(key)) return *v;
        throw InputError(where_, std::string(key), "missing (a MetaImage image needs it)");
    }
    // Exactly `count` finite numbers, or nullopt when the key is absent.
    std::optional<std::vector<double>> numbers(std::string_view key, std::size_t count) const {
        const std::string* v = find(key);
        if (!v) return std::nullopt;
        std::vector<double> out;
        std::size_t at = 0;
        while (true) {
            at = v->find_first_not_of(" \t", at);
            if (at == std::string::npos) break;
            const std::size_t end = std::min(v->find_first_of(" \t", at), v->size());
            const auto n = parse_number(std::string_view(*v).substr(at, end - at));
            if (!n || out.size() == count) fail(key, count, *v);
            out.push_back(*n);
            at = end;
        }
        if (out.size() != count) fail(key, count, *v);
        return out;
    }
    // A whole number in [lo, hi], or nullopt when the key is absent.
    std::optional<double> integer(std::string_view key, double lo, double hi) const {
        const std::string* v = find(key);
        if (!v) return std::nullopt;
        const NumberRange range{lo, hi, false, true};
        if (std::string p = number_problem(*v, range); !p.empty())
            throw InputError(where_, std::string(key), p);
        return *parse_number(*v);
    }
    std::optional<bool> boolean(std::string_view key) const {
        const std::string* v = find(key);
        if (!v) return std::nullopt;
        const std::string b = lower(*v);
        if (b == "true" || b == "1") return true;
        if (b == "false" || b == "0") return false;
        throw InputError(where_, std::string(key), "expected True or False, got " + quote(*v));
    }
    const std::string& where() const { return where_; }
    std::size_t data_offset() const { return h_.data_offset; }

  private:
    [[noreturn]] void fail(std::string_view key, std::size_t count, const std::string& v) const {
        throw InputError(where_, std::string(key),
                         "expected " + std::to_string(count) + " numbers, got " + quote(v));
    }
    HeaderText h_;
    std::string where_;
};

VoxelType element_type(const Keys& k) {
    static const std::map<std::string, VoxelType> kTypes = {
        {"MET_UCHAR", VoxelType::u8},   {"MET_CHAR", VoxelType::i8},
        {"MET_USHORT", VoxelType::u16}, {"MET_SHORT", VoxelType::i16},
        {"MET_UINT", VoxelType::u32},   {"MET_INT", VoxelType::i32},
        {"MET_FLOAT", VoxelType::f32},  {"MET_DOUBLE", VoxelType::f64}};
    const std::string& v = k.required("ElementType");
    const auto it = kTypes.find(v);
    if (it == kTypes.end())
        throw InputError(k.where(), "ElementType",
                         quote(v) +
                             " is not a type isowall reads (MET_UCHAR, MET_CHAR, "
                             "MET_USHORT, MET_SHORT, MET_UINT, MET_INT, MET_FLOAT, "
                             "MET_DOUBLE)");
    return it->second;
}

// The keys that make the voxels a single 3-D scalar image.
void check_image_keys(const Keys& k) {
    if (const std::string* t = k.find("ObjectType"); t && lower(*t) != "image")
        throw InputError(k.where(), "ObjectType", "expected Image, got " + quote(*t));
    if (const std::string& n = k.required("NDims"); n != "3")
        throw InputError(k.where(), "NDims", "expected 3 (a 3-D image), got " + quote(n));
    if (const std::string* c = k.find("ElementNumberOfChannels"); c && *c != "1")
        throw InputError(k.where(), "ElementNumberOfChannels",
                         "expected 1 (a scalar image), got " + quote(*c));
    if (k.boolean("BinaryData") == false)
        throw InputError(k.where(), "BinaryData",
                         "False (voxels as text) is not supported; isowall reads binary data");
}

glm::ivec3 dim_size(const Keys& k, VoxelType type) {
    k.required("DimSize");
    const std::vector<double> v = *k.numbers("DimSize", 3);
    std::uint64_t sizes[3];
    for (int a = 0; a < 3; ++a) {
        if (!(v[a] >= 0) || v[a] != std::floor(v[a]))
            throw InputError(k.where(), "DimSize",
                             "expected three whole numbers, got " + quote(k.required("DimSize")));
        sizes[a] = v[a] > INT_MAX ? std::uint64_t(INT_MAX) + 1 : std::uint64_t(v[a]);
    }
    return checked_dims(k.where(), "DimSize", sizes, type);
}

// The first of `keys` the header gives (MetaIO's aliases), with the numbers it holds.
struct Given {
    std::string key;
    std::vector<double> values;
};
std::optional<Given> first_of(const Keys& k, std::initializer_list<const char*> keys,
                              std::size_t count) {
    for (const char* key : keys)
        if (auto v = k.numbers(key, count)) return Given{key, std::move(*v)};
    return std::nullopt;
}

// TransformMatrix holds each axis's direction as three numbers in a row, which ITK makes the
// columns of its direction matrix (itkMetaImageIO.cxx: SetDirection(ii, row ii)); ITK and
// MetaImage space is LPS, ours.
glm::mat3 direction_axes(const Given& g, const std::string& where) {
    glm::mat3 axes;
    for (int c = 0; c < 3; ++c)
        axes[c] = glm::vec3(float(g.values[3 * c]), float(g.values[3 * c + 1]),
                            float(g.values[3 * c + 2]));
    for (int c = 0; c < 3; ++c) {
        const bool unit = std::abs(glm::length(axes[c]) - 1.0f) < 1e-3f;
        const bool square = std::abs(glm::dot(axes[c], axes[(c + 1) % 3])) < 1e-3f;
        if (!unit || !square)
            throw InputError(where, g.key,
                             "the three directions must be unit length and at right angles");
    }
    return axes;
}

void take_geometry(const Keys& k, Decoded& d) {
    if (const auto s = first_of(k, {"ElementSpacing", "ElementSize"}, 3)) {
        for (int a = 0; a < 3; ++a)  // finish_volume checks too, but could not name the key
            if (std::string p = spacing_problem(s->values[a], d.dims[a], a); !p.empty())
                throw InputError(k.where(), s->key, p);
        d.spacing = {float(s->values[0]), float(s->values[1]), float(s->values[2])};
        d.facts.push_back({"spacing from", s->key});
    } else {
        d.facts.push_back({"spacing from", "none in the file (1 1 1)"});
    }
    if (const auto o = first_of(k, {"Offset", "Position", "Origin"}, 3))
        d.orientation.origin = {float(o->values[0]), float(o->values[1]), float(o->values[2])};
    if (const auto m = first_of(k, {"TransformMatrix", "Rotation", "Orientation"}, 9)) {
        d.orientation.axes = direction_axes(*m, k.where());
        d.orientation.known = true;
        d.facts.push_back({"orientation from", m->key});
    } else {
        d.facts.push_back({"orientation from", "none in the file"});
    }
    if (const std::string* a = k.find("AnatomicalOrientation"))
        d.facts.push_back({"anatomical orientation", clip(*a, 20) + " (as written; not used)"});
}

// Where the stored voxels are: which file, from which byte, how many bytes.
struct DataPlace {
    fs::path file;
    std::uint64_t offset = 0, stored = 0;
    bool compressed = false;
};

fs::path data_file(const Keys& k, const fs::path& header) {
    const std::string& name = k.required("ElementDataFile");
    if (lower(name) == "local") return header;  // MetaIO takes LOCAL, Local and local
    if (name.starts_with("LIST") || name.find('%') != std::string::npos)
        throw InputError(k.where(), "ElementDataFile",
                         quote(name) +
                             ": a list or pattern of slice files is not supported; "
                             "isowall reads one data file (or LOCAL)");
    const fs::path p = header.parent_path() / name;  // an absolute name stays absolute
    check_regular_file(p, k.where(), "ElementDataFile");
    return p;
}

DataPlace data_place(const Keys& k, const fs::path& header, std::uint64_t voxel_bytes) {
    DataPlace p;
    p.file = data_file(k, header);
    p.compressed = k.boolean("CompressedData").value_or(false);
    const auto csize = k.integer("CompressedDataSize", 0, 9007199254740992.0);
    const double skip = k.integer("HeaderSize", -1, 9007199254740992.0).value_or(0);
    const std::uint64_t have = fs::file_size(p.file);
    p.offset = skip > 0 ? std::uint64_t(skip) : p.file == header ? k.data_offset() : 0;
    p.stored = p.compressed ? (csize ? std::uint64_t(*csize) : 0) : voxel_bytes;
    if (p.compressed && !csize) {  // the rest of the file, as MetaIO takes it
        if (skip < 0)
            throw InputError(k.where(), "HeaderSize",
                             "-1 (data at the end) needs CompressedDataSize when compressed");
        if (have < p.offset) check_size(p.file.string(), have, p.offset, 0);  // throws: too short
        p.stored = have - p.offset;
    }
    if (skip < 0) {
        if (have < p.stored) check_size(p.file.string(), have, 0, p.stored);  // throws: too short
        p.offset = have - p.stored;
    }
    check_size(p.file.string(), have, p.offset, p.stored);
    if (p.compressed && voxel_bytes / kMaxInflateRatio > p.stored)
        throw InputError(k.where(), "CompressedData",
                         std::to_string(p.stored) + " compressed bytes cannot hold the " +
                             std::to_string(voxel_bytes) +
                             " bytes DimSize and ElementType ask for");
    return p;
}

// MetaIO writes both byte-order keys and reads either; two that disagree leave no answer.
bool big_endian(const Keys& k) {
    const auto element = k.boolean("ElementByteOrderMSB");
    const auto binary = k.boolean("BinaryDataByteOrderMSB");
    if (element && binary && *element != *binary)
        throw InputError(k.where(), "ElementByteOrderMSB", "disagrees with BinaryDataByteOrderMSB");
    return element.value_or(binary.value_or(false));
}

}  // namespace

PlaneStack metaimage_planes(const fs::path& path) {
    const std::string where = path.string();
    check_regular_file(path, where, "file");
    std::string head(kMaxHeaderBytes, '\0');
    std::ifstream in(path, std::ios::binary);
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(std::size_t(in.gcount()));
    const bool whole = in.gcount() < std::streamsize(kMaxHeaderBytes) || in.peek() == EOF;
    const Keys k(split_lines(head, whole, where), where);

    check_image_keys(k);
    PlaneStack stack;
    Decoded& d = stack.head;
    d.type = element_type(k);
    d.dims = dim_size(k, d.type);
    take_geometry(k, d);
    const std::uint64_t need = voxel_bytes(d.dims, d.type);
    const DataPlace place = data_place(k, path, need);
    const bool swap = big_endian(k) != (host_endian() == Endian::big);
    d.format = "MetaImage";
    d.files = {path};
    if (place.file != path) d.files.push_back(place.file);
    if (place.compressed) d.facts.push_back({"compression", "zlib"});
    stack.size_field = "DimSize";
    // The data file is mapped, not read: a slab of planes is copied (or inflated) at a time.
    auto file = std::make_shared<MappedFile>(place.file, false);
    const std::span<const std::byte> data =
        file->bytes().subspan(place.offset, place.compressed ? place.stored : need);
    std::shared_ptr<InflateStream> inflate;
    if (place.compressed)
        inflate = std::make_shared<InflateStream>(data, need, where, "CompressedData");
    const std::size_t plane = std::size_t(d.dims.x) * d.dims.y * voxel_size(d.type);
    const std::size_t size = voxel_size(d.type);
    stack.read = [file, data, inflate, plane, size, swap](int z0, int z1, std::byte* to) {
        const std::size_t n = plane * std::size_t(z1 - z0);
        if (inflate)
            inflate->read(to, n);
        else
            std::memcpy(to, data.data() + plane * std::size_t(z0), n);
        if (swap) swap_bytes({to, n}, size);
    };
    return stack;
}

Volume read_metaimage(const fs::path& path) {
    return read_whole(metaimage_planes(path), path.string());
}

}  // namespace isowall::formats
