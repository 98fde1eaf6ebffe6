#pragma once
// Another tool's Zarr store (a folder or a URL) paged under --memory-limit. Its chunks seldom suit
// paging (slices of 1x512x512, one chunk of the whole volume, a codec decoded in a child), so it
// is copied once, a slab of planes at a time, into an isowall store under the cache folder
// (stores/KEY), whose bricks then page as an imported store's do. KEY digests the source's name,
// its selection and shape, and for a folder every file's path, size and times: a store that
// changes gets a new copy; an unchanged one reuses the last. Processes opening the same store at
// once (a wall's ranks on one host) take turns on a lock beside it: the first writes the copy,
// the others wait for it and read it.
#include <filesystem>
#include <string>

#include "volume/plane_source.h"

namespace isowall {

struct RechunkedStore {
    std::filesystem::path store;  // the copy, an isowall store
    bool written = false;         // written now (else an earlier run's copy was found)
    double seconds = 0;           // to write it, or to find it
};

// The key (16 hex digits) of the copy of `planes`, read from `source` (a folder or a URL with its
// selection, as given to --volume).
std::string rechunk_key(const std::string& source, const PlaneSource& planes);

// The copy of `planes` under `cache_dir`/stores, written unless it is there; the progress on
// stderr unless `quiet`. Errors (a full disk, the source's) are InputErrors; no partial copy is
// left behind (store/store_writer.h).
RechunkedStore rechunk_into_cache(const std::string& source, PlaneSource& planes,
                                  const std::filesystem::path& cache_dir, bool quiet);

}  // namespace isowall
