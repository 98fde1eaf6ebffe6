#pragma once
// The volume options every subcommand shares, and opening the volume they describe.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "store/paged_voxels.h"
#include "volume/plane_source.h"
#include "volume/volume.h"

namespace isowall {

struct VolumeOptions {
    std::string path;  // empty: the built-in phantom
    std::vector<int> dims;
    std::string type;
    std::vector<float> spacing;
    std::string endian = "little";
    std::size_t header_bytes = 0;
    std::string cache_dir;
    bool no_cache = false;
    std::string huge_pages = "auto";  // auto, on, off (volume/huge_pages.h)
    std::string memory_limit;         // a store's cap ("512M", "8G"); empty: the default share
    double http_timeout = 30;         // a volume over HTTP: seconds without a byte before a retry
    int http_connections = 8;         // a volume over HTTP: objects fetched at once
    // A time series (a numbered pattern, volume/time_steps.h): the step opened (the wall's first).
    std::uint32_t time = 0;
};

void add_volume_options(CLI::App& app, VolumeOptions& opts);

struct OpenedVolume {
    Volume volume;
    std::optional<std::filesystem::path> file;  // nullopt for the phantom
    std::filesystem::path cache_dir;            // empty: no octree cache
    double load_s = 0;
    // A store's pager (store/paged_voxels.h), for what it read; null for other volumes.
    std::shared_ptr<const store::PagedVoxels> pager;
    // A store's reader, for a wall master that sends chunks to ranks that cannot see the store.
    std::shared_ptr<const store::StoreReader> store;
};

// Who holds the volume: `casts` when this process runs the engine over it (the master of a wall
// and `info` only read its size and octree, so it stays mapped); `copies_on_host` is how many
// processes on this machine would each copy it into huge pages (a wall's tile ranks).
struct VolumeUse {
    bool casts = true;
    int copies_on_host = 1;
    bool one_frame = false;  // the process draws one frame (choose_huge_pages)
};

// A store's --memory-limit for this process: the option, or its share of the host's memory.
// InputError naming --memory-limit when the value is not a size.
std::uint64_t memory_limit(const VolumeOptions& opts, VolumeUse use);

// The octree cache folder of `opts` (--cache-dir, $ISOWALL_CACHE_DIR, ~/.cache/isowall), or
// empty with --no-cache.
std::filesystem::path cache_dir(const VolumeOptions& opts);

// Loads the file (or generates the phantom), moves it into huge pages when --huge-pages says so,
// and prints one line about it. A numbered pattern (a time series) opens its step --time.
OpenedVolume open_volume(const VolumeOptions& opts, bool quiet = false, VolumeUse use = {});
// The store named by `opts` read through `reader` where this host cannot see it (a wall rank's
// bricks from the master, tile/store_client.h), its octree copied to the file `octree`: the
// memory limit and cache folder are `opts`'s, as for a store open_volume reads itself.
OpenedVolume open_volume(const VolumeOptions& opts,
                         std::shared_ptr<const store::StoreReader> reader,
                         const std::filesystem::path& octree, VolumeUse use);

// Whether this host reads `path` itself: a file or folder that is here, one with a part after it
// (an HDF5 file's FILE.h5:/dataset, a Zarr store's pick STORE:t=3) whose file or folder is here,
// or a URL (fetched by each process that opens it). A wall's rank that cannot asks the master for a
// store's bricks instead.
bool readable_here(const std::string& path);

// The volume's planes for `isowall import` to stream (readers/read_volume.h: open_planes),
// or null where open_volume serves (the phantom, a store, raw data and raw NRRD it maps).
std::unique_ptr<PlaneSource> open_planes(const VolumeOptions& opts);

}  // namespace isowall
