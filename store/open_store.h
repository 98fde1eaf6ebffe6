#pragma once
// `--volume STORE`: a store's voxels as a Volume, paged under a memory cap (paged_voxels.h).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "store/paged_voxels.h"
#include "volume/volume.h"

namespace isowall::store {

struct OpenedStore {
    Volume volume;
    std::shared_ptr<const PagedVoxels> pager;  // null when the store was read whole
    std::shared_ptr<const StoreReader> reader;
    std::uint64_t bytes_on_disk = 0;
    std::string how;  // "paged, limit 512 MiB" or why it was read whole
};

// Opens the store at `path` with the voxels paged in on first touch under `cap_bytes`. Where
// userfaultfd is not available, a store that fits under the cap is read whole instead (and `how`
// says why); one that does not is an InputError naming the store and --memory-limit.
OpenedStore open_store(const std::filesystem::path& path, std::uint64_t cap_bytes);
// The same for a store read elsewhere (StoreReader's fetching constructor), with its octree file
// copied to `octree`.
OpenedStore open_store(std::shared_ptr<const StoreReader> reader,
                       const std::filesystem::path& octree, std::uint64_t cap_bytes);

// The default --memory-limit for a process: half the memory available now, shared by the
// `processes` on this host that each open the store (a wall's tile ranks).
std::uint64_t default_memory_limit(int processes);

}  // namespace isowall::store
