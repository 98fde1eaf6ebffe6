#include "readers/zarr_reader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "files/input_file.h"
#include "readers/http_fetch.h"
#include "readers/plane_stack.h"
#include "readers/voxel_ops.h"
#include "readers/zarr_array.h"
#include "volume/load_checks.h"

namespace isowall::formats {

namespace fs = std::filesystem;
using nlohmann::json;
using zarr::ZarrArray;

namespace {

[[noreturn]] void bad(const std::string& where, const std::string& field, const std::string& why) {
    throw InputError(where, field, why);
}

// Chunks a store may have (16 M: 256^3 chunks of 8^3 voxels, a 2048^3 volume).
constexpr std::uint64_t kMaxChunks = std::uint64_t{1} << 24;

bool is_metadata(const std::string& key) {
    return key.ends_with(".zarray") || key.ends_with(".zattrs") || key.ends_with(".zgroup") ||
           key.ends_with("zarr.json");
}

// A store's keys in a folder (the key's path below it).
class FolderSource : public ZarrSource {
  public:
    explicit FolderSource(fs::path dir) : dir_(std::move(dir)) {}
    std::optional<std::string> get(const std::string& key, std::size_t max_bytes) const override {
        const fs::path file = dir_ / key;
        std::error_code ec;
        if (!fs::exists(file, ec)) return std::nullopt;
        const std::string field = is_metadata(key) ? "metadata" : "chunk";
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
        return fetch_.get(where(key), is_metadata(key) ? "metadata" : "chunk", max_bytes);
    }
    std::vector<std::optional<std::string>> get_many(const std::vector<std::string>& keys,
                                                     std::size_t max_bytes) const override {
        std::vector<std::string> urls;
        for (const std::string& key : keys) urls.push_back(where(key));
        return fetch_.get_many(urls, "chunk", max_bytes);
    }
    std::string where(const std::string& key) const override { return base_ + "/" + key; }
    // The object's copy in the HTTP cache, once fetched: the octree cache keys on it as on a
    // folder's file (a store's objects do not change under one URL).
    fs::path file(const std::string& key) const override { return fetch_.cached_file(where(key)); }

  private:
    std::string base_;
    HttpFetcher fetch_;
};

// The array's planes (x fastest, host order) a slab at a time, from the rows of chunks that
// cross them (a row: the chunks of one chunk-index along z). A slab that ends inside a row keeps
// the row decoded for the next slab, so each chunk is decoded once in a stream of slabs; a row
// wholly inside the slab asked for is put straight into it.
class ChunkRows {
  public:
    ChunkRows(std::shared_ptr<const ZarrSource> source, ZarrArray a, glm::ivec3 dims)
        : source_(std::move(source)), a_(std::move(a)), dims_(dims), fill_(zarr::fill_bytes(a_)) {
        const std::size_t k = a_.shape.size();
        // Element strides of each axis within a decoded chunk, the slowest axis first in order.
        const std::vector<std::size_t> order = a_.grid_order();
        std::vector<std::size_t> stride(k, 1);
        for (std::size_t i = k - 1; i-- > 0;)
            stride[order[i]] =
                stride[order[i + 1]] * static_cast<std::size_t>(a_.chunks[order[i + 1]]);
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
            const std::int64_t lo = std::max<std::int64_t>(z0, r0),
                               hi = std::min<std::int64_t>(z1, r1);
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
        // The row's chunks asked for at once (a URL's fetched several at a time), then decoded.
        std::vector<std::string> keys;
        for (std::int64_t by = 0; by * cy < dims_.y; ++by)
            for (std::int64_t bx = 0; bx * cx < dims_.x; ++bx)
                keys.push_back(a_.prefix + zarr::chunk_key(a_, bz, by, bx));
        std::vector<std::optional<std::string>> chunks =
            source_->get_many(keys, zarr::kMaxChunkBytes + (1 << 20));
        std::size_t next = 0;
        for (std::int64_t by = 0; by * cy < dims_.y; ++by)
            for (std::int64_t bx = 0; bx * cx < dims_.x; ++bx) {
                const std::string& key = keys[next];
                std::optional<std::string> bytes = std::move(chunks[next++]);
                if (!bytes) continue;  // a missing chunk is the fill value
                zarr::decode_chunk(a_, *bytes, source_->where(key), chunk_);
                bytes.reset();
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
        std::byte* row =
            out + ((static_cast<std::size_t>(z) * dims_.y + static_cast<std::size_t>(y)) * dims_.x +
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
glm::vec3 ome_spacing(const std::string& file, const json& multiscale, const json& dataset,
                      const std::string& dataset_field) {
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
          dataset_field + ".coordinateTransformations");
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
    try {
        if (fs::exists(path / "zarr.json", ec)) {  // Zarr v3: an array, or an OME-Zarr 0.5 group
            const json z = zarr::read_json(FolderSource(path), "zarr.json");
            const json at = z.is_object() ? z.value("attributes", json::object()) : json();
            return z.is_object() &&
                   (z.value("node_type", std::string()) == "array" ||
                    (at.is_object() && (at.contains("ome") || at.contains("multiscales"))));
        }
        if (!fs::exists(path / ".zattrs", ec)) return false;
        const json at = zarr::read_json(FolderSource(path), ".zattrs");
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

// Where an OME-Zarr image's chosen level lies, and what it says of it.
struct Located {
    ZarrArray array;
    glm::vec3 spacing{1.0f};
    std::vector<std::string> names;  // the axes', slowest first (OME's, else v3's)
    std::string what;                // "Zarr v2 array", "OME-Zarr 0.4 (dataset "0")"
    std::vector<fs::path> files;     // the metadata files
};

// "level=N" taken out of `selection` (the rest left for pick_axes); -1 where it is not there.
int take_level(std::string& selection, const std::string& where) {
    std::string rest;
    int level = -1;
    std::size_t at = 0;
    while (at < selection.size()) {
        const std::size_t end = std::min(selection.find(',', at), selection.size());
        const std::string item = selection.substr(at, end - at);
        at = end + 1;
        if (!item.starts_with("level=")) {
            rest += (rest.empty() ? "" : ",") + item;
            continue;
        }
        const std::string n = item.substr(6);
        if (n.empty() || n.size() > 3 || !std::all_of(n.begin(), n.end(), ::isdigit))
            throw InputError(where, "level",
                             "expected level=N, a dataset of the multiscale, got " + quote(item));
        level = std::stoi(n);
    }
    selection = rest;
    return level;
}

// The multiscale's dataset `level` (its finest, 0, by default) of the OME-Zarr image whose
// attributes `ome` (0.4's .zattrs, 0.5's zarr.json "ome") are in `file`.
Located locate_ome(const ZarrSource& source, const json& ome, const std::string& file, int level,
                   int version) {
    const json& ms = ome.is_object() ? ome.value("multiscales", json()) : json();
    if (!ms.is_array() || ms.empty() || !ms[0].is_object())
        bad(file, "multiscales", "expected a list of OME-Zarr multiscales (or an array beside it)");
    const json& ds = ms[0].value("datasets", json());
    const std::size_t n = ds.is_array() ? ds.size() : 0;
    const int chosen = std::max(level, 0);
    const std::string field = "multiscales[0].datasets[" + std::to_string(chosen) + "]";
    if (n == 0)
        bad(file, "multiscales[0].datasets", "expected a list of datasets, each with a path");
    if (static_cast<std::size_t>(chosen) >= n)
        throw InputError(file, "level",
                         "level=" + std::to_string(level) + ": the image has " + std::to_string(n) +
                             " level" + (n == 1 ? "" : "s") + ", 0 (the finest) to " +
                             std::to_string(n - 1));
    const json& d = ds[static_cast<std::size_t>(chosen)];
    if (!d.is_object() || !d.value("path", json()).is_string())
        bad(file, field, "expected a dataset with a path");
    const std::string sub = d["path"].get<std::string>();
    if (sub.empty() || sub.find("..") != std::string::npos || sub.front() == '/' ||
        sub.find_first_of("?#") != std::string::npos)
        bad(file, field + ".path", "expected a folder inside the store, got " + quote(sub));
    Located l;
    l.array = version == 3 ? zarr::read_v3_array(source, sub + "/")
                           : zarr::read_v2_array(source, sub + "/");
    l.spacing = ome_spacing(file, ms[0], d, field);
    for (const json& ax : ms[0].value("axes", json::array()))  // 0.4: objects; 0.3: names
        l.names.push_back(ax.is_string() ? ax.get<std::string>() : ax.value("name", std::string()));
    const std::string v =
        ome.value("version", ms[0].value("version", std::string(version == 3 ? "0.5" : "0.4")));
    l.what = "OME-Zarr " + v + " (level " + std::to_string(chosen) + " of " + std::to_string(n) +
             ", dataset " + quote(sub) + ")";
    return l;
}

// The array a store holds: a Zarr v2 or v3 array at its root, or an OME-Zarr 0.4 (v2) or 0.5
// (v3) image's dataset `level`.
Located locate(const ZarrSource& source, int level, const std::string& name) {
    Located l;
    const auto add_file = [&](const std::string& key) {
        if (!source.file(key).empty()) l.files.push_back(source.file(key));
    };
    // .zarray first: a v2 array (the most common) costs one request.
    if (source.get(".zarray", zarr::kMaxMetadataBytes)) {
        l.array = zarr::read_v2_array(source, "");
        l.what = "Zarr v2 array";
        add_file(".zarray");
    } else if (const auto v3 = source.get("zarr.json", zarr::kMaxMetadataBytes)) {
        const json z = zarr::parse_json(*v3, source.where("zarr.json"));
        if (z.is_object() && z.value("node_type", std::string()) == "group") {
            const json at = z.value("attributes", json::object());
            l = locate_ome(source, at.is_object() && at.contains("ome") ? at["ome"] : at,
                           source.where("zarr.json"), level, 3);
        } else {
            l.array = zarr::read_v3_array(source, "");
            l.what = "Zarr v3 array";
        }
        add_file("zarr.json");
        if (!l.array.prefix.empty()) add_file(l.array.prefix + "zarr.json");
    } else {
        l = locate_ome(source, zarr::read_json(source, ".zattrs"), source.where(".zattrs"), level,
                       2);
        add_file(".zattrs");
        add_file(l.array.prefix + ".zarray");
    }
    if (level >= 0 && l.what.find("level") == std::string::npos)
        throw InputError(name, "level",
                         "level=" + std::to_string(level) +
                             ": a plain array has one level; levels are an OME-Zarr image's");
    if (l.names.size() != l.array.shape.size()) l.names = l.array.names;
    if (l.names.size() != l.array.shape.size() ||
        std::any_of(l.names.begin(), l.names.end(),
                    [](const std::string& s) { return s.empty(); })) {
        l.names.clear();  // no names, or not one per axis: their indices
        for (std::size_t i = 0; i < l.array.shape.size(); ++i) l.names.push_back(std::to_string(i));
    }
    return l;
}

OpenedArray open_array(std::shared_ptr<const ZarrSource> source, const std::string& name,
                       std::string selection) {
    const int level = take_level(selection, name);
    Located l = locate(*source, level, name);
    ZarrArray& a = l.array;
    a.pick = pick_axes(a, l.names, selection, name);
    const glm::vec3 spacing = l.spacing;
    std::vector<fs::path>& files = l.files;
    const std::string& what = l.what;
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
    const auto shape_of = [](const std::vector<std::int64_t>& v) {
        std::string t;
        for (std::size_t i = 0; i < v.size(); ++i) {
            if (i) t += 'x';
            t += std::to_string(v[i]);
        }
        return t;
    };
    std::vector<std::size_t> c_order(k);
    std::iota(c_order.begin(), c_order.end(), std::size_t{0});
    const std::vector<std::size_t> f_order(c_order.rbegin(), c_order.rend());
    const std::string order = a.order == c_order ? "C" : a.order == f_order ? "F" : "transposed";
    d.facts.push_back(
        {"chunks", a.shard ? shape_of(a.chunks) + " shards of " + shape_of(a.shard->inner) + " (" +
                                 order + " order, " + codec + ")"
                           : shape_of(a.chunks) + " (" + order + " order, " + codec + ")"});
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
