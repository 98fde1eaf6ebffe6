#include "readers/zarr_reader.h"

#include <blosc.h>
#include <lz4.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "files/input_file.h"
#include "readers/http_fetch.h"
#include "readers/plane_stack.h"
#include "readers/voxel_ops.h"
#include "volume/load_checks.h"

namespace isowall::formats {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr std::size_t kMaxMetadataBytes = std::size_t{1} << 20;
// A chunk decoded at most: larger chunks than this are not a volume's (and would be a claim to
// check before any allocation).
constexpr std::size_t kMaxChunkBytes = std::size_t{1} << 30;
// Chunks a store may have (16 M: 256^3 chunks of 8^3 voxels, a 2048^3 volume).
constexpr std::uint64_t kMaxChunks = std::uint64_t{1} << 24;

// A store's keys in a folder (the key's path below it).
class FolderSource : public ZarrSource {
  public:
    explicit FolderSource(fs::path dir) : dir_(std::move(dir)) {}
    std::optional<std::string> get(const std::string& key, std::size_t max_bytes) const override {
        const fs::path file = dir_ / key;
        std::error_code ec;
        if (!fs::exists(file, ec)) return std::nullopt;
        const std::string field = key.find(".z") != std::string::npos ? "metadata" : "chunk";
        // Sized by the file (read_input_file would hold max_bytes, a gigabyte for a chunk).
        if (!fs::is_regular_file(file, ec)) throw InputError(file.string(), field, "not a file");
        const auto size = fs::file_size(file, ec);
        if (ec || size > max_bytes)
            throw InputError(
                file.string(), field,
                ec ? "cannot be read" : "larger than " + std::to_string(max_bytes) + " bytes");
        std::string bytes(static_cast<std::size_t>(size), '\0');
        std::ifstream in(file, std::ios::binary);
        if (!in.read(bytes.data(), static_cast<std::streamsize>(size)))
            throw InputError(file.string(), field, "cannot be read");
        return bytes;
    }
    std::string where(const std::string& key) const override { return (dir_ / key).string(); }
    fs::path file(const std::string& key) const override { return dir_ / key; }

  private:
    fs::path dir_;
};

// Objects under one URL (http_fetch.h).
class UrlSource : public ZarrSource {
  public:
    UrlSource(std::string base, const HttpOptions& options)
        : base_(std::move(base)), fetch_(options) {
        while (base_.ends_with("/")) base_.pop_back();
    }
    std::optional<std::string> get(const std::string& key, std::size_t max_bytes) const override {
        return fetch_.get(where(key), key.find(".z") != std::string::npos ? "metadata" : "chunk",
                          max_bytes);
    }
    std::string where(const std::string& key) const override { return base_ + "/" + key; }

  private:
    std::string base_;
    HttpFetcher fetch_;
};

json parse_json(const std::string& text, const std::string& where) {
    try {
        return json::parse(text);
    } catch (const json::exception& e) {
        throw InputError(where, "JSON", e.what());
    }
}

// `key`'s JSON; an InputError where the store has none.
json read_json(const ZarrSource& s, const std::string& key) {
    const auto text = s.get(key, kMaxMetadataBytes);
    if (!text) throw InputError(s.where(key), "metadata", "not found");
    return parse_json(*text, s.where(key));
}

struct ZarrArray {
    std::string prefix;                       // the array's keys start with this ("" or "0/")
    std::string where;                        // its .zarray, for messages
    std::vector<std::int64_t> shape, chunks;  // slowest axis first, as Zarr lists them
    VoxelType type = VoxelType::u8;
    bool big_endian = false;
    bool fortran = false;            // order "F": the first axis varies fastest in a chunk
    std::string separator;           // between a chunk key's indices: "." or "/"
    json compressor;                 // null: none
    json fill;                       // null: 0
    std::vector<std::int64_t> pick;  // the element taken on each axis before z, y, x

    std::size_t item() const { return voxel_size(type); }
    std::size_t chunk_elements() const {
        std::size_t n = 1;
        for (std::int64_t c : chunks) n *= static_cast<std::size_t>(c);
        return n;
    }
};

[[noreturn]] void bad(const std::string& where, const std::string& field, const std::string& why) {
    throw InputError(where, field, why);
}

VoxelType dtype_of(const std::string& file, const std::string& dtype, bool& big_endian) {
    if (dtype.size() < 3 || (dtype[0] != '<' && dtype[0] != '>' && dtype[0] != '|'))
        bad(file, "dtype", "expected a NumPy type string such as \"<u2\", got " + quote(dtype));
    big_endian = dtype[0] == '>';
    const std::string t = dtype.substr(1);
    if (t == "u1") return VoxelType::u8;
    if (t == "i1") return VoxelType::i8;
    if (t == "u2") return VoxelType::u16;
    if (t == "i2") return VoxelType::i16;
    if (t == "u4") return VoxelType::u32;
    if (t == "i4") return VoxelType::i32;
    if (t == "f4") return VoxelType::f32;
    if (t == "f8") return VoxelType::f64;
    bad(file, "dtype",
        quote(dtype) + " is not a voxel type isowall reads (u1 i1 u2 i2 u4 i4 f4 f8)");
}

std::vector<std::int64_t> sizes(const std::string& file, const json& za, const char* field) {
    const auto it = za.find(field);
    if (it == za.end() || !it->is_array() || it->empty() || it->size() > 8)
        bad(file, field, "expected a list of 1 to 8 sizes");
    std::vector<std::int64_t> out;
    for (const json& v : *it) {
        if (!v.is_number_integer() || v.get<std::int64_t>() < 1 ||
            v.get<std::int64_t>() > std::numeric_limits<int>::max())
            bad(file, field, "expected sizes from 1 to 2147483647, got " + quote(it->dump()));
        out.push_back(v.get<std::int64_t>());
    }
    return out;
}

ZarrArray read_zarray(const ZarrSource& source, const std::string& prefix) {
    const std::string file = source.where(prefix + ".zarray");
    const json za = read_json(source, prefix + ".zarray");
    if (!za.is_object()) bad(file, "metadata", "expected a JSON object");
    if (za.value("zarr_format", 0) != 2)
        bad(file, "zarr_format",
            "expected 2 (Zarr v2), got " + quote(za.value("zarr_format", json()).dump()));
    ZarrArray a;
    a.prefix = prefix;
    a.where = file;
    a.shape = sizes(file, za, "shape");
    a.chunks = sizes(file, za, "chunks");
    if (a.chunks.size() != a.shape.size())
        bad(file, "chunks",
            "expected one size per axis of the shape (" + std::to_string(a.shape.size()) +
                "), got " + std::to_string(a.chunks.size()));
    if (a.shape.size() < 3)
        bad(file, "shape",
            "a volume has three axes (z, y, x), got " + std::to_string(a.shape.size()));
    if (!za.contains("dtype") || !za["dtype"].is_string())
        bad(file, "dtype", "expected a NumPy type string (a structured dtype is not a volume)");
    a.type = dtype_of(file, za["dtype"].get<std::string>(), a.big_endian);
    if (a.chunk_elements() > kMaxChunkBytes / a.item())
        bad(file, "chunks", "a chunk of more than 1 GiB");
    const std::string order = za.value("order", std::string("C"));
    if (order != "C" && order != "F")
        bad(file, "order", "expected \"C\" or \"F\", got " + quote(order));
    a.fortran = order == "F";
    if (za.contains("filters") && !za["filters"].is_null() && !za["filters"].empty())
        bad(file, "filters",
            "isowall reads arrays without filters, got " + quote(za["filters"].dump()));
    a.separator = za.value("dimension_separator", std::string("."));
    if (a.separator != "." && a.separator != "/")
        bad(file, "dimension_separator", "expected \".\" or \"/\", got " + quote(a.separator));
    a.compressor = za.value("compressor", json());
    if (!a.compressor.is_null()) {
        const std::string id = a.compressor.value("id", std::string());
        if (id != "blosc" && id != "zstd" && id != "gzip" && id != "zlib" && id != "lz4")
            bad(file, "compressor",
                "isowall decodes blosc, zstd, gzip, zlib, lz4 or none, got " +
                    quote(a.compressor.dump()));
    }
    a.fill = za.value("fill_value", json());
    return a;
}

// The fill value as `type`'s bytes.
std::vector<std::byte> fill_bytes(const ZarrArray& a) {
    double v = 0;
    if (a.fill.is_number()) {
        v = a.fill.get<double>();
    } else if (a.fill.is_string()) {
        const std::string s = a.fill.get<std::string>();
        if (s == "NaN")
            v = std::numeric_limits<double>::quiet_NaN();
        else if (s == "Infinity")
            v = std::numeric_limits<double>::infinity();
        else if (s == "-Infinity")
            v = -std::numeric_limits<double>::infinity();
        else
            bad(a.where, "fill_value", "expected a number, null, NaN or Infinity, got " + quote(s));
    } else if (!a.fill.is_null()) {
        bad(a.where, "fill_value", "expected a number or null, got " + quote(a.fill.dump()));
    }
    std::vector<std::byte> out(a.item());
    auto put = [&out](auto x) { std::memcpy(out.data(), &x, sizeof x); };
    switch (a.type) {
        case VoxelType::u8:
            put(static_cast<std::uint8_t>(v));
            break;
        case VoxelType::i8:
            put(static_cast<std::int8_t>(v));
            break;
        case VoxelType::u16:
            put(static_cast<std::uint16_t>(v));
            break;
        case VoxelType::i16:
            put(static_cast<std::int16_t>(v));
            break;
        case VoxelType::u32:
            put(static_cast<std::uint32_t>(v));
            break;
        case VoxelType::i32:
            put(static_cast<std::int32_t>(v));
            break;
        case VoxelType::f32:
            put(static_cast<float>(v));
            break;
        case VoxelType::f64:
            put(v);
            break;
    }
    return out;  // host order
}

// One chunk's bytes decoded into `out` (exactly the chunk's size), or an InputError naming it.
void decode_chunk(const ZarrArray& a, const std::string& in, const std::string& file,
                  std::vector<std::byte>& out) {
    const std::size_t want = out.size();
    auto wrong = [&](const std::string& why) { bad(file, "chunk", why); };
    auto size_check = [&](std::size_t got) {
        if (got != want)
            wrong("decodes to " + std::to_string(got) + " bytes, expected " + std::to_string(want));
    };
    const std::string id = a.compressor.is_null() ? "" : a.compressor.value("id", std::string());
    if (id.empty()) {
        size_check(in.size());
        std::memcpy(out.data(), in.data(), want);
    } else if (id == "blosc") {
        std::size_t nbytes = 0;
        if (blosc_cbuffer_validate(in.data(), in.size(), &nbytes) != 0)
            wrong("not a Blosc buffer, or cut short");
        size_check(nbytes);
        if (blosc_decompress_ctx(in.data(), out.data(), want, 1) != static_cast<int>(want))
            wrong("Blosc could not decode it");
    } else if (id == "zstd") {
        const unsigned long long n = ZSTD_getFrameContentSize(in.data(), in.size());
        if (n == ZSTD_CONTENTSIZE_ERROR) wrong("not a zstd frame");
        if (n != ZSTD_CONTENTSIZE_UNKNOWN) size_check(static_cast<std::size_t>(n));
        const std::size_t got = ZSTD_decompress(out.data(), want, in.data(), in.size());
        if (ZSTD_isError(got)) wrong(std::string("zstd: ") + ZSTD_getErrorName(got));
        size_check(got);
    } else if (id == "gzip" || id == "zlib") {
        z_stream z{};
        if (inflateInit2(&z, 15 + 32) != Z_OK) wrong("zlib could not start");  // gzip or zlib
        z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
        z.avail_in = static_cast<uInt>(in.size());
        z.next_out = reinterpret_cast<Bytef*>(out.data());
        z.avail_out = static_cast<uInt>(want);
        const int r = inflate(&z, Z_FINISH);
        const std::size_t got = z.total_out;
        inflateEnd(&z);
        if (r != Z_STREAM_END && z.avail_out == 0)
            wrong("decodes to more than " + std::to_string(want) + " bytes, expected " +
                  std::to_string(want));
        if (r != Z_STREAM_END) wrong(id + ": the stream is damaged or cut short");
        size_check(got);
    } else {  // lz4, as numcodecs frames it: the decoded size (u32 little-endian), then one block
        if (in.size() < 4) wrong("lz4: shorter than its 4-byte size");
        std::uint32_t n;
        std::memcpy(&n, in.data(), 4);
        size_check(n);
        const int got =
            LZ4_decompress_safe(in.data() + 4, reinterpret_cast<char*>(out.data()),
                                static_cast<int>(in.size() - 4), static_cast<int>(want));
        if (got < 0) wrong("lz4: the block is damaged");
        size_check(static_cast<std::size_t>(got));
    }
}

std::string chunk_key(const ZarrArray& a, std::int64_t z, std::int64_t y, std::int64_t x) {
    std::string key;
    for (std::size_t i = 0; i + 3 < a.shape.size(); ++i)
        key += std::to_string(a.pick[i] / a.chunks[i]) + a.separator;
    return key + std::to_string(z) + a.separator + std::to_string(y) + a.separator +
           std::to_string(x);
}

// The array's planes (x fastest, host order) a slab at a time, from the rows of chunks that
// cross them (a row: the chunks of one chunk-index along z). A slab that ends inside a row keeps
// the row decoded for the next slab, so each chunk is decoded once in a stream of slabs; a row
// wholly inside the slab asked for is put straight into it.
class ChunkRows {
  public:
    ChunkRows(std::shared_ptr<const ZarrSource> source, ZarrArray a, glm::ivec3 dims)
        : source_(std::move(source)), a_(std::move(a)), dims_(dims), fill_(fill_bytes(a_)) {
        const std::size_t k = a_.shape.size();
        // Element strides of each axis within a chunk: C order has the last axis fastest.
        std::vector<std::size_t> stride(k, 1);
        if (a_.fortran)
            for (std::size_t i = 1; i < k; ++i)
                stride[i] = stride[i - 1] * static_cast<std::size_t>(a_.chunks[i - 1]);
        else
            for (std::size_t i = k - 1; i-- > 0;)
                stride[i] = stride[i + 1] * static_cast<std::size_t>(a_.chunks[i + 1]);
        sz_ = stride[k - 3], sy_ = stride[k - 2], sx_ = stride[k - 1];
        for (std::size_t i = 0; i + 3 < k; ++i)
            picked_ += static_cast<std::size_t>(a_.pick[i] % a_.chunks[i]) * stride[i];
        // The voxels are swapped to host order once placed, the fill with them: file order.
        if (a_.big_endian) std::reverse(fill_.begin(), fill_.end());
        chunk_.resize(a_.chunk_elements() * a_.item());
    }

    void read(int z0, int z1, std::byte* to) {
        const std::int64_t cz = a_.chunks[a_.shape.size() - 3];
        for (std::int64_t bz = z0 / cz; bz * cz < z1; ++bz) {
            const std::int64_t r0 = bz * cz, r1 = std::min<std::int64_t>(r0 + cz, dims_.z);
            const std::int64_t lo = std::max<std::int64_t>(z0, r0), hi = std::min<std::int64_t>(z1, r1);
            if (lo == r0 && hi == r1) {
                put_row(bz, to + static_cast<std::size_t>(r0 - z0) * plane());
            } else {
                if (row_ != bz) {
                    row_bytes_.resize(static_cast<std::size_t>(r1 - r0) * plane());
                    put_row(bz, row_bytes_.data());
                    row_ = bz;
                }
                std::memcpy(to + static_cast<std::size_t>(lo - z0) * plane(),
                            row_bytes_.data() + static_cast<std::size_t>(lo - r0) * plane(),
                            static_cast<std::size_t>(hi - lo) * plane());
            }
        }
        if (a_.big_endian && a_.item() > 1)
            swap_bytes({to, static_cast<std::size_t>(z1 - z0) * plane()}, a_.item());
    }

    bool keep_files = false;      // whether to list the chunk files read (a whole read's)
    std::vector<fs::path> files;  // the chunk files read, where the source has files

  private:
    std::size_t plane() const { return static_cast<std::size_t>(dims_.x) * dims_.y * a_.item(); }

    // Row `bz`'s planes into `out` (file order): every chunk of it read, decoded and put in.
    void put_row(std::int64_t bz, std::byte* out) {
        const std::size_t k = a_.shape.size(), e = a_.item();
        const std::int64_t cz = a_.chunks[k - 3], cy = a_.chunks[k - 2], cx = a_.chunks[k - 1];
        const std::int64_t nz = std::min(cz, dims_.z - bz * cz);
        const std::size_t n = static_cast<std::size_t>(nz) * dims_.x * dims_.y;
        if (std::any_of(fill_.begin(), fill_.end(), [](std::byte b) { return b != std::byte{0}; }))
            for (std::size_t i = 0; i < n; ++i) std::memcpy(out + i * e, fill_.data(), e);
        else
            std::memset(out, 0, n * e);
        for (std::int64_t by = 0; by * cy < dims_.y; ++by)
            for (std::int64_t bx = 0; bx * cx < dims_.x; ++bx) {
                const std::string key = a_.prefix + chunk_key(a_, bz, by, bx);
                const auto bytes = source_->get(key, kMaxChunkBytes + (1 << 20));
                if (!bytes) continue;  // a missing chunk is the fill value
                decode_chunk(a_, *bytes, source_->where(key), chunk_);
                if (keep_files && !source_->file(key).empty()) files.push_back(source_->file(key));
                const std::int64_t ny = std::min(cy, dims_.y - by * cy),
                                   nx = std::min(cx, dims_.x - bx * cx);
                for (std::int64_t z = 0; z < nz; ++z)
                    for (std::int64_t y = 0; y < ny; ++y)
                        put_chunk_row(out, z, by * cy + y, bx * cx, nx,
                                      picked_ + static_cast<std::size_t>(z) * sz_ +
                                          static_cast<std::size_t>(y) * sy_);
            }
    }

    // `nx` voxels of the decoded chunk from element `base` on (x stride sx_) into plane z, row y,
    // from column x of `out`.
    void put_chunk_row(std::byte* out, std::int64_t z, std::int64_t y, std::int64_t x,
                       std::int64_t nx, std::size_t base) const {
        const std::size_t e = a_.item();
        std::byte* row = out + ((static_cast<std::size_t>(z) * dims_.y + static_cast<std::size_t>(y)) *
                                    dims_.x +
                                static_cast<std::size_t>(x)) *
                                   e;
        if (sx_ == 1) {
            std::memcpy(row, chunk_.data() + base * e, static_cast<std::size_t>(nx) * e);
            return;
        }
        for (std::int64_t i = 0; i < nx; ++i)
            std::memcpy(row + static_cast<std::size_t>(i) * e,
                        chunk_.data() + (base + static_cast<std::size_t>(i) * sx_) * e, e);
    }

    std::shared_ptr<const ZarrSource> source_;
    ZarrArray a_;
    glm::ivec3 dims_;
    std::vector<std::byte> fill_;
    std::size_t sz_ = 0, sy_ = 0, sx_ = 0, picked_ = 0;
    std::vector<std::byte> chunk_;
    std::int64_t row_ = -1;  // the row held in row_bytes_
    std::vector<std::byte> row_bytes_;
};

// The spacing (x, y, z) of an OME-Zarr dataset: its "scale" transform's last three values (z, y,
// x), times the multiscale's own scale where it has one.
glm::vec3 ome_spacing(const std::string& file, const json& multiscale, const json& dataset) {
    glm::vec3 spacing(1.0f);
    auto apply = [&](const json& transforms, const std::string& where) {
        if (!transforms.is_array()) return;
        for (const json& t : transforms) {
            if (!t.is_object() || t.value("type", std::string()) != "scale") continue;
            const json& s = t.value("scale", json());
            if (!s.is_array() || s.size() < 3)
                bad(file, where + ".scale", "expected a list of at least three numbers");
            for (int i = 0; i < 3; ++i) {
                const json& v = s[s.size() - 1 - static_cast<std::size_t>(i)];
                if (!v.is_number() || !(v.get<double>() > 0) || !std::isfinite(v.get<double>()))
                    bad(file, where + ".scale",
                        "expected positive finite numbers, got " + quote(s.dump()));
                spacing[i] *= static_cast<float>(v.get<double>());
            }
        }
    };
    apply(dataset.value("coordinateTransformations", json()),
          "datasets[0].coordinateTransformations");
    apply(multiscale.value("coordinateTransformations", json()),
          "multiscales[0].coordinateTransformations");
    return spacing;
}

// The element of each axis before z, y and x that `selection` ("t=3,c=0") picks, the axes named
// by `names` (OME's; else their index). An axis of one element needs no pick.
std::vector<std::int64_t> pick_axes(const ZarrArray& a, const std::vector<std::string>& names,
                                    const std::string& selection, const std::string& where) {
    const std::size_t lead = a.shape.size() - 3;
    std::vector<std::int64_t> pick(lead, -1);
    auto bad_pick = [&](const std::string& why) { throw InputError(where, "axes", why); };
    std::string all;
    for (std::size_t i = 0; i < lead; ++i) all += (i ? ", " : "") + names[i];
    std::size_t at = 0;
    while (at < selection.size()) {
        const std::size_t end = std::min(selection.find(',', at), selection.size());
        const std::string item = selection.substr(at, end - at);
        at = end + 1;
        const std::size_t eq = item.find('=');
        const std::string name = item.substr(0, eq);
        const auto it =
            std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(lead), name);
        if (eq == std::string::npos || it == names.begin() + static_cast<std::ptrdiff_t>(lead))
            bad_pick("expected AXIS=INDEX for an axis before z, y, x (" +
                     (all.empty() ? "none" : all) + "), got " + quote(item));
        const std::size_t i = static_cast<std::size_t>(it - names.begin());
        const std::string number = item.substr(eq + 1);
        std::int64_t n = -1;
        if (!number.empty() && number.size() < 10 &&
            std::all_of(number.begin(), number.end(),
                        [](unsigned char c) { return std::isdigit(c); }))
            n = std::stoll(number);
        if (n < 0 || n >= a.shape[i])
            bad_pick(name + "=" + number + ": axis " + name + " has " + std::to_string(a.shape[i]) +
                     " elements, expected an index from 0 to " + std::to_string(a.shape[i] - 1));
        pick[i] = n;
    }
    for (std::size_t i = 0; i < lead; ++i) {
        if (pick[i] >= 0) continue;
        if (a.shape[i] != 1)
            bad_pick("axis " + names[i] + " has " + std::to_string(a.shape[i]) +
                     " elements (a time series or several channels): pick one, e.g. " + where +
                     ":" + names[i] + "=0");
        pick[i] = 0;
    }
    return pick;
}

}  // namespace

bool is_foreign_zarr(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_directory(path, ec)) return false;
    if (fs::exists(path / ".zarray", ec)) return true;
    if (!fs::exists(path / ".zattrs", ec)) return false;
    try {
        const json at = read_json(FolderSource(path), ".zattrs");
        return at.is_object() && at.contains("multiscales") && !at.contains("isowall");
    } catch (const InputError&) {
        return false;  // not readable as Zarr metadata: the other readers say what it is
    }
}

Volume read_zarr(const fs::path& path, const std::string& selection) {
    return read_zarr(std::make_shared<FolderSource>(path), path.string(), selection);
}

Volume read_zarr_url(const std::string& url, const std::string& selection,
                     const HttpOptions& options) {
    return read_zarr(std::make_shared<UrlSource>(url, options), url, selection);
}

PlaneStack zarr_planes(const fs::path& path, const std::string& selection) {
    return zarr_planes(std::make_shared<FolderSource>(path), path.string(), selection);
}

PlaneStack zarr_url_planes(const std::string& url, const std::string& selection,
                           const HttpOptions& options) {
    return zarr_planes(std::make_shared<UrlSource>(url, options), url, selection);
}

namespace {

// The array `source` holds (an OME image's first dataset), its axes before z, y, x picked by
// `selection`, as a plane stack whose `read` puts the chunks' voxels in host order.
struct OpenedArray {
    PlaneStack stack;
    std::shared_ptr<ChunkRows> rows;
};

OpenedArray open_array(std::shared_ptr<const ZarrSource> source, const std::string& name,
                       const std::string& selection) {
    std::string prefix;
    glm::vec3 spacing(1.0f);
    std::vector<fs::path> files;
    std::string what = "Zarr v2 array";
    std::vector<std::string> names;  // OME's axis names, slowest first
    std::optional<std::string> zarray = source->get(".zarray", kMaxMetadataBytes);
    if (!zarray) {
        const std::string file = source->where(".zattrs");
        const json at = read_json(*source, ".zattrs");
        const json& ms = at.is_object() ? at.value("multiscales", json()) : json();
        if (!ms.is_array() || ms.empty() || !ms[0].is_object())
            bad(file, "multiscales",
                "expected a list of OME-Zarr multiscales (or a .zarray beside it)");
        const json& ds = ms[0].value("datasets", json());
        if (!ds.is_array() || ds.empty() || !ds[0].is_object() ||
            !ds[0].value("path", json()).is_string())
            bad(file, "multiscales[0].datasets", "expected a list of datasets, each with a path");
        const std::string sub = ds[0]["path"].get<std::string>();
        if (sub.empty() || sub.find("..") != std::string::npos || sub.front() == '/' ||
            sub.find_first_of("?#") != std::string::npos)
            bad(file, "multiscales[0].datasets[0].path",
                "expected a folder inside the store, got " + quote(sub));
        prefix = sub + "/";
        spacing = ome_spacing(file, ms[0], ds[0]);
        for (const json& ax : ms[0].value("axes", json::array()))  // 0.4: objects; 0.3: names
            names.push_back(ax.is_string() ? ax.get<std::string>()
                                           : ax.value("name", std::string()));
        if (!source->file(".zattrs").empty()) files.push_back(source->file(".zattrs"));
        what = "OME-Zarr " + ms[0].value("version", std::string("0.4")) + " (dataset " +
               quote(sub) + ")";
    }
    ZarrArray a = read_zarray(*source, prefix);
    if (names.size() != a.shape.size()) {  // no names, or not one per axis: their indices
        names.clear();
        for (std::size_t i = 0; i < a.shape.size(); ++i) names.push_back(std::to_string(i));
    }
    a.pick = pick_axes(a, names, selection, name);
    if (!source->file(prefix + ".zarray").empty())
        files.insert(files.begin(), source->file(prefix + ".zarray"));
    const std::size_t k = a.shape.size();
    const std::uint64_t sides[3] = {static_cast<std::uint64_t>(a.shape[k - 1]),
                                    static_cast<std::uint64_t>(a.shape[k - 2]),
                                    static_cast<std::uint64_t>(a.shape[k - 3])};
    const glm::ivec3 dims = checked_dims(a.where, "shape", sides, a.type);
    // A chunk key per chunk of the grid is looked up: a grid of millions of tiny chunks over a
    // large shape would take hours to find missing.
    std::uint64_t grid = 1;
    for (int i = 0; i < 3; ++i)
        grid *= (sides[i] +
                 static_cast<std::uint64_t>(a.chunks[k - 1 - static_cast<std::size_t>(i)]) - 1) /
                static_cast<std::uint64_t>(a.chunks[k - 1 - static_cast<std::size_t>(i)]);
    if (grid > kMaxChunks)
        bad(a.where, "chunks",
            std::to_string(grid) + " chunks; isowall reads stores of at most " +
                std::to_string(kMaxChunks) +
                " (larger chunks, or `isowall import` from the source)");
    OpenedArray out;
    Decoded& d = out.stack.head;
    d.dims = dims;
    d.type = a.type;
    d.spacing = spacing;
    d.format = what;
    d.files = std::move(files);
    const std::string codec =
        a.compressor.is_null() ? "none" : a.compressor.value("id", std::string());
    std::string chunks;
    for (std::size_t i = 0; i < k; ++i) chunks += (i ? "x" : "") + std::to_string(a.chunks[i]);
    d.facts.push_back({"chunks", chunks + " (" + (a.fortran ? "F" : "C") + " order, " + codec + ")"});
    out.stack.size_field = "shape";
    out.rows = std::make_shared<ChunkRows>(std::move(source), std::move(a), dims);
    out.stack.read = [rows = out.rows](int z0, int z1, std::byte* to) { rows->read(z0, z1, to); };
    return out;
}

}  // namespace

PlaneStack zarr_planes(std::shared_ptr<const ZarrSource> source, const std::string& name,
                       const std::string& selection) {
    return open_array(std::move(source), name, selection).stack;
}

Volume read_zarr(std::shared_ptr<const ZarrSource> source, const std::string& name,
                 const std::string& selection) {
    OpenedArray opened = open_array(std::move(source), name, selection);
    Decoded& d = opened.stack.head;
    const std::uint64_t need = voxel_bytes(d.dims, d.type);
    check_fits_memory(need, name, "shape");
    d.bytes = allocate_voxels(need, name, "shape");
    opened.rows->keep_files = true;
    opened.rows->read(0, d.dims.z, d.bytes.data());
    // The chunk files join the metadata's: the octree cache's key covers every one.
    d.files.insert(d.files.end(), opened.rows->files.begin(), opened.rows->files.end());
    return finish_volume(std::move(d), name, "");
}

}  // namespace isowall::formats
