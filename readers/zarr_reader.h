#pragma once
// Zarr v2 arrays and OME-Zarr 0.4 images written by other tools (zarr-python, napari's writers,
// ome-zarr-py), read whole into memory as --volume or as an `import` source:
//   - STORE holding .zarray: that array;
//   - STORE holding .zattrs with OME "multiscales": the first multiscale's first dataset (the
//     finest level), its spacing from that dataset's "scale" transform (times the multiscale's
//     own scale, when it has one), the last three axes as z, y, x;
//   - compressors: none, Blosc (every inner codec c-blosc has: lz4, lz4hc, zstd, zlib, blosclz;
//     shuffle and bit-shuffle), zstd, gzip, zlib and lz4 (numcodecs' framing: the decoded size,
//     then one LZ4 block), each through its library;
//   - any chunk shape, C or F order, "." or "/" separators, any byte order; a missing chunk
//     reads as the fill value (0 where it is null);
//   - three axes (z, y, x), or more, the axes before them each given one element by `selection`
//     ("t=3,c=0": OME's axis names, else each axis's index, "0=3"), or of one element.
// Served over HTTP(S) (`--volume https://host/path.zarr`), the same objects are fetched through
// libcurl (http_fetch.h). isowall's own stores (an "isowall" block in .zattrs) are not this
// reader's on disk: they page
// (store/open_store.h). Bad metadata or a damaged chunk is an InputError naming the store and
// the field or the chunk's key.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "readers/http_fetch.h"
#include "readers/plane_stack.h"
#include "volume/volume.h"

namespace isowall::formats {

// Whether `path` is a folder holding a Zarr array or an OME-Zarr group that is not an isowall
// store (isowall's own go through store/open_store.h).
bool is_foreign_zarr(const std::filesystem::path& path);

Volume read_zarr(const std::filesystem::path& path, const std::string& selection = "");

// The same array's planes a slab at a time (plane_stack.h), for `isowall import` and for paging
// a store through a re-chunked copy: a row of chunks along z is decoded once and held while the
// slabs asked for cross it.
PlaneStack zarr_planes(const std::filesystem::path& path, const std::string& selection = "");
PlaneStack zarr_url_planes(const std::string& url, const std::string& selection,
                           const HttpOptions& options);

// The same from a store served over HTTP(S) at `url` (http_fetch.h: one GET per object, 404 a
// chunk left out, retries, an optional disk cache).
Volume read_zarr_url(const std::string& url, const std::string& selection,
                     const HttpOptions& options);

// Where a store's objects come from: a folder, or a URL.
class ZarrSource {
  public:
    virtual ~ZarrSource() = default;
    // The bytes of `key` (".zattrs", "0/.zarray", "0/1.2.3"), nullopt where the store has none;
    // an InputError past `max_bytes` or when it cannot be read.
    virtual std::optional<std::string> get(const std::string& key, std::size_t max_bytes) const = 0;
    // The bytes of each of `keys`, as get() gives them; a URL's are fetched several at once.
    virtual std::vector<std::optional<std::string>> get_many(const std::vector<std::string>& keys,
                                                             std::size_t max_bytes) const {
        std::vector<std::optional<std::string>> out;
        for (const std::string& key : keys) out.push_back(get(key, max_bytes));
        return out;
    }
    // `key` named for messages: its file or its URL.
    virtual std::string where(const std::string& key) const = 0;
    // The file that holds `key` (the octree cache's key covers it); empty for a URL.
    virtual std::filesystem::path file(const std::string&) const { return {}; }
};
Volume read_zarr(std::shared_ptr<const ZarrSource> source, const std::string& name,
                 const std::string& selection);
PlaneStack zarr_planes(std::shared_ptr<const ZarrSource> source, const std::string& name,
                       const std::string& selection);

}  // namespace isowall::formats
