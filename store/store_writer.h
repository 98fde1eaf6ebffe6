#pragma once
// Writing a store (store_format.h) from a volume, one slab of chunks at a time.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>

#include "store/store_format.h"
#include "volume/plane_source.h"
#include "volume/volume.h"

namespace isowall::store {

struct ImportProgress {
    std::size_t chunks_done = 0, chunks_total = 0;
    std::uint64_t bytes_in = 0;   // level 0's voxel bytes compressed so far (the source's pace)
    std::uint64_t bytes_out = 0;  // chunk bytes written so far, every level
};

struct ImportResult {
    StoreLayout layout;
    std::uint64_t bytes_in = 0, bytes_out = 0;
    // Empty when the store's octree was written (octree_file(out)); else why it was not.
    std::string octree_note;
};

struct ImportOptions {
    bool replace = false;  // an existing store at `out` is replaced (else it is an error)
    int threads = 1;       // chunks compressed at once
    int zstd_level = 1;
    int levels = 0;  // of the multiscale pyramid (store_format.h); 0: levels_for(), 1: none
    std::function<void(const ImportProgress&)> progress;  // after each slab of chunks
    // The store's octree, built from the slabs as they are read (store/slab_octree.h)
    // and written into the store before it moves into place: `--volume STORE` maps it wherever
    // the store lies instead of reading every brick to build it.
    bool octree = true;
    // Called with the layout and the temporary folder once every chunk is written, before the
    // store moves into place (tests: a stop at that moment).
    std::function<void(const StoreLayout&, const std::filesystem::path&)> before_commit;
    // Read before each slab and before the store moves into place: true ends the import with
    // ImportStopped, the temporary removed (a stop signal: app/stop_signals.h).
    const std::atomic<bool>* stop = nullptr;
};

// An import ended by ImportOptions::stop; its temporary folder is gone when this is caught.
struct ImportStopped : std::runtime_error {
    explicit ImportStopped(const std::filesystem::path& temporary)
        : std::runtime_error("stopped; " + temporary.string() + " removed, no store written") {}
};

// Writes `volume` as a store at `out`. The store is built under a temporary name beside `out`
// and renamed into place only when whole, so a run that is stopped leaves no store (and the next
// run starts over); a store is never half old, half new. The temporary is locked while it is
// written: a second import into the same `out` at once is refused. `replace` replaces only a
// store isowall wrote that holds nothing else (a folder with other files in it is left alone).
// Memory stays bounded by a slab of chunks per thread: a memory-mapped source lets go of each
// slab's pages once it is written. Errors (a full or read-only disk, an existing `out`) are
// InputErrors naming `out`; the temporary is removed.
ImportResult write_store(const Volume& volume, const std::filesystem::path& out,
                         const ImportOptions& options);
// The same from planes read in z order (volume/plane_source.h): a slab of them, and one
// plane more, at a time. A source's InputError ends the import as any other failure does.
ImportResult write_store(PlaneSource& source, const std::filesystem::path& out,
                         const ImportOptions& options);

// Where write_store builds the store before renaming it (".NAME.importing" beside it).
std::filesystem::path temporary_for(const std::filesystem::path& out);

}  // namespace isowall::store
