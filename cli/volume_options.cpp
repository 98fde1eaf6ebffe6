#include "cli/volume_options.h"

#include "volume/time_steps.h"

#include <cstdio>

#include "cli/cli_checks.h"
#include "cli/rechunked_store.h"
#include "core/error.h"
#include "core/number.h"
#include "core/util.h"
#include "readers/http_fetch.h"
#include "readers/read_volume.h"
#include "readers/zarr_reader.h"
#include "store/open_store.h"
#include "store/store_format.h"
#include "volume/load_checks.h"
#include "volume/octree.h"
#include "volume/phantom.h"

namespace isowall {

void add_volume_options(CLI::App& app, VolumeOptions& o) {
    app.add_option("--volume,-v", o.path,
                   "Volume: NRRD (.nrrd/.nhdr), NIfTI (.nii, .nii.gz, .hdr/.img), a DICOM "
                   "series (its folder, or one file of it), MetaImage (.mhd/.mha), HDF5 "
                   "(FILE.h5:/dataset), TIFF (a multi-page .tif or a folder of slices), or "
                   "headerless raw with --dims and --type, a Zarr v2/v3 array or OME-Zarr image "
                   "(its folder; FOLDER:t=N,c=M picks a time point and a channel, "
                   "FOLDER:level=N a multiscale level), the same over "
                   "http:// or https://, or a store made by `isowall import` (its folder; read on "
                   "first touch under --memory-limit). Default: the built-in phantom");
    app.add_option("--time", o.time,
                   "With a numbered --volume pattern (a time series, e.g. 'run/t_%03d.nrrd': "
                   "the folder's files with a number there, without a gap), the step to open, "
                   "from 0; the wall starts there")
        ->transform(number_in({0, 99999, false, true}));
    app.add_option("--dims", o.dims, "Raw volume size in voxels: X Y Z (x varies fastest)")
        ->expected(3)
        ->transform(number_in({1, 2147483647.0, false, true}));
    app.add_option("--type", o.type,
                   "Raw voxel type: uint8 int8 uint16 int16 uint32 int32 float32 float64");
    app.add_option("--spacing", o.spacing, "Raw voxel spacing: SX SY SZ (default 1 1 1)")
        ->expected(3)
        ->transform(number_in({1e-6, 1e6}));
    app.add_option("--endian", o.endian, "Raw byte order: little or big")
        ->check(CLI::IsMember({"little", "big"}));
    app.add_option("--header-bytes", o.header_bytes, "Raw: bytes to skip at the start of the file")
        ->transform(number_in({0, 9007199254740992.0, false, true}));
    app.add_option("--cache-dir", o.cache_dir,
                   "Octree cache folder (default $ISOWALL_CACHE_DIR, else ~/.cache/isowall)");
    app.add_flag("--no-cache", o.no_cache,
                 "Always build the octree; never read or write the cache");
    app.add_option("--huge-pages", o.huge_pages,
                   "Copy the volume into transparent huge pages for the engine's random reads: "
                   "auto (from 256 MiB, when every rank's copy fits in half the available "
                   "memory), on, off (keep the shared memory map). Default: auto")
        ->check(CLI::IsMember({"auto", "on", "off"}));
    app.add_option("--http-timeout", o.http_timeout,
                   "A volume over HTTP: seconds without a byte from the server before the request "
                   "is tried again (3 more tries, then an error naming the URL). Fetched objects "
                   "are kept under the cache folder's http/ (not with --no-cache). Default: 30")
        ->transform(number_in({0.1, 3600}));
    app.add_option("--http-connections", o.http_connections,
                   "A volume over HTTP: how many of a row's chunks are fetched at once, each "
                   "connection kept for the next (fewer spare a small server; more hide a far "
                   "server's round trips). Default: 8")
        ->transform(number_in({1, 64, false, true}));
    app.add_option("--memory-limit", o.memory_limit,
                   "A store's voxels in memory at most (e.g. 512M, 8G); the rest stays on disk "
                   "and is read when a ray or the surface first needs it. Another tool's Zarr "
                   "store (a folder or a URL) given a limit, or past it, is first copied into an "
                   "isowall store in the cache folder (stores/), once. Default: half the "
                   "available memory, shared by the processes of this host")
        ->check([](const std::string& text) -> std::string {
            if (parse_byte_size(text)) return "";
            return "expected a size such as 512M or 8G, got " + quote(text);
        });
}

namespace {

// --memory-limit caps a store's bricks; given for a file, it would silently do nothing.
void check_no_memory_limit(const VolumeOptions& o) {
    if (!o.memory_limit.empty())
        throw InputError("--memory-limit", "value",
                         "applies to a store (`isowall import`), not to " + quote(o.path));
}

std::optional<RawSpec> raw_spec(const VolumeOptions& o) {
    const bool raw = !o.dims.empty() || !o.type.empty();
    if (!raw) return std::nullopt;
    if (o.path.empty())
        throw InputError("--dims/--type", "--volume", "a raw volume needs --volume FILE");
    if (o.dims.size() != 3) throw InputError(o.path, "--dims", "a raw volume needs --dims X Y Z");
    if (o.type.empty()) throw InputError(o.path, "--type", "a raw volume needs --type T");
    RawSpec spec;
    spec.dims = {o.dims[0], o.dims[1], o.dims[2]};
    const auto type = parse_voxel_type(o.type);
    if (!type)
        throw InputError(
            o.path, "--type",
            "expected one of uint8 int8 uint16 int16 uint32 int32 float32 float64, got " +
                quote(o.type));
    spec.type = *type;
    if (!o.spacing.empty()) spec.spacing = {o.spacing[0], o.spacing[1], o.spacing[2]};
    spec.endian = o.endian == "big" ? Endian::big : Endian::little;
    spec.header_bytes = o.header_bytes;
    return spec;
}

}  // namespace

std::uint64_t memory_limit(const VolumeOptions& o, VolumeUse use) {
    if (o.memory_limit.empty()) return store::default_memory_limit(use.copies_on_host);
    const auto parsed = parse_byte_size(o.memory_limit);
    if (!parsed)
        throw InputError("--memory-limit", "value",
                         "expected a size such as 512M or 8G, got " + quote(o.memory_limit));
    return *parsed;
}

std::filesystem::path cache_dir(const VolumeOptions& o) {
    if (o.no_cache) return {};
    return o.cache_dir.empty() ? octree_cache::default_dir() : std::filesystem::path(o.cache_dir);
}

formats::HttpOptions http_options(const VolumeOptions& o) {
    formats::HttpOptions h;
    h.stall_s = o.http_timeout;
    h.connections = o.http_connections;
    if (!o.no_cache) h.cache_dir = cache_dir(o) / "http";
    return h;
}

// A store `isowall import` wrote (paged); another tool's Zarr store is read by the readers.
bool own_store(const std::string& path) {
    return store::is_store(path) && !formats::is_foreign_zarr(path);
}

bool readable_here(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec) || formats::is_url(path)) return true;
    // FILE.h5:/dataset, STORE:t=3: what comes before the last ':' is here.
    const std::size_t colon = path.rfind(':');
    return colon != std::string::npos && colon > 0 &&
           std::filesystem::exists(path.substr(0, colon), ec);
}

std::unique_ptr<PlaneSource> open_planes(const VolumeOptions& o) {
    if (o.path.empty() || own_store(o.path)) return nullptr;
    check_no_memory_limit(o);
    return formats::open_planes(o.path, raw_spec(o), http_options(o));
}

namespace {

// Another tool's Zarr store opened paged through its copy in the cache folder
// (rechunked_store.h) when --memory-limit is given or its voxels pass the limit; nullopt when it
// is read whole (and `planes`, opened to learn its size, is dropped).
std::optional<OpenedVolume> open_rechunked(const VolumeOptions& o, bool quiet, VolumeUse use,
                                           std::string& note) {
    std::unique_ptr<PlaneSource> planes =
        formats::open_planes(o.path, std::nullopt, http_options(o));
    const std::uint64_t cap = memory_limit(o, use);
    const bool asked = !o.memory_limit.empty();
    if (!asked && voxel_bytes(planes->dims(), planes->type()) <= cap) return std::nullopt;
    const std::filesystem::path cache = cache_dir(o);
    if (cache.empty()) {
        if (!asked) return std::nullopt;  // read whole, as without a cache it must be
        throw InputError("--memory-limit", "--no-cache",
                         "paging " + quote(o.path) +
                             " copies it into the cache folder first; drop --no-cache, or "
                             "`isowall import` it and give the store");
    }
    const RechunkedStore copy = rechunk_into_cache(o.path, *planes, cache, quiet);
    planes.reset();
    store::OpenedStore opened = store::open_store(copy.store, cap);
    OpenedVolume out;
    out.volume = std::move(opened.volume);
    out.pager = std::move(opened.pager);
    out.store = std::move(opened.reader);
    out.file = copy.store;
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.2f s", copy.seconds);
    note = std::string(" (re-chunked into ") + copy.store.string() +
           (copy.written ? std::string(" in ") + seconds : std::string(", an earlier copy")) +
           "; " + opened.how + ")";
    return out;
}

}  // namespace

OpenedVolume open_volume(const VolumeOptions& o, std::shared_ptr<const store::StoreReader> reader,
                         const std::filesystem::path& octree, VolumeUse use) {
    OpenedVolume out;
    out.cache_dir = cache_dir(o);
    store::OpenedStore s = store::open_store(std::move(reader), octree, memory_limit(o, use));
    out.volume = std::move(s.volume);
    out.pager = std::move(s.pager);
    out.file = std::filesystem::path(o.path);
    return out;
}

// A numbered pattern's step --time, opened as any volume.
static OpenedVolume open_step(const VolumeOptions& o, bool quiet, VolumeUse use) {
    const TimeSeries series = find_series(o.path, "--volume");
    if (o.time >= series.steps.size())
        throw InputError("--time", "value",
                         "step " + std::to_string(o.time) + ": the series has " +
                             std::to_string(series.steps.size()) + " steps (0 to " +
                             std::to_string(series.steps.size() - 1) + ")");
    VolumeOptions step = o;
    step.path = series.steps[o.time].string();
    if (!quiet)
        std::printf("time: step %u of %zu steps, %s\n", o.time, series.steps.size(),
                    step.path.c_str());
    step.time = 0;
    return open_volume(step, quiet, use);
}

OpenedVolume open_volume(const VolumeOptions& o, bool quiet, VolumeUse use) {
    if (is_series_pattern(o.path)) return open_step(o, quiet, use);
    if (o.time != 0)
        throw InputError("--time", "value",
                         "applies to a time series: a numbered --volume pattern (run/t_%03d.nrrd)");
    OpenedVolume out;
    Stopwatch sw;
    std::string store_note;
    std::optional<OpenedVolume> out_rechunked;
    std::string shown;  // the name the line gives; empty: the volume's source
    if (o.path.empty()) {
        if (!o.dims.empty() || !o.type.empty())
            throw InputError("--dims/--type", "--volume", "raw options need --volume FILE");
        out.volume = make_phantom();
    } else if (own_store(o.path)) {
        if (!o.dims.empty() || !o.type.empty())
            throw InputError(o.path, "--dims/--type", "a store carries its own size and type");
        const std::uint64_t cap = memory_limit(o, use);
        const std::filesystem::path path = store::store_path(o.path);
        store::OpenedStore opened = store::open_store(path, cap);
        out.volume = std::move(opened.volume);
        out.pager = std::move(opened.pager);
        out.store = std::move(opened.reader);
        out.file = path;
        store_note = " (" + opened.how + ")";
    } else if (formats::is_zarr_source(o.path) &&
               (out_rechunked = open_rechunked(o, quiet, use, store_note))) {
        out = std::move(*out_rechunked);
        shown = o.path;  // the store given, not its copy (named in the note)
    } else {
        // A volume not cast (import) streams its file itself, at the disk's pace.
        out.volume = formats::is_url(o.path) ? formats::read_url(o.path, http_options(o))
                                             : formats::read_volume(o.path, raw_spec(o), use.casts);
        out.file = std::filesystem::path(o.path);
        check_no_memory_limit(o);
    }
    std::string huge_note;
    // A store's voxels stay paged: a copy would read them all.
    if (use.casts && !out.volume.paged()) {
        const auto mode = parse_huge_pages(o.huge_pages);
        if (!mode)
            throw InputError("--huge-pages", "value",
                             "expected auto, on or off, got " + quote(o.huge_pages));
        const HugePagesChoice choice =
            choose_huge_pages(*mode, out.volume.bytes().size(), use.copies_on_host, thp_mode(),
                              mem_available(), use.one_frame);
        huge_note = " (huge pages: no, " + choice.why + ")";
        if (choice.copy) {
            try {
                out.volume.copy_to_huge_pages();
                huge_note = " (" + choice.why + ")";
            } catch (const std::runtime_error& e) {
                // The mapping failed (no address space or memory): asked for, that is the error;
                // under auto the volume stays in its map, which works, only slower.
                if (*mode == HugePages::on) throw InputError("--huge-pages", "on", e.what());
                huge_note = std::string(" (huge pages: no, ") + e.what() + ")";
            }
        }
    }
    out.load_s = sw.seconds();
    if (out.file) out.cache_dir = cache_dir(o);
    if (quiet) return out;
    const Volume& v = out.volume;
    const glm::ivec3 d = v.dims();
    const glm::vec3 s = v.spacing();
    const char* where = v.in_huge_pages() ? "in huge pages"
                        : v.paged()       ? "in a store"
                        : v.mapped()      ? "memory-mapped"
                                          : "in memory";
    std::printf("volume: %s  %dx%dx%d %s  spacing %g %g %g  %.1f MiB %s%s  (%.2f s)\n",
                (shown.empty() ? v.source() : shown).c_str(), d.x, d.y, d.z,
                std::string(type_name(v.type())).c_str(), double(s.x), double(s.y), double(s.z),
                double(v.bytes().size()) / (1024.0 * 1024.0), where,
                (huge_note + store_note).c_str(), out.load_s);
    return out;
}

}  // namespace isowall
