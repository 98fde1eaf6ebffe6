#include "app/wall_run.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <tuple>

#include "app/remote_commands.h"
#include "app/step_volumes.h"
#include "app/wall_http.h"
#include "app/wall_outputs.h"
#include "cli/iso_option.h"
#include "comm/host_slots.h"
#include "core/error.h"
#include "core/fatal.h"
#include "core/util.h"
#include "extract/surface_extractor.h"
#include "master/console.h"
#include "master/control_window.h"
#include "master/wall_master.h"
#include "render/renderer.h"
#include "store/open_store.h"
#include "tile/preview_show.h"
#include "tile/store_client.h"
#include "tile/tile_loop.h"
#include "tile/tile_window.h"
#include "volume/phantom.h"
#include "volume/time_steps.h"
#include "wall_spec/control_layout.h"
#include "wall_spec/script.h"
#include "wall_spec/wall.h"

namespace isowall {
namespace {

// A stereo eye's window covers its half of the tile's screen (side-by-side, top-bottom), or the
// whole of its own screen (full).
WindowOptions::Part window_part(const WallSpec& spec, Eye eye) {
    using Part = WindowOptions::Part;
    if (!spec.stereo || eye == Eye::centre || spec.stereo->mode == StereoMode::full)
        return Part::whole;
    if (spec.stereo->mode == StereoMode::side_by_side)
        return eye == Eye::left ? Part::left_half : Part::right_half;
    return eye == Eye::left ? Part::top_half : Part::bottom_half;
}

// The full mode shows each eye on a screen of its own: with --windows, the right eyes need theirs.
void check_windows(const WallSpec& spec, const WallOptions& o) {
    if (o.windows && spec.stereo && spec.stereo->mode == StereoMode::full &&
        spec.stereo->right_display.empty())
        throw InputError(o.wall, "stereo.right_display",
                         "--windows with the full mode shows each eye on a screen of its own; give "
                         "the right eyes' X display");
}

std::unique_ptr<SurfaceExtractor> open_extractor(const OpenedVolume& ov, ThreadBudget budget) {
    OctreeSource src;
    if (ov.file) src.volume_path = *ov.file;
    src.cache_dir = ov.cache_dir;
    return make_surface_extractor(ov.volume, src, nullptr, budget);
}

// --volume's time series, when it is a numbered pattern (volume/time_steps.h).
std::optional<TimeSeries> time_series(const VolumeOptions& v) {
    if (!is_series_pattern(v.path)) return std::nullopt;
    return find_series(v.path, "--volume");
}

// The rank's thread budget: --threads, or its share of the node's cores (core/
// thread_budget.h), so that ranks emulating a wall on one machine do not oversubscribe it.
ThreadBudget rank_budget(const WallOptions& o, const Comm& comm) {
    if (o.threads > 0) return ThreadBudget{o.threads};
    return node_share(cores_allowed(), ThreadBudget::hardware().threads, comm.ranks_on_host());
}

// What the master checks before any frame starts: a bad volume, isovalue, output folder, engine
// option or script line stops the job here, with one line naming the source and the field.
struct MasterInput {
    std::optional<OpenedVolume> volume;
    std::unique_ptr<SurfaceExtractor> extractor;
    double iso = 0;
    ClipSet clip;
    std::vector<SurfaceStyle> surfaces;       // --iso's, canonical order
    std::optional<TimeSeries> series;         // --volume's steps, when it is a numbered pattern
    std::optional<OpenedColourField> colour;  // --color-by: checked here, its range for the legend
    std::vector<ScriptLine> script;
};

MasterInput check_master_input(const WallOptions& o, ThreadBudget budget) {
    MasterInput in;
    in.clip = checked_clip(o.clip);
    (void)checked_colour_map(o.colour);
    // A time series: the master reads the first step shown (--time: its range, bounds and work
    // estimate stand for every step); the tiles open each step a view shows.
    in.series = time_series(o.volume);
    // The master casts no ray: its volume stays in the shared map.
    in.volume.emplace(open_volume(o.volume, /*quiet=*/false, VolumeUse{.casts = false}));
    const OpenedVolume& ov = *in.volume;
    in.extractor = open_extractor(ov, budget);
    in.surfaces =
        checked_surfaces(o.iso, {ov.file ? ov.file->string() : std::string("phantom"), !ov.file,
                                 in.extractor->value_min(), in.extractor->value_max()});
    in.iso = in.surfaces[0].iso;
    if (o.measure && !one_opaque_surface(in.surfaces))
        throw InputError("--measure", "--iso",
                         "studies one opaque surface; drop --measure or give one --iso");
    check_clip_keeps(in.clip, ov.volume.dims(), "--clip", "value");
    in.colour = open_colour_field(o.colour, o.volume, ov.volume);
    to_engine_options(o.engine);
    // The console and the window or page would both take the operator's commands; one at a
    // time (the window and the page share one loop and take turns).
    if ((o.control || o.http_port >= 0) && o.script == "-")
        throw InputError(o.control ? "--control" : "--http", "--script",
                         "the console (--script -) cannot drive the wall beside the control "
                         "window or the page; give one, or a script file");
    if (o.http_port < 0)
        for (const auto& [given, name] : {std::pair{!o.token.empty(), "--token"},
                                          {!o.tls_cert.empty(), "--tls-cert"},
                                          {!o.tls_key.empty(), "--tls-key"},
                                          {!o.allow_hosts.empty(), "--allow-host"},
                                          {o.http_listen != "127.0.0.1", "--http-listen"}})
            if (given) throw InputError(name, "value", "applies to the page: give --http PORT");
    // A folder, a device or a missing file is an error naming --script (a folder read as empty).
    if (!o.script.empty() && o.script != "-") in.script = load_script(o.script);
    check_wall_outputs(o, load_wall(o.wall), in.script);
    return in;
}

int run_master(const WallOptions& o, Comm& comm, const WallSpec& spec, MasterInput& in) {
    MasterOptions mo;
    mo.wall_name = o.wall;
    mo.front_axes = in.volume->volume.orientation().axes;
    mo.out = o.out;
    mo.tiles_out = o.tiles_out;
    mo.trace = o.trace;
    mo.timeout_s = o.timeout_s;
    mo.startup_timeout_s = o.startup_timeout_s;
    if (o.fault.rank == kMasterRank) mo.fault = o.fault;
    mo.results_out = o.results_out;
    mo.balance = o.balance;
    if (o.orbit.size() == 2) mo.orbit = {o.orbit[0], o.orbit[1]};
    mo.zoom = o.zoom;
    mo.clip = in.clip;
    mo.surfaces = in.surfaces;
    if (in.series) {
        mo.steps = in.series->steps.size();
        mo.first_step = o.volume.time;
        std::printf("time series: %zu steps, %s to %s\n", mo.steps,
                    in.series->steps.front().filename().c_str(),
                    in.series->steps.back().filename().c_str());
    }
    if (in.colour) {
        mo.legend = in.colour->field.scale;
        mo.legend_label = colour_label(o.colour, in.colour->field.scale);
    }
    mo.dims = in.volume->volume.dims();
    if (o.pan.size() == 2) mo.pan = {o.pan[0], o.pan[1]};
    mo.regions_from_work = o.region == "auto";
    mo.dispatch = o.dispatch == "emulated" ? Dispatch::emulated : Dispatch::arrival;
    std::tie(mo.region_w, mo.region_h) = parse_region(o.region).value_or(std::pair{0, 0});
    // The work estimate's boxes: the screen mask's active nodes (engine/region_cursor.cpp).
    mo.work_boxes = [&ex = *in.extractor](double iso) {
        return ex.active_boxes(iso, kWorkBoxes, 0).boxes;
    };
    mo.screen_box = to_engine_options(o.engine).screen_box;
    mo.measure = o.measure;
    if (o.control || o.http_port >= 0) mo.preview_side = preview_max_side(spec);
    mo.store = in.volume->store;
    mo.store_octree = in.volume->volume.own_octree();
    WallMaster master(mo, comm, spec, in.volume->volume.bounds(), in.iso, in.extractor->value_min(),
                      in.extractor->value_max());
    // Opened before the tiles load: a display that cannot open, a port in use or a certificate
    // that does not load ends the job at once.
    std::optional<ControlWindow> control;
    if (o.control) control.emplace(spec, o.control_display, o.out);
    std::optional<WallHttp> http;
    if (o.http_port >= 0)
        http.emplace(spec, WallHttpOptions{o.http_listen, o.http_port, o.token,
                                           server_tls(o.tls_cert, o.tls_key), o.allow_hosts, o.out,
                                           std::filesystem::path(o.wall).filename().string()});
    master.start();
    const std::string where = o.script.empty() ? std::string("--script") : o.script;
    bool quit = false;
    if (o.script == "-") {
        run_console(
            STDIN_FILENO,
            [&](const ScriptCommand& c, const std::string& w) { return master.execute(c, w); },
            [&] { master.idle(); });
    } else {
        for (const ScriptLine& l : in.script)
            if (!master.execute(l.command, where + ":" + std::to_string(l.line))) {
                quit = true;
                break;
            }
    }
    std::vector<SteeringSource*> steering;
    if (control) steering.push_back(&*control);
    if (http) steering.push_back(&*http);
    if (!steering.empty() && !quit)
        run_steering(master, steering, control ? "control" : "http");
    else if (o.script.empty())
        master.execute(WaitCmd{WaitCmd::Until::done, 0}, where);
    return master.finish();
}

// A tile rank's volume: read on its own host, or, where the host cannot see the store given as
// --volume (or with --bricks-from master), the master's store through `remote`.
OpenedVolume open_tile_volume(const WallOptions& o, Comm& comm,
                              std::optional<StoreClient>& remote) {
    const VolumeUse use{.copies_on_host = comm.ranks_on_host()};
    const std::string& path = o.volume.path;
    if (path.empty() || (o.bricks_from != "master" && readable_here(path)))
        return open_volume(o.volume, /*quiet=*/true, use);
    remote.emplace(comm, o.timeout_s);
    // The octree's copy lives in the cache folder (a temporary one with --no-cache).
    const std::filesystem::path cache = cache_dir(o.volume);
    const std::filesystem::path dir =
        cache.empty() ? std::filesystem::temp_directory_path() : cache;
    auto reader = remote->open(path, dir);
    return open_volume(o.volume, std::move(reader), remote->octree_file(), use);
}

int run_tile_rank(const WallOptions& given, Comm& comm, const WallSpec& spec, ThreadBudget budget) {
    // A time series: step 0 opened here, the others when a view first shows them.
    const std::optional<TimeSeries> series = time_series(given.volume);
    WallOptions o = given;
    if (series) {
        o.volume.path = series->steps[0].string();
        o.volume.time = 0;
    }
    std::optional<StoreClient> remote;
    const OpenedVolume ov = open_tile_volume(o, comm, remote);
    auto extractor = open_extractor(ov, budget);
    std::optional<StepVolumes> steps;
    if (series)
        steps.emplace(
            *series, o.volume, VolumeUse{.copies_on_host = comm.ranks_on_host()},
            [budget](const OpenedVolume& v) { return open_extractor(v, budget); }, ov, *extractor);
    // A rank with one core (a wall emulated on one machine) has llvmpipe rasterise in its drawing
    // thread, unless the user says otherwise: the work then stays on its core and in the frame
    // thread's CPU clock, which the trace and the emulated time read. With more, llvmpipe keeps
    // its raster threads (groups of 2,000 triangles draw 2.3x faster with one than with none,
    // isowall_bench_render at 1024x768), and their CPU is not in the trace. A vendor driver
    // ignores the variable. Ranks that are threads of one process (tests) leave the shared
    // environment alone: another rank's thread may be reading it.
    if (budget.usable() == 1 && comm.owns_process()) setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);
    auto renderer = make_renderer(o.gl);
    auto help_renderer = make_renderer(o.gl);
    TileSetup setup{*extractor, *renderer, *help_renderer, to_engine_options(o.engine),
                    {},         o.measure};
    // The master has checked --color-by against the volume; every rank reads the field itself.
    const std::optional<OpenedColourField> colour =
        open_colour_field(o.colour, o.volume, ov.volume);
    if (colour) setup.engine.colour = colour_hook(colour->field, ov.volume.spacing());
    setup.engine.region_clip = o.region_clip;
    setup.engine.threads = budget.usable();
    if (o.fault.on(comm.rank())) setup.fault = o.fault;
    setup.make_renderer = [gl = o.gl] { return make_renderer(gl); };
    if (steps)
        setup.step_extractor = [&steps](std::uint32_t k) -> SurfaceExtractor& {
            return steps->extractor(k);
        };
    const PixelRect tile = eye_rect(spec, tile_of_rank(spec, comm.rank()));
    setup.timeout_s = o.timeout_s;
    setup.tile_width = tile.width;
    setup.tile_height = tile.height;
    if (ov.pager) setup.io_cpu_s = [pager = ov.pager] { return pager->stats().cpu_s; };
    if (remote) setup.store_client = &*remote;
    std::optional<HostSlots> slots;
    if (o.emulate_cores > 0) {
        slots.emplace(comm.job_id(), o.emulate_cores);
        setup.slots = &*slots;
    }
    // The name goes when the rank ends, however it ends (every rank of the host has opened it
    // by then: the master starts no frame before every tile has said hello).
    struct UnlinkAtEnd {
        std::optional<HostSlots>& slots;
        ~UnlinkAtEnd() {
            if (slots) slots->unlink();
        }
    } const unlink_slots{slots};
    std::optional<TileWindow> window;
    if (o.windows) {
        const int t = tile_of_rank(spec, comm.rank());
        const Eye eye = eye_of_rank(spec, comm.rank());
        window.emplace(tile_display(spec, t, eye), t, comm.host(), window_part(spec, eye), eye);
        setup.shows.push_back(&*window);
    }
    std::optional<PreviewShow> preview;
    if (o.control || o.http_port >= 0) {
        preview.emplace(comm, preview_max_side(spec));
        setup.shows.push_back(&*preview);
    }
    const int status = run_tile(comm, setup);
    // A study's figure (--measure): what this rank's pager read, to weigh one cache per host
    // against one per rank (docs/volumes.md).
    if (ov.pager && o.measure)
        std::printf("rank %d store: %s\n", comm.rank(),
                    store::paging_line(ov.pager->stats(), ov.pager->cap()).c_str());
    return status;
}

// A tile waits for the master's start (the volume is loaded and its octree cached, so the tile
// maps the same files rather than building its own), for at most the start-up limit.
void await_start(Comm& comm, double timeout_s) {
    const double limit_s = timeout_s + tile_grace_s(comm.rank());
    Stopwatch waited;
    while (waited.seconds() < limit_s) {
        auto e = comm.receive(kMasterRank, 0.05);
        if (!e) continue;
        const Message m = decode_message(e->tag, e->bytes);
        if (std::holds_alternative<StartMsg>(m)) return;
        if (!std::holds_alternative<AliveMsg>(m))
            throw WireError(std::string("expected start from the master, got ") +
                            to_string(e->tag));
    }
    char msg[200];
    std::snprintf(msg, sizeof(msg),
                  "the master (rank 0) has not started the wall within %g s (--startup-timeout): "
                  "it is still loading the volume, has stopped, or cannot be reached",
                  timeout_s);
    throw MasterUnreachable(msg);
}

std::string role(const WallSpec& spec, int rank) {
    return rank == kMasterRank ? std::string("master") : tile_name(spec, rank);
}

// The job's one error line, then every rank ended. Bad input names its source and field already;
// any other error is prefixed with the rank that met it.
[[noreturn]] void print_and_end(Comm& comm, const WallSpec& spec, int rank, bool input,
                                const std::string& what) {
    std::fflush(stdout);
    // clip: one bounded line, every byte a terminal could act on escaped.
    if (input)
        std::fprintf(stderr, "isowall: error: %s\n", clip(what, 800).c_str());
    else
        std::fprintf(stderr, "isowall: error: rank %d (%s): %s\n", rank, role(spec, rank).c_str(),
                     clip(what, 800).c_str());
    std::fflush(stderr);
    comm.abort(input ? 1 : 2);
    throw CommAborted(input ? 1 : 2);  // not reached: abort() ends the rank
}

// How long a failed tile waits for the master to end the job before it says why itself: the
// master answers within a receive slice unless it is stopped or busy outside its loop.
constexpr double kMasterEndsJobS = 10;

// The single failure path: whatever a rank throws is printed once, as one line, and ends the job.
// A tile does not print: it tells the master, which prints the first failure it hears of (tiles
// that fail together, as on a damaged chunk each of them meets, give one line, not one per tile)
// and ends every rank. Only when the master cannot be told, or does not end the job in time,
// does the tile print its own line and end the job itself.
[[noreturn]] void fail(Comm& comm, const WallSpec& spec, const std::exception& e, bool input,
                       double timeout_s) {
    if (comm.rank() != kMasterRank && !dynamic_cast<const MasterUnreachable*>(&e)) {
        try {
            send_message(comm, kMasterRank, FailedMsg{input, e.what()});
            const Stopwatch waited;
            const double limit = std::min(timeout_s, kMasterEndsJobS);
            // Whatever comes meanwhile is for a rank that is ending; the in-process transport
            // throws CommAborted here once the master has ended the job.
            while (waited.seconds() < limit) comm.receive(kMasterRank, limit - waited.seconds());
        } catch (const CommAborted&) {
            throw;
        } catch (const std::exception&) {  // the master cannot be told: say it here
        }
    }
    print_and_end(comm, spec, comm.rank(), input, e.what());
}

}  // namespace

std::optional<std::pair<int, int>> parse_region(const std::string& spec) {
    if (spec == "tile") return std::pair{0, 0};
    int w = 0, h = 0, used = 0;
    if (std::sscanf(spec.c_str(), "%dx%d%n", &w, &h, &used) != 2 ||
        used != static_cast<int>(spec.size()))
        return std::nullopt;
    if (w < 1 || h < 1 || w > 32768 || h > 32768) return std::nullopt;
    return std::pair{w, h};
}

int run_wall(const WallOptions& o, Comm& comm) {
    // Every rank reads the wall file (it is small): a bad file is the same error everywhere, and
    // every rank can check the rank count against it without waiting for the master.
    WallSpec spec;
    try {
        spec = load_wall(o.wall);
        check_windows(spec, o);
    } catch (const std::exception& e) {
        if ((comm.rank() == kMasterRank))
            std::fprintf(stderr, "isowall: error: %s\n", clip(e.what(), 800).c_str());
        return 1;
    }
    if (comm.size() != rank_count(spec)) {
        std::fprintf(
            stderr,
            "isowall: error: %s: tiles: the wall has %d tile(s), so it needs mpirun -np %d "
            "(one master + one rank per tile); this job has %d ranks (rank %d)\n",
            o.wall.c_str(), rank_count(spec) - 1, rank_count(spec), comm.size(), comm.rank());
        return 1;
    }
    // An error where nothing can be thrown (a damaged chunk met by the pager mid-frame) ends the
    // job as any other error on a rank after start-up: named by the rank, exit 2, every rank ended.
    set_fatal_handler([&comm, &spec, &o](const std::string& what) {
        fail(comm, spec, std::runtime_error(what), false, o.timeout_s);
    });
    try {
        // The master loads first and writes the octree cache; the tile ranks then map the same
        // files, so the machine holds one copy of the volume and the octree.
        if (!(comm.rank() == kMasterRank)) {
            const ThreadBudget budget = rank_budget(o, comm);
            send_message(
                comm, kMasterRank,
                TileHelloMsg{comm.host(), static_cast<std::uint32_t>(budget.usable()), false});
            await_start(comm, o.startup_timeout_s);
            if (o.fault.rank == comm.rank()) raise_test_signal(o.fault, FaultMoment::load);
            return run_tile_rank(o, comm, spec, budget);
        }
        if (o.fault.rank == kMasterRank) raise_test_signal(o.fault, FaultMoment::load);
        std::optional<MasterInput> input;
        try {
            input.emplace(check_master_input(o, rank_budget(o, comm)));
        } catch (const InputError& e) {
            fail(comm, spec, e, true, o.timeout_s);
        }
        return run_master(o, comm, spec, *input);
    } catch (const CommAborted&) {
        throw;                       // another rank failed and has said why
    } catch (const TileFailed& e) {  // the master, told by a tile
        print_and_end(comm, spec, e.rank(), e.input(), e.what());
    } catch (const InputError& e) {
        fail(comm, spec, e, true, o.timeout_s);
    } catch (const std::exception& e) {
        fail(comm, spec, e, false, o.timeout_s);
    }
}

}  // namespace isowall
