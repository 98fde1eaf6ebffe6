#include "store/store_format.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "volume/load_checks.h"

namespace isowall::store {
namespace fs = std::filesystem;
using nlohmann::json;

StoreLayout layout_for(glm::ivec3 dims, VoxelType type, glm::vec3 spacing) {
    StoreLayout l;
    l.dims = dims;
    l.type = type;
    l.spacing = spacing;
    l.brick_log2 = 5;
    if (l.chunk_count() > 65536) l.brick_log2 = 6;
    return l;
}

namespace {

struct DtypeName {
    VoxelType type;
    std::string_view name;
};
constexpr DtypeName kDtypes[] = {
    {VoxelType::u8, "|u1"},  {VoxelType::i8, "|i1"},  {VoxelType::u16, "<u2"},
    {VoxelType::i16, "<i2"}, {VoxelType::u32, "<u4"}, {VoxelType::i32, "<i4"},
    {VoxelType::f32, "<f4"}, {VoxelType::f64, "<f8"},
};

[[noreturn]] void bad(const std::string& store, const std::string& field, const std::string& why) {
    throw InputError(store, field, why);
}

// A positive int within `limit` from json, or the line naming store/file: field.
int positive_int(const json& j, const std::string& store, const std::string& field, long limit) {
    if (!j.is_number_integer() || j.get<long long>() < 1 || j.get<long long>() > limit)
        bad(store, field,
            "expected an integer from 1 to " + std::to_string(limit) + ", got " + quote(j.dump()));
    return static_cast<int>(j.get<long long>());
}

json parse_json(std::string_view text, const std::string& store, const std::string& file) {
    json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded() || !j.is_object()) bad(store, file, "not a JSON object");
    return j;
}

const json& member(const json& j, const char* name, const std::string& store,
                   const std::string& file) {
    const auto it = j.find(name);
    if (it == j.end()) bad(store, file + ": " + name, "missing");
    return *it;
}

// The member `name` of object `j` as text: `absent` when it is missing, and its JSON (never equal
// to a string a caller asks for, which would be quoted) when it is not a string. nlohmann's
// value(name, fallback) throws type_error for a member of another type; a store's metadata is
// input, so no check may throw anything but the line naming the field.
std::string text_member(const json& j, const char* name, const std::string& absent) {
    const auto it = j.find(name);
    if (it == j.end()) return absent;
    return it->is_string() ? it->get<std::string>() : it->dump();
}

}  // namespace

std::string zarr_dtype(VoxelType t) {
    for (const auto& d : kDtypes)
        if (d.type == t) return std::string(d.name);
    return "|u1";
}

std::optional<VoxelType> parse_zarr_dtype(std::string_view s) {
    for (const auto& d : kDtypes)
        if (d.name == s) return d.type;
    return std::nullopt;
}

std::string zgroup_json() {
    return json{{"zarr_format", 2}}.dump(4) + "\n";
}

std::string zarray_json(const StoreLayout& l) {
    const json j = {
        {"zarr_format", 2},
        {"shape", {l.dims.z, l.dims.y, l.dims.x}},
        {"chunks", {l.brick(), l.brick(), l.brick()}},
        {"dtype", zarr_dtype(l.type)},
        // No "checksum" key: numcodecs before 0.12 (Debian 12's 0.11) refuses the codec with it.
        // The frames carry their checksums anyway, and every zstd decoder checks them.
        {"compressor", {{"id", "zstd"}, {"level", l.zstd_level}}},
        {"fill_value", 0},
        {"order", "C"},
        {"filters", nullptr},
        {"dimension_separator", "/"},
    };
    return j.dump(4) + "\n";
}

std::string zattrs_json(const StoreLayout& l) {
    const json axes = json::array({{{"name", "z"}, {"type", "space"}},
                                   {{"name", "y"}, {"type", "space"}},
                                   {{"name", "x"}, {"type", "space"}}});
    json datasets = json::array();
    for (int k = 0; k < l.levels; ++k) {
        const glm::vec3 s = l.level(k).spacing;
        const json scale = {{"type", "scale"}, {"scale", {s.z, s.y, s.x}}};
        datasets.push_back(
            {{"path", std::to_string(k)}, {"coordinateTransformations", json::array({scale})}});
    }
    const json j = {
        {"multiscales", json::array({{{"version", "0.4"},
                                      {"name", fs::path(l.source).filename().string()},
                                      {"axes", axes},
                                      {"datasets", datasets}}})},
        {"isowall",
         {{"format", kFormatVersion},
          {"id", l.id},
          {"source", l.source},
          {"value_min", l.value_min},
          {"value_max", l.value_max},
          {"chunks", l.chunk_count()},
          {"bytes", l.bytes},
          {"levels", l.levels}}},
    };
    return j.dump(4) + "\n";
}

namespace {

// An array's metadata (K/.zarray, `za`) into `l`: shape, cubic chunks, dtype, zstd, C order.
void parse_zarray(std::string_view zarray, const std::string& store, StoreLayout& l,
                  const std::string& za = "0/.zarray") {
    constexpr long kMaxSide = 2147483647;
    const json a = parse_json(zarray, store, za);
    if (member(a, "zarr_format", store, za) != 2)
        bad(store, za + ": zarr_format", "expected 2 (isowall reads Zarr v2 stores)");
    const json& shape = member(a, "shape", store, za);
    const json& chunks = member(a, "chunks", store, za);
    if (!shape.is_array() || shape.size() != 3)
        bad(store, za + ": shape", "expected 3 sizes (z, y, x), got " + quote(shape.dump()));
    if (!chunks.is_array() || chunks.size() != 3)
        bad(store, za + ": chunks", "expected 3 sizes (z, y, x), got " + quote(chunks.dump()));
    l.dims = {positive_int(shape[2], store, za + ": shape", kMaxSide),
              positive_int(shape[1], store, za + ": shape", kMaxSide),
              positive_int(shape[0], store, za + ": shape", kMaxSide)};
    if (glm::any(glm::lessThan(l.dims, glm::ivec3(2))))
        bad(store, za + ": shape",
            "every side needs at least 2 voxels, got " + quote(shape.dump()));
    const int side = positive_int(chunks[0], store, za + ": chunks", kMaxSide);
    l.brick_log2 = 0;
    while ((1 << l.brick_log2) < side && l.brick_log2 < 8) ++l.brick_log2;
    if ((1 << l.brick_log2) != side || side < 8 || side > 128 ||
        positive_int(chunks[1], store, za + ": chunks", kMaxSide) != side ||
        positive_int(chunks[2], store, za + ": chunks", kMaxSide) != side)
        bad(store, za + ": chunks",
            "isowall reads cubic chunks of 8 to 128 voxels a side, a power of two, got " +
                quote(chunks.dump()));
    // The bricks' address space (paged_voxels.h reserves it whole) must fit this machine's
    // 47-bit user space with room to spare: 64 TiB.
    {
        auto n = [&](int d) { return (std::uint64_t(d) + std::uint64_t(side) - 1) / side; };
        const auto bytes = checked_product(
            {n(l.dims.x), n(l.dims.y), n(l.dims.z), std::uint64_t(side) * side * side, 8});
        if (!bytes || *bytes > (std::uint64_t(1) << 46))
            bad(store, za + ": shape", "larger than 64 TiB of voxels, got " + quote(shape.dump()));
    }
    const json& dtype = member(a, "dtype", store, za);
    const auto type = dtype.is_string() ? parse_zarr_dtype(dtype.get<std::string>()) : std::nullopt;
    if (!type)
        bad(store, za + ": dtype",
            "expected a little-endian |u1 |i1 <u2 <i2 <u4 <i4 <f4 <f8, got " + quote(dtype.dump()));
    l.type = *type;
    const json& comp = member(a, "compressor", store, za);
    if (!comp.is_object() || text_member(comp, "id", "") != "zstd")
        bad(store, za + ": compressor", "expected zstd, got " + quote(comp.dump()));
    // The level the chunks were written with (any reads them): kept, so that the layout read back
    // is the layout written, and its content key the same.
    if (comp.contains("level") && comp["level"].is_number_integer())
        l.zstd_level = comp["level"].get<int>();
    if (text_member(a, "order", "C") != "C")
        bad(store, za + ": order", "expected \"C\", got " + quote(a["order"].dump()));
    if (a.contains("filters") && !a["filters"].is_null())
        bad(store, za + ": filters", "expected null, got " + quote(a["filters"].dump()));
    if (text_member(a, "dimension_separator", ".") != "/")
        bad(store, za + ": dimension_separator", "expected \"/\"");
}

// The group's attributes (.zattrs) into `l`: isowall's block, checked against the array, and
// the spacing from the OME-Zarr scale.
void parse_zattrs(std::string_view zattrs, const std::string& store, StoreLayout& l) {
    const std::string at = ".zattrs";
    const json t = parse_json(zattrs, store, at);
    const json& iso = member(t, "isowall", store, at);
    const auto format = iso.is_object() ? iso.find("format") : iso.end();
    if (format == iso.end() || !format->is_number_integer() ||
        format->get<long long>() != kFormatVersion)
        bad(store, at + ": isowall.format",
            "expected " + std::to_string(kFormatVersion) + " (a store isowall wrote)");
    l.source = text_member(iso, "source", "");
    l.id = iso.contains("id") && iso["id"].is_string() ? iso["id"].get<std::string>() : "";
    if (l.id.size() != 16 || l.id.find_first_not_of("0123456789abcdef") != std::string::npos)
        bad(store, at + ": isowall.id", "expected 16 hex digits, got " + quote(l.id));
    if (!iso.contains("value_min") || !iso["value_min"].is_number() || !iso.contains("value_max") ||
        !iso["value_max"].is_number())
        bad(store, at + ": isowall.value_min", "expected two numbers, value_min and value_max");
    l.value_min = iso["value_min"].get<double>();
    l.value_max = iso["value_max"].get<double>();
    if (!iso.contains("chunks") || !iso["chunks"].is_number_unsigned() ||
        iso["chunks"].get<std::uint64_t>() != l.chunk_count())
        bad(store, at + ": isowall.chunks",
            "disagrees with 0/.zarray (which makes " + std::to_string(l.chunk_count()) +
                " chunks of its shape), got " + quote(iso.value("chunks", json()).dump()));
    // Stores of the first imports did not record their bytes: then the reader counts them.
    if (iso.contains("bytes")) {
        if (!iso["bytes"].is_number_unsigned())
            bad(store, at + ": isowall.bytes",
                "expected a byte count, got " + quote(iso["bytes"].dump()));
        l.bytes = iso["bytes"].get<std::uint64_t>();
    }
    // Levels past 0 (stores without the field have level 0 only); their arrays are checked by
    // the reader (store_reader.cpp), each against l.level(k).
    if (iso.contains("levels")) {
        const json& n = iso["levels"];
        if (!n.is_number_unsigned() || n.get<std::uint64_t>() < 1 || n.get<std::uint64_t>() > 12 ||
            n.get<int>() > levels_for(l.dims, l.brick_log2))
            bad(store, at + ": isowall.levels",
                "expected 1 to " + std::to_string(levels_for(l.dims, l.brick_log2)) +
                    " for this shape, got " + quote(n.dump()));
        l.levels = n.get<int>();
    }
    // The spacing: the first dataset's scale transform, z y x.
    try {
        const json& s = t.at("multiscales")
                            .at(0)
                            .at("datasets")
                            .at(0)
                            .at("coordinateTransformations")
                            .at(0)
                            .at("scale");
        const double sx = s.at(2).get<double>(), sy = s.at(1).get<double>(),
                     sz = s.at(0).get<double>();
        for (double v : {sx, sy, sz})
            if (!(v > 0) || !std::isfinite(v) || v > 1e6) throw std::runtime_error("range");
        l.spacing = {float(sx), float(sy), float(sz)};
    } catch (const std::exception&) {
        bad(store, at + ": multiscales", "expected a scale of three positive numbers for path 0");
    }
}

}  // namespace

StoreLayout parse_layout(std::string_view zarray, std::string_view zattrs,
                         const std::string& store) {
    StoreLayout l;
    parse_zarray(zarray, store, l);
    parse_zattrs(zattrs, store, l);
    return l;
}

void check_level(std::string_view zarray, const StoreLayout& l, int k, const std::string& store) {
    const std::string za = std::to_string(k) + "/.zarray";
    StoreLayout got;
    parse_zarray(zarray, store, got, za);
    const StoreLayout want = l.level(k);
    if (got.dims != want.dims)
        bad(store, za + ": shape",
            "expected [" + std::to_string(want.dims.z) + ", " + std::to_string(want.dims.y) + ", " +
                std::to_string(want.dims.x) + "] (level 0's shape halved " + std::to_string(k) +
                " times, rounded up)");
    if (got.brick_log2 != l.brick_log2 || got.type != l.type)
        bad(store, za + ": chunks", "expected the chunks and dtype of 0/.zarray");
}

fs::path octree_file(const fs::path& store) {
    return store / "octree.isowall";
}

std::uint64_t content_key(const StoreLayout& l) {
    std::uint64_t h = 14695981039346656037ull;  // FNV-1a
    for (unsigned char c : l.id + "/" + zarray_json(l)) h = (h ^ c) * 1099511628211ull;
    return h;
}

std::string new_store_id() {
    std::random_device rd;
    const std::uint64_t v =
        (std::uint64_t(rd()) << 32) ^ rd() ^
        std::uint64_t(std::chrono::steady_clock::now().time_since_epoch().count());
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
    return text;
}

std::string chunk_key(glm::ivec3 b, int level) {
    return std::to_string(level) + "/" + std::to_string(b.z) + "/" + std::to_string(b.y) + "/" +
           std::to_string(b.x);
}

int levels_for(glm::ivec3 dims, int brick_log2) {
    int levels = 1;
    while (levels < 12 &&
           (std::max({dims.x, dims.y, dims.z}) - 1) >> (levels - 1) >= (1 << brick_log2))
        ++levels;
    return levels;
}

fs::path store_path(const std::string& text) {
    fs::path p = fs::path(text).lexically_normal();
    if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
    return p;
}

bool is_store(const fs::path& path) {
    std::error_code ec;
    return fs::is_directory(path, ec) && fs::exists(path / ".zattrs", ec) &&
           fs::exists(path / "0" / ".zarray", ec);
}

}  // namespace isowall::store
