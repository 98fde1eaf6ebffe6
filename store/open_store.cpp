#include "store/open_store.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "core/error.h"
#include "volume/huge_pages.h"

namespace isowall::store {
namespace fs = std::filesystem;

namespace {

std::string mib(std::uint64_t bytes) {
    char s[32];
    std::snprintf(s, sizeof s, "%.0f MiB", double(bytes) / (1024.0 * 1024.0));
    return s;
}

void add_facts(Volume& v, const StoreReader& r) {
    const StoreLayout& l = r.layout();
    const double raw = double(l.chunk_count()) * double(l.brick_bytes());
    char text[160];
    std::snprintf(text, sizeof text,
                  "Zarr v2 (OME-Zarr 0.4), %zu bricks of %d^3 voxels, %d level%s, zstd %.2f:1",
                  l.chunk_count(), l.brick(), l.levels, l.levels == 1 ? "" : "s",
                  r.bytes_on_disk() ? raw / double(r.bytes_on_disk()) : 0.0);
    v.add_fact("store", text);
    std::snprintf(text, sizeof text, "%.1f MiB of level 0's chunks (%.1f MiB of bricks)",
                  double(r.bytes_on_disk()) / (1024.0 * 1024.0), raw / (1024.0 * 1024.0));
    v.add_fact("on disk", text);
    if (!l.source.empty()) v.add_fact("imported from", l.source);
}

// Read-ahead is on unless ISOWALL_READ_AHEAD=off (a study's switch: scripts/bench_store.py
// measures a cold frame with and without it).
bool read_ahead_wanted() {
    const char* v = std::getenv("ISOWALL_READ_AHEAD");
    return !(v && std::string_view(v) == "off");
}

}  // namespace

OpenedStore open_store(const fs::path& path, std::uint64_t cap_bytes) {
    OpenedStore out =
        open_store(std::make_shared<const StoreReader>(path), octree_file(path), cap_bytes);
    out.volume.set_files({path / ".zattrs", path / "0" / ".zarray"});
    return out;
}

OpenedStore open_store(std::shared_ptr<const StoreReader> reader, const fs::path& octree,
                       std::uint64_t cap_bytes) {
    const StoreLayout& l = reader->layout();
    OpenedStore out;
    out.bytes_on_disk = reader->bytes_on_disk();
    const std::string source = reader->path().string();
    try {
        auto pager = std::make_shared<const PagedVoxels>(reader, cap_bytes, read_ahead_wanted());
        out.volume = Volume(l.dims, l.type, l.spacing, pager, pager->bytes(), source);
        out.volume.set_brick_hint(
            [p = pager.get()](std::vector<std::uint8_t> wanted) { p->want(std::move(wanted)); });
        out.pager = std::move(pager);
        out.how = "paged, limit " + mib(cap_bytes);
    } catch (const InputError&) {
        throw;
    } catch (const std::runtime_error& e) {
        // No userfaultfd here: every brick at once, when they fit.
        const std::uint64_t bytes = std::uint64_t(l.chunk_count()) * l.brick_bytes();
        if (bytes > cap_bytes)
            throw InputError(source, "--memory-limit",
                             std::string("paging needs userfaultfd (") + e.what() +
                                 "), and the voxels (" + mib(bytes) + ") pass the limit (" +
                                 mib(cap_bytes) + ")");
        std::vector<std::byte> all(bytes);
        for (std::size_t i = 0; i < l.chunk_count(); ++i)
            reader->read_chunk(l.brick_at(i),
                               std::span(all).subspan(i * l.brick_bytes(), l.brick_bytes()));
        out.volume = Volume(l.dims, l.type, l.spacing, std::move(all), source);
        out.how = std::string("read whole: no paging here (") + e.what() + ")";
    }
    out.volume.set_bricks(l.brick_log2);
    out.volume.set_own_octree(octree, content_key(l));
    add_facts(out.volume, *reader);
    out.reader = std::move(reader);
    return out;
}

std::uint64_t default_memory_limit(int processes) {
    const std::uint64_t avail = mem_available().value_or(std::uint64_t(4) << 30);
    return std::max<std::uint64_t>(avail / 2 / std::uint64_t(std::max(processes, 1)), 64 << 20);
}

}  // namespace isowall::store
