#include "readers/zarr_array.h"

#include <blosc.h>
#include <lz4.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <string_view>

#include "core/error.h"
#include "readers/voxel_ops.h"
#include "volume/volume.h"

namespace isowall::formats::zarr {

using nlohmann::json;

namespace {

[[noreturn]] void bad(const std::string& where, const std::string& field, const std::string& why) {
    throw InputError(where, field, why);
}

}  // namespace

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

namespace {

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

}  // namespace

ZarrArray read_v2_array(const ZarrSource& source, const std::string& prefix) {
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
    a.order.resize(a.shape.size());
    for (std::size_t i = 0; i < a.order.size(); ++i)
        a.order[i] = order == "F" ? a.order.size() - 1 - i : i;
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
    dispatch_voxel_type(a.type, [&](auto t) {
        const auto x = static_cast<decltype(t)>(v);
        std::memcpy(out.data(), &x, sizeof x);
    });
    return out;  // host order
}

namespace {

// One chunk's bytes (an inner chunk's, when sharded) decoded into `out` (exactly the chunk's
// size), or an InputError naming it.
void decode_plain(const ZarrArray& a, std::string_view in, const std::string& file,
                  std::vector<std::byte>& out) {
    const std::size_t want = out.size();
    auto wrong = [&](const std::string& why) { bad(file, "chunk", why); };
    auto size_check = [&](std::size_t got) {
        if (got != want)
            wrong("decodes to " + std::to_string(got) + " bytes, expected " + std::to_string(want));
    };
    if (a.crc32c) {
        if (in.size() < 4) wrong("shorter than its 4-byte CRC-32C");
        std::uint32_t sum;
        std::memcpy(&sum, in.data() + in.size() - 4, 4);
        in.remove_suffix(4);
        if (crc32c(in.data(), in.size()) != sum) wrong("its CRC-32C does not match its bytes");
    }
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

VoxelType v3_type(const std::string& file, const json& j) {
    const std::string t = j.value("data_type", json()).is_string()
                              ? j["data_type"].get<std::string>()
                              : std::string();
    static const std::array<std::pair<const char*, VoxelType>, 8> kTypes = {{
        {"uint8", VoxelType::u8},
        {"int8", VoxelType::i8},
        {"uint16", VoxelType::u16},
        {"int16", VoxelType::i16},
        {"uint32", VoxelType::u32},
        {"int32", VoxelType::i32},
        {"float32", VoxelType::f32},
        {"float64", VoxelType::f64},
    }};
    for (const auto& [name, type] : kTypes)
        if (t == name) return type;
    bad(file, "data_type",
        "expected one of uint8 int8 uint16 int16 uint32 int32 float32 float64, got " +
            quote(j.value("data_type", json()).dump()));
}

// The codec chain `codecs` (v3: array-to-array, then one array-to-bytes, then bytes-to-bytes)
// into `a`'s layout, byte order and compressor; `shard` allows sharding_indexed.
void v3_codecs(const std::string& file, const std::string& field, const json& codecs, ZarrArray& a,
               bool shard) {
    if (!codecs.is_array() || codecs.empty())
        bad(file, field,
            "expected a list of codecs, with one of \"bytes\" or \"sharding_indexed\"");
    const std::size_t k = a.shape.size();
    int stage = 0;  // 0: array to array, 1: bytes to bytes
    for (std::size_t i = 0; i < codecs.size(); ++i) {
        const json& c = codecs[i];
        const std::string name = c.is_object() ? c.value("name", std::string()) : std::string();
        const json cfg = c.is_object() ? c.value("configuration", json::object()) : json::object();
        const std::string at = field + "[" + std::to_string(i) + "]";
        if (name == "transpose" && stage == 0) {
            const json& o = cfg.value("order", json());
            std::vector<std::size_t> order;
            if (o.is_string() && (o == "C" || o == "F")) {
                for (std::size_t n = 0; n < k; ++n) order.push_back(o == "F" ? k - 1 - n : n);
            } else if (o.is_array() && o.size() == k) {
                for (const json& v : o)
                    if (v.is_number_unsigned() && v.get<std::size_t>() < k)
                        order.push_back(v.get<std::size_t>());
            }
            std::vector<std::size_t> sorted = order;
            std::sort(sorted.begin(), sorted.end());
            if (order.size() != k ||
                std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
                bad(file, at + ".order",
                    "expected a permutation of the " + std::to_string(k) + " axes, got " +
                        quote(o.dump()));
            std::vector<std::size_t> composed(k);  // applied after any earlier transpose
            for (std::size_t n = 0; n < k; ++n) composed[n] = a.order[order[n]];
            a.order = composed;
        } else if (name == "bytes" && stage == 0) {
            const std::string endian = cfg.value("endian", std::string("little"));
            if (endian != "little" && endian != "big")
                bad(file, at + ".endian", "expected \"little\" or \"big\", got " + quote(endian));
            a.big_endian = endian == "big";
            stage = 1;
        } else if (name == "sharding_indexed" && stage == 0 && shard) {
            ZarrArray::Shard s;
            s.inner = sizes(file, cfg, "chunk_shape");
            if (s.inner.size() != k) bad(file, at + ".chunk_shape", "expected one size per axis");
            for (std::size_t n = 0; n < k; ++n)
                if (a.chunks[n] % s.inner[n] != 0)
                    bad(file, at + ".chunk_shape",
                        "an inner chunk must divide the shard (" + std::to_string(a.chunks[n]) +
                            " by " + std::to_string(s.inner[n]) + ")");
            const std::string location = cfg.value("index_location", std::string("end"));
            if (location != "end" && location != "start")
                bad(file, at + ".index_location", "expected \"start\" or \"end\"");
            s.index_at_start = location == "start";
            ZarrArray index;  // the index's codecs: bytes, then crc32c or nothing
            index.shape = index.chunks = std::vector<std::int64_t>(k, 1);
            index.order.resize(k);
            std::iota(index.order.begin(), index.order.end(), std::size_t{0});
            v3_codecs(file, at + ".index_codecs", cfg.value("index_codecs", json()), index, false);
            if (!index.compressor.is_null())
                bad(file, at + ".index_codecs", "isowall reads an index of bytes and crc32c only");
            s.index_big_endian = index.big_endian;
            s.index_crc32c = index.crc32c;
            v3_codecs(file, at + ".codecs", cfg.value("codecs", json()), a, false);
            a.shard = s;
            stage = 2;  // nothing may follow a shard's codec here
        } else if ((name == "blosc" || name == "gzip" || name == "zstd") && stage == 1 &&
                   a.compressor.is_null() && !a.crc32c) {
            a.compressor = json{{"id", name}};
        } else if (name == "crc32c" && stage == 1 && !a.crc32c) {
            a.crc32c = true;
        } else {
            bad(file, at,
                "isowall reads transpose, bytes and sharding_indexed, then blosc, gzip or zstd, "
                "then crc32c, in that order; got " +
                    quote(c.dump()));
        }
    }
    if (stage == 0) bad(file, field, "no \"bytes\" or \"sharding_indexed\" codec");
}

// A shard's inner chunks into `out` (the shard, C order), a missing one the fill value.
void decode_shard(const ZarrArray& a, const std::string& in, const std::string& file,
                  std::vector<std::byte>& out) {
    const ZarrArray::Shard& s = *a.shard;
    const std::size_t k = a.shape.size(), e = a.item();
    std::vector<std::size_t> count(k), inner(k);
    std::size_t n = 1, inner_n = 1;
    for (std::size_t i = 0; i < k; ++i) {
        inner[i] = static_cast<std::size_t>(s.inner[i]);
        count[i] = static_cast<std::size_t>(a.chunks[i]) / inner[i];
        n *= count[i];
        inner_n *= inner[i];
    }
    const std::size_t index_bytes = 16 * n + (s.index_crc32c ? 4 : 0);
    if (in.size() < index_bytes)
        bad(file, "chunk",
            "a shard of " + std::to_string(in.size()) + " bytes, shorter than its index of " +
                std::to_string(index_bytes));
    std::string_view index(in.data() + (s.index_at_start ? 0 : in.size() - index_bytes),
                           index_bytes);
    if (s.index_crc32c) {
        std::uint32_t sum;
        std::memcpy(&sum, index.data() + 16 * n, 4);
        if (crc32c(index.data(), 16 * n) != sum)
            bad(file, "chunk", "its shard index's CRC-32C does not match");
    }
    std::vector<std::byte> fill = fill_bytes(a);
    if (a.big_endian) std::reverse(fill.begin(), fill.end());
    for (std::size_t i = 0; i < out.size() / e; ++i)
        std::memcpy(out.data() + i * e, fill.data(), e);
    // Strides: the shard's, C order; an inner chunk's, its codecs' order.
    std::vector<std::size_t> outer(k, 1), within(k, 1);
    for (std::size_t i = k - 1; i-- > 0;)
        outer[i] = outer[i + 1] * static_cast<std::size_t>(a.chunks[i + 1]);
    for (std::size_t i = k - 1; i-- > 0;)
        within[a.order[i]] = within[a.order[i + 1]] * inner[a.order[i + 1]];
    std::vector<std::byte> chunk(inner_n * e);
    for (std::size_t j = 0; j < n; ++j) {
        std::uint64_t entry[2];
        std::memcpy(entry, index.data() + 16 * j, 16);
        if (s.index_big_endian) swap_bytes({reinterpret_cast<std::byte*>(entry), 16}, 8);
        if (entry[0] == ~std::uint64_t{0} && entry[1] == ~std::uint64_t{0}) continue;  // missing
        if (entry[0] > in.size() || entry[1] > in.size() - entry[0])
            bad(file, "chunk", "inner chunk " + std::to_string(j) + " lies past the shard's end");
        decode_plain(a, std::string_view(in.data() + entry[0], entry[1]),
                     file + " (inner chunk " + std::to_string(j) + ")", chunk);
        // Where the inner chunk starts in the shard, then each of its elements, its last axis
        // a run of one memcpy where it is the fastest in both layouts.
        std::size_t base = 0;
        for (std::size_t i = k, rest = j; i-- > 0; rest /= count[i])
            base += (rest % count[i]) * inner[i] * outer[i];
        const bool runs = within[k - 1] == 1;
        const std::size_t run = runs ? inner[k - 1] : 1;
        std::vector<std::size_t> m(k, 0);
        for (std::size_t done = 0; done < inner_n; done += run) {
            std::size_t from = 0, to = base;
            for (std::size_t i = 0; i < k; ++i) from += m[i] * within[i], to += m[i] * outer[i];
            std::memcpy(out.data() + to * e, chunk.data() + from * e, run * e);
            for (std::size_t i = runs ? k - 1 : k; i-- > 0;) {  // the next index, C order
                if (++m[i] < inner[i]) break;
                m[i] = 0;
            }
        }
    }
}

}  // namespace

ZarrArray read_v3_array(const ZarrSource& source, const std::string& prefix) {
    const std::string file = source.where(prefix + "zarr.json");
    const json j = read_json(source, prefix + "zarr.json");
    if (!j.is_object()) bad(file, "metadata", "expected a JSON object");
    if (j.value("zarr_format", 0) != 3)
        bad(file, "zarr_format", "expected 3, got " + quote(j.value("zarr_format", json()).dump()));
    if (j.value("node_type", std::string()) != "array")
        bad(file, "node_type",
            "expected \"array\", got " + quote(j.value("node_type", json()).dump()));
    ZarrArray a;
    a.version = 3;
    a.prefix = prefix;
    a.where = file;
    a.shape = sizes(file, j, "shape");
    if (a.shape.size() < 3)
        bad(file, "shape",
            "a volume has three axes (z, y, x), got " + std::to_string(a.shape.size()));
    a.type = v3_type(file, j);
    const json grid = j.value("chunk_grid", json());
    if (!grid.is_object() || grid.value("name", std::string()) != "regular")
        bad(file, "chunk_grid", "expected a \"regular\" grid, got " + quote(grid.dump()));
    a.chunks = sizes(file, grid.value("configuration", json::object()), "chunk_shape");
    if (a.chunks.size() != a.shape.size())
        bad(file, "chunk_grid.configuration.chunk_shape",
            "expected one size per axis of the shape");
    if (a.chunk_elements() > kMaxChunkBytes / a.item())
        bad(file, "chunk_grid", "a chunk of more than 1 GiB");
    const json keys = j.value("chunk_key_encoding", json{{"name", "default"}});
    const std::string encoding =
        keys.is_object() ? keys.value("name", std::string()) : std::string();
    if (encoding != "default" && encoding != "v2")
        bad(file, "chunk_key_encoding",
            "expected \"default\" or \"v2\", got " + quote(keys.dump()));
    a.separator = keys.value("configuration", json::object())
                      .value("separator", std::string(encoding == "default" ? "/" : "."));
    if (a.separator != "." && a.separator != "/")
        bad(file, "chunk_key_encoding.separator",
            "expected \".\" or \"/\", got " + quote(a.separator));
    if (encoding == "default") a.key_prefix = "c" + a.separator;
    a.order.resize(a.shape.size());
    std::iota(a.order.begin(), a.order.end(), std::size_t{0});
    v3_codecs(file, "codecs", j.value("codecs", json()), a, true);
    a.fill = j.value("fill_value", json());
    for (const json& name : j.value("dimension_names", json::array()))
        a.names.push_back(name.is_string() ? name.get<std::string>() : std::string());
    return a;
}

void decode_chunk(const ZarrArray& a, const std::string& in, const std::string& where,
                  std::vector<std::byte>& out) {
    if (a.shard)
        decode_shard(a, in, where, out);
    else
        decode_plain(a, in, where, out);
}

std::vector<std::size_t> ZarrArray::grid_order() const {
    if (!shard) return order;
    std::vector<std::size_t> c(shape.size());
    std::iota(c.begin(), c.end(), std::size_t{0});
    return c;
}

std::uint32_t crc32c(const void* data, std::size_t size) {
    static const std::array<std::uint32_t, 256> kTable = [] {
        std::array<std::uint32_t, 256> t{};
        for (std::uint32_t i = 0; i < 256; ++i) {
            std::uint32_t c = i;
            for (int b = 0; b < 8; ++b) c = (c >> 1) ^ (c & 1 ? 0x82F63B78u : 0u);
            t[i] = c;
        }
        return t;
    }();
    std::uint32_t c = ~0u;
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) c = kTable[(c ^ p[i]) & 0xFF] ^ (c >> 8);
    return ~c;
}

std::string chunk_key(const ZarrArray& a, std::int64_t z, std::int64_t y, std::int64_t x) {
    std::string key = a.key_prefix;
    for (std::size_t i = 0; i + 3 < a.shape.size(); ++i)
        key += std::to_string(a.pick[i] / a.chunks[i]) + a.separator;
    return key + std::to_string(z) + a.separator + std::to_string(y) + a.separator +
           std::to_string(x);
}

}  // namespace isowall::formats::zarr
