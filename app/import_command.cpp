#include "app/import_command.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <thread>

#include "app/stop_signals.h"
#include "cli/cli_checks.h"
#include "cli/import_progress.h"
#include "core/error.h"
#include "core/util.h"
#include "store/store_writer.h"
#include "volume/load_checks.h"
#include "volume/octree.h"

namespace isowall {

CLI::App* add_import_command(CLI::App& app, ImportCommand& o) {
    auto* c = app.add_subcommand(
        "import",
        "Write a volume as a store (Zarr v2 with OME-Zarr metadata, zstd chunks with "
        "checksums) that --volume then reads on first touch, under --memory-limit. The source, "
        "in any format --volume reads, is read a slab at a time, never whole");
    c->add_option("source", o.source,
                  "The volume to import: any file or folder --volume reads (or give --volume)");
    add_volume_options(*c, o.volume);
    c->add_option("--out,-o", o.out, "The store folder to write")
        ->required()
        ->check(CLI::Validator(
            [](const std::string& s) { return s.empty() ? "name the store folder to write" : ""; },
            "FOLDER"));
    c->add_flag("--force", o.force,
                "Replace a store already at --out (only a store isowall wrote, holding no other "
                "files)");
    c->add_option("--level", o.level,
                  "zstd level, 1 (fastest) to 19 (smallest). Default: 1 (3 makes the 4x CT head "
                  "6% smaller and its import 10% slower)")
        ->transform(number_in({1, 19, false, true}));
    c->add_option("--levels", o.levels,
                  "Levels of the multiscale pyramid, each every other voxel of the one below "
                  "(what napari and neuroglancer show first). Default: down to one brick a side; "
                  "1: full resolution only")
        ->transform(number_in({1, 12, false, true}));
    c->add_flag("--quiet,-q", o.quiet, "No progress bar");
    return c;
}

int run_import(const ImportCommand& o) {
    VolumeOptions vo = o.volume;
    if (!o.source.empty() && !vo.path.empty() && o.source != vo.path)
        throw InputError(
            "source", "value",
            "the volume is given twice: " + quote(o.source) + " and --volume " + quote(vo.path));
    if (!o.source.empty()) vo.path = o.source;
    if (vo.path.empty())
        throw InputError("source", "value", "name the volume to import (a file or folder)");
    const std::filesystem::path out = store::store_path(o.out);
    {
        // The store is a folder, so the file checks of other outputs do not apply; its parent must
        // be there (a typo'd path is not created).
        const std::filesystem::path parent = std::filesystem::absolute(out).parent_path();
        std::error_code ec;
        if (!std::filesystem::is_directory(parent, ec))
            throw InputError(o.out, "--out", "folder " + parent.string() + " does not exist");
    }
    Stopwatch sw;  // from the open: a format decoded into memory reads its file there
    // Formats a library decodes stream a slab of planes at a time; raw data and raw NRRD are
    // mapped and streamed from the map; the rest (bzip2, hex, ascii NRRD) are decoded whole.
    std::unique_ptr<PlaneSource> planes = open_planes(vo);
    OpenedVolume ov;
    if (!planes) ov = open_volume(vo, o.quiet, VolumeUse{.casts = false});

    ImportProgressBar bar("import", o.quiet);
    store::ImportOptions opts;
    opts.replace = o.force;
    opts.zstd_level = o.level;
    opts.levels = o.levels;
    opts.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    opts.progress = [&](const store::ImportProgress& p) {
        bar.update(p);
        if (o.fault.on(0)) raise_test_signal(o.fault, FaultMoment::slab);
    };
    // A stop signal ends the import at the next slab, its temporary folder removed; then the
    // signal ends the process as it would have (128 + signal).
    catch_stop_signals();
    opts.stop = &stop_requested();
    std::optional<store::ImportResult> written;
    try {
        written = planes ? store::write_store(*planes, out, opts)
                         : store::write_store(ov.volume, out, opts);
    } catch (const store::ImportStopped& e) {
        bar.finish();
        std::fprintf(stderr, "import: %s (signal %d)\n", e.what(), stop_signal());
        std::fflush(stderr);
        end_by_stop_signal();
        throw;
    }
    const store::ImportResult& r = *written;
    bar.finish();
    const double write_s = sw.seconds();

    const double mib = 1024.0 * 1024.0;
    const store::StoreLayout& l = r.layout;
    const double source = double(voxel_bytes(l.dims, l.type));  // the voxels, all levels from them
    std::printf(
        "import: wrote %s  %dx%dx%d %s, %zu bricks of %d^3 (%d level%s), %.1f MiB -> %.1f MiB "
        "(%.2f:1) in %.2f s (%.0f MiB/s)\n",
        out.c_str(), l.dims.x, l.dims.y, l.dims.z, std::string(type_name(l.type)).c_str(),
        l.chunk_count(), l.brick(), l.levels, l.levels == 1 ? "" : "s", source / mib,
        double(r.bytes_out) / mib, source / double(std::max<std::uint64_t>(r.bytes_out, 1)),
        write_s, source / mib / std::max(write_s, 1e-9));
    std::printf("import: octree %s\n",
                r.octree_note.empty() ? ("written to " + store::octree_file(out).string()).c_str()
                                      : ("not written: " + r.octree_note).c_str());
    const char* how = planes               ? "decoded a slab of planes at a time"
                      : ov.volume.mapped() ? "read a slab at a time from the file's memory map"
                                           : "decoded whole first";
    std::printf("import: source %s; peak resident memory %.0f MiB\n", how, peak_rss_mib());
    return 0;
}

}  // namespace isowall
