#include "app/program_cli.h"

#include "cli/cli_checks.h"
#include "cli/iso_option.h"
#include "core/error.h"
#include "core/util.h"

namespace isowall {
namespace {

// parse_size first: from_chars, so no digits overflow an int on the way to parse_region.
const CLI::Validator kRegion(
    [](std::string& s) {
        return s == "auto" || s == "tile" || (parse_size(s) && parse_region(s))
                   ? std::string()
                   : "expected auto, WxH, each 1 to 32768 (e.g. 256x192), or 'tile', got " +
                         quote(s);
    },
    "auto|WxH|tile");

CLI::App* add_render_command(CLI::App& app, RenderOptions& re) {
    auto* re_cmd = app.add_subcommand(
        "render", "Render one view progressively (or the full surface with --full) to an image");
    add_volume_options(*re_cmd, re.volume);
    add_surfaces_option(*re_cmd, re.iso);
    add_clip_options(*re_cmd, re.clip);
    add_colour_options(*re_cmd, re.colour);
    re_cmd->add_option("--size", re.size, "Image size WIDTHxHEIGHT")->capture_default_str();
    re_cmd->add_option("--out,-o", re.out, "Output image (PNG, or any format OpenImageIO writes)")
        ->capture_default_str();
    re_cmd->add_option("--depth-out", re.depth_out, "Also write window depth (EXR)");
    re_cmd->add_option("--gl", re.gl, "OpenGL back end")
        ->check(CLI::IsMember({"osmesa", "egl"}))
        ->capture_default_str();
    re_cmd->add_option("--projection", re.projection, "perspective or orthographic")
        ->check(CLI::IsMember({"perspective", "orthographic"}))
        ->capture_default_str();
    re_cmd->add_option("--orbit", re.orbit, "Rotate the front view: YAW PITCH in degrees")
        ->expected(2)
        ->transform(number_in(limits::kAngleDeg));
    re_cmd->add_option("--zoom", re.zoom, "Zoom factor (>1 moves closer)")
        ->transform(number_in(limits::kZoom))
        ->capture_default_str();
    re_cmd->add_flag("--full", re.full,
                     "Extract and draw the whole surface instead of the progressive engine");
    add_engine_options(*re_cmd, re.engine);
    re_cmd->add_option("--timeline", re.timeline, "Write the timeline (CSV) of the frame");
    re_cmd
        ->add_option("--snapshots", re.snapshots,
                     "Write the image when correctness first reaches these percentages, e.g. "
                     "90,99,99.9")
        ->delimiter(',')
        ->transform(number_in(limits::kPercent));
    re_cmd
        ->add_option("--snapshot-measure", re.snapshot_measure,
                     "Correctness measure for --snapshots: final (share of final pixels, "
                     "chapters 2-3) or c (C = 1 - E, section 4.2)")
        ->check(CLI::IsMember({"final", "c"}))
        ->capture_default_str();
    re_cmd
        ->add_option("--snapshot-rays", re.snapshot_rays,
                     "Write the image after these numbers of rays, e.g. 100,10000")
        ->delimiter(',')
        ->transform(number_in(limits::kRayCount));
    re_cmd->add_flag("--no-measure", re.no_measure,
                     "Skip the replay that measures correctness against the final image");
    re_cmd
        ->add_option("--threads", re.threads,
                     "Threads casting rays and propagating side by side (and building the "
                     "octree); 0: every core of the machine. With 1, llvmpipe rasterises in the "
                     "drawing thread too (LP_NUM_THREADS=0 unless set), so the frame uses one core")
        ->transform(number_in({0, 1024, false, true}))
        ->capture_default_str();
    re_cmd->add_flag("--against-full", re.against_full,
                     "After the progressive frame, extract and draw the full surface (not timed) "
                     "and print both correctness measures of the final image against it: what "
                     "adaptive resolution and other shortcuts cost in the image");
    re_cmd->add_flag(
        "--against-truth", re.against_truth,
        "After the frame (not timed), draw the full surface at 4x4 samples per pixel, "
        "box-filtered (what a pixel can show), and print C_T and coverage IoU against it for "
        "the final image and for the full surface at one sample per pixel, and whether the final "
        "image passes the fidelity gate (C_T within 0.005 and IoU within 0.002 of the full "
        "surface's, or better)");
    re_cmd->add_flag("--warm-up", re.warm_up,
                     "First draw one untimed frame (of the view turned 30 degrees; with --full, "
                     "the same full surface), so the timed frame finds the process warm as a "
                     "running wall's frames do: without it, the timings include a fresh "
                     "process's first touch of its memory");
    re_cmd->add_flag("--quiet,-q", re.quiet, "No progress lines while casting");

    return re_cmd;
}

void add_control_options(CLI::App& wall_cmd, WallOptions& wall) {
    wall_cmd.add_flag(
        "--control", wall.control,
        "Open the control window on the master's display: a live mosaic of the "
        "wall; drag orbits, wheel zooms, Up/Down change the isovalue, Left/Right "
        "move the head, c and [ ] clip, s snapshots, Escape quits (after --script FILE, "
        "if given)");
    wall_cmd.add_option("--control-display", wall.control_display,
                        "X display of the control window (default $DISPLAY)");
    wall_cmd
        .add_option("--http", wall.http_port,
                    "Serve the wall's page on this port (0: any free port, printed): the live "
                    "mosaic, steering from a browser, several pages watching")
        ->check(CLI::Range(0, 65535));
    wall_cmd
        .add_option("--http-listen", wall.http_listen,
                    "Address of the page; anything but loopback needs --tls-cert, --tls-key and "
                    "--token")
        ->capture_default_str();
    wall_cmd.add_option("--token", wall.token, "A secret every page must present (--http)");
    wall_cmd.add_option("--tls-cert", wall.tls_cert,
                        "The page over https and wss: this PEM certificate chain, with --tls-key");
    wall_cmd.add_option("--tls-key", wall.tls_key,
                        "The PEM private key of --tls-cert (no passphrase)");
    add_allow_host_option(wall_cmd, wall.allow_hosts, "--http");
}

// What each rank of a wall may use: its threads, and where it reads a store.
void add_rank_options(CLI::App& wall_cmd, WallOptions& wall) {
    wall_cmd
        .add_option("--threads", wall.threads,
                    "Threads each rank may use (octree build; rays and propagation). 0: its "
                    "share of its node's cores (1 each when emulating a wall on one machine)")
        ->transform(number_in({0, 1024, false, true}))
        ->capture_default_str();
    wall_cmd
        .add_option("--emulate-cores", wall.emulate_cores,
                    "At most N tile ranks of a host run a job at once, each holding one of N "
                    "slots while it works: a cluster with a core per rank emulated on a host of N "
                    "cores, where a job's CPU is then less inflated by ranks competing for the "
                    "cores and their caches (for studies). 0: no limit")
        ->transform(number_in({0, 4096, false, true}))
        ->capture_default_str();
    wall_cmd
        .add_option("--bricks-from", wall.bricks_from,
                    "Where tile ranks read a store (--volume STORE): auto, on their own host when "
                    "they can see its folder, else from the master over MPI; master, always "
                    "from the master")
        ->check(CLI::IsMember({"auto", "master"}))
        ->capture_default_str();
}

// The screen-region scheduler's options of `wall` (master/job_board.h, region_plan.h,
// dispatch_order.h).
void add_scheduler_options(CLI::App& cmd, WallOptions& wall) {
    cmd.add_option("--balance", wall.balance,
                   "Screen-region scheduler: on, idle ranks take regions of busy tiles; off, "
                   "every tile casts its own screen (the static wall)")
        ->transform(
            CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}))
        ->default_str("on");
    cmd.add_option("--region", wall.region,
                   "Screen regions the scheduler hands out (balancing on): auto, cut where the "
                   "work is (estimated from the octree, then measured in the last frame); WxH, "
                   "a fixed grid of that size (for studies); 'tile', one region per tile")
        ->check(kRegion)
        ->capture_default_str();
    cmd.add_option("--dispatch", wall.dispatch,
                   "Which rank asking for work is served first: arrival, the first to ask (a "
                   "cluster, a core per rank); emulated, the one whose CPU clock is earliest, so "
                   "that on fewer cores than ranks the operating system's choice of who ran does "
                   "not decide who works (for studies; needs progress from busy ranks)")
        ->check(CLI::IsMember({"arrival", "emulated"}))
        ->capture_default_str();
    cmd.add_option("--region-clip", wall.region_clip,
                   "Propagation stays within the screen region of each job (or tile): on, no "
                   "pass extracts surface its region cannot show; off, as in the text")
        ->transform(
            CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}))
        ->default_str("on");
}

CLI::App* add_wall_command(CLI::App& app, WallOptions& wall) {
    auto* wall_cmd = app.add_subcommand(
        "wall",
        "Display-wall run under mpirun: rank 0 is the master, ranks 1..T drive one tile each");
    add_volume_options(*wall_cmd, wall.volume);
    wall_cmd->add_option("--wall", wall.wall, "Wall file (TOML; see walls/)")->required();
    add_surfaces_option(*wall_cmd, wall.iso);
    add_clip_options(*wall_cmd, wall.clip);
    add_colour_options(*wall_cmd, wall.colour);
    wall_cmd->add_option("--out,-o", wall.out, "Mosaic of the whole wall (PNG)")
        ->capture_default_str();
    wall_cmd->add_option("--tiles-out", wall.tiles_out,
                         "Also write each tile's image into this folder");
    wall_cmd->add_option("--gl", wall.gl, "OpenGL back end")
        ->check(CLI::IsMember({"osmesa", "egl"}))
        ->capture_default_str();
    add_engine_options(*wall_cmd, wall.engine);
    wall_cmd->add_option("--script", wall.script,
                         "Commands (orbit, look-at, zoom, pan, iso, head, clip, wait, snapshot, "
                         "quit), one per line; "
                         "- reads them from the master's console");
    add_control_options(*wall_cmd, wall);
    wall_cmd
        ->add_option("--timeout", wall.timeout_s,
                     "Seconds a silent tile rank may take before the job ends (under mpirun "
                     "--enable-recovery: before the others draw its screen)")
        ->transform(number_in(limits::kSeconds))
        ->capture_default_str();
    wall_cmd
        ->add_option("--startup-timeout", wall.startup_timeout_s,
                     "Seconds the tile ranks may take to load the volume and start")
        ->transform(number_in(limits::kSeconds))
        ->capture_default_str();
    add_rank_options(*wall_cmd, wall);
    wall_cmd->add_option("--trace", wall.trace,
                         "Write per-rank spans by stage with thread CPU time: PREFIX.json (Chrome "
                         "trace, opens in Perfetto) and PREFIX.csv; migrated jobs show as flows");
    wall_cmd->add_option("--orbit", wall.orbit, "Start turned: YAW PITCH in degrees")
        ->expected(2)
        ->transform(number_in(limits::kAngleDeg));
    wall_cmd->add_option("--zoom", wall.zoom, "Start zoomed (>1 moves closer)")
        ->transform(number_in(limits::kZoom))
        ->capture_default_str();
    wall_cmd
        ->add_option("--pan", wall.pan,
                     "Start panned: DX DY in screen widths and heights (the view moves right, up)")
        ->expected(2)
        ->transform(number_in(limits::kPan));
    add_scheduler_options(*wall_cmd, wall);
    wall_cmd->add_flag("--windows", wall.windows,
                       "Each tile shows its frame as it builds in a borderless window covering "
                       "its X screen (the wall file's display keys, else $DISPLAY)");
    wall_cmd->add_flag("--measure", wall.measure,
                       "Measure wall-wide correctness against emulated time (each rank on its own "
                       "core, from thread CPU time); costs a read-back per job");
    return wall_cmd;
}

}  // namespace

std::string unknown_subcommand(const CLI::App& app, int argc, const char* const* argv) {
    if (argc < 2 || argv[1][0] == '-') return {};
    const std::string word = argv[1];
    std::string names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
        if (sub->get_name() == word) return {};
        names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    return "unknown subcommand " + quote(word) + "; expected one of " + names;
}

ProgramCli::ProgramCli() {
    app.require_subcommand(1);
    app.set_version_flag("--version", "isowall 0.1.0");

    info_cmd = app.add_subcommand("info", "Print a volume's size, type, value range and octree");
    add_volume_options(*info_cmd, info.volume);

    ex_cmd = app.add_subcommand(
        "extract",
        "Extract the full isosurface to a mesh file: PLY, STL, OBJ, VTK PolyData or binary glTF");
    add_volume_options(*ex_cmd, ex.volume);
    add_iso_option(*ex_cmd, ex.iso);
    add_clip_options(*ex_cmd, ex.clip);
    ex_cmd
        ->add_option("--out,-o", ex.out,
                     "Output mesh, its format by the extension: .ply (binary, with normals), .stl "
                     "(binary), .obj, .vtp (VTK XML PolyData, for ParaView) or .glb (binary glTF "
                     "2.0). Positions in object units (voxel index times spacing)")
        ->required();
    ex_cmd
        ->add_option("--compress", ex.compress,
                     "A .glb's compression: none, or meshopt (EXT_meshopt_compression: lossless, "
                     "the vertices reordered for the GPU's caches; three.js, Babylon.js and "
                     "glTF-Transform read it). Default: none")
        ->check(CLI::IsMember({"none", "meshopt"}));

    re_cmd = add_render_command(app, re);
    wall_cmd = add_wall_command(app, wall);
    serve_cmd = add_serve_command(app, serve);
    view_cmd = add_view_command(app, view);
    import_cmd = add_import_command(app, import);
    wall_cmd->add_flag("--ranks-needed", ranks_needed,
                       "Print the -np this wall file needs (1 + its tiles) and exit, without MPI");
}

}  // namespace isowall
