// isowall: progressive view-dependent isosurfaces for display walls.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <tuple>

#include <CLI/CLI.hpp>

#include "common/core/util.h"
#include "master/commands.h"
#include "master/wall_run.h"

namespace {

using namespace isowall;

// CLI::PositiveNumber lets "nan" and "inf" through; a limit in seconds must be a finite number > 0.
const CLI::Validator kPositiveSeconds(
    [](std::string& text) {
        double v = 0;
        try {
            std::size_t used = 0;
            v = std::stod(text, &used);
            if (used != text.size()) return "expected a number of seconds, got \"" + text + "\"";
        } catch (const std::exception&) {
            return "expected a number of seconds, got \"" + text + "\"";
        }
        if (!std::isfinite(v) || v <= 0)
            return "expected a finite number of seconds > 0, got " + text;
        return std::string();
    },
    "SECONDS > 0");

// A finite number (NaN and infinity turn a camera into garbage with no error).
const CLI::Validator kFiniteNumber(
    [](std::string& text) {
        try {
            std::size_t used = 0;
            const double v = std::stod(text, &used);
            if (used == text.size() && std::isfinite(v)) return std::string();
        } catch (const std::exception&) {
        }
        return "expected a finite number, got \"" + text + "\"";
    },
    "FINITE");

CLI::App* add_render_command(CLI::App& app, RenderOptions& re) {
    auto* re_cmd = app.add_subcommand(
        "render", "Render one view progressively (or the full surface with --full) to an image");
    add_volume_options(*re_cmd, re.volume);
    re_cmd->add_option("--iso", re.iso, "Isovalue (default for the phantom: skin, 50)");
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
        ->expected(2);
    re_cmd->add_option("--zoom", re.zoom, "Zoom factor (>1 moves closer)")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    re_cmd->add_flag("--full", re.full,
                     "Extract and draw the whole surface instead of the progressive engine");
    add_engine_options(*re_cmd, re.engine);
    re_cmd->add_option("--timeline", re.timeline, "Write the timeline (CSV) of the frame");
    re_cmd
        ->add_option("--snapshots", re.snapshots,
                     "Write the image when correctness first reaches these percentages, e.g. "
                     "90,99,99.9")
        ->delimiter(',');
    re_cmd
        ->add_option("--snapshot-measure", re.snapshot_measure,
                     "Correctness measure for --snapshots: final (share of final pixels, "
                     "chapters 2-3) or c (C = 1 - E, section 4.2)")
        ->check(CLI::IsMember({"final", "c"}))
        ->capture_default_str();
    re_cmd
        ->add_option("--snapshot-rays", re.snapshot_rays,
                     "Write the image after these numbers of rays, e.g. 100,10000")
        ->delimiter(',');
    re_cmd->add_flag("--no-measure", re.no_measure,
                     "Skip the replay that measures correctness against the final image");
    re_cmd->add_flag("--quiet,-q", re.quiet, "No progress lines while casting");

    return re_cmd;
}

CLI::App* add_wall_command(CLI::App& app, WallOptions& wall) {
    auto* wall_cmd = app.add_subcommand(
        "wall",
        "Display-wall run under mpirun: rank 0 is the master, ranks 1..T drive one tile each");
    add_volume_options(*wall_cmd, wall.volume);
    wall_cmd->add_option("--wall", wall.wall, "Wall file (TOML; see walls/)")->required();
    wall_cmd->add_option("--iso", wall.iso, "Isovalue (default for the phantom: skin, 50)");
    wall_cmd->add_option("--out,-o", wall.out, "Mosaic of the whole wall (PNG)")
        ->capture_default_str();
    wall_cmd->add_option("--tiles-out", wall.tiles_out,
                         "Also write each tile's image into this folder");
    wall_cmd->add_option("--gl", wall.gl, "OpenGL back end")
        ->check(CLI::IsMember({"osmesa", "egl"}))
        ->capture_default_str();
    add_engine_options(*wall_cmd, wall.engine);
    wall_cmd->add_option(
        "--script", wall.script,
        "Commands (orbit, look-at, zoom, pan, iso, wait, snapshot, quit), one per line; "
        "- reads them from the master's console");
    wall_cmd
        ->add_option("--timeout", wall.timeout_s,
                     "Seconds a silent tile rank may take before the job ends")
        ->check(kPositiveSeconds)
        ->capture_default_str();
    wall_cmd
        ->add_option("--startup-timeout", wall.startup_timeout_s,
                     "Seconds the tile ranks may take to load the volume and start")
        ->check(kPositiveSeconds)
        ->capture_default_str();
    wall_cmd
        ->add_option("--threads", wall.threads,
                     "Threads each rank may use (octree build, extraction); on a cluster, the "
                     "cores of a display node")
        ->check(CLI::Range(1, 1024))
        ->capture_default_str();
    wall_cmd->add_option("--trace", wall.trace,
                         "Write per-rank spans by stage with thread CPU time: PREFIX.json (Chrome "
                         "trace, opens in Perfetto) and PREFIX.csv; migrated jobs show as flows");
    wall_cmd->add_option("--orbit", wall.orbit, "Start turned: YAW PITCH in degrees")
        ->expected(2)
        ->check(kFiniteNumber);
    wall_cmd->add_option("--zoom", wall.zoom, "Start zoomed (>1 moves closer)")
        ->check(kFiniteNumber & CLI::PositiveNumber)
        ->capture_default_str();
    wall_cmd
        ->add_option("--pan", wall.pan,
                     "Start panned: DX DY in screen widths and heights (the view moves right, up)")
        ->expected(2)
        ->check(kFiniteNumber);
    wall_cmd
        ->add_option("--balance", wall.balance,
                     "Screen-region scheduler: on, idle ranks take regions of busy tiles; off, "
                     "every tile casts its own screen (the static wall)")
        ->transform(
            CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}))
        ->default_str("on");
    wall_cmd
        ->add_option("--region", wall.region,
                     "Size WxH of the screen regions the scheduler hands out (balancing on); "
                     "'tile' for one region per tile")
        ->check([](const std::string& s) {
            return parse_region(s) ? std::string() : "expected WxH (e.g. 256x192) or 'tile'";
        })
        ->capture_default_str();
    wall_cmd
        ->add_option("--region-clip", wall.region_clip,
                     "Propagation stays within the screen region of each job (or tile): on, no "
                     "pass extracts surface its region cannot show; off, as in the text")
        ->transform(
            CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}))
        ->default_str("on");
    wall_cmd->add_flag("--measure", wall.measure,
                       "Measure wall-wide correctness against emulated time (each rank on its own "
                       "core, from thread CPU time); costs a read-back per job");
    return wall_cmd;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace isowall;
    CLI::App app{"isowall: isosurfaces of large volumes on tiled display walls"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "isowall 0.1.0");

    InfoOptions info;
    auto* info_cmd =
        app.add_subcommand("info", "Print a volume's size, type, value range and octree");
    add_volume_options(*info_cmd, info.volume);

    ExtractOptions ex;
    auto* ex_cmd =
        app.add_subcommand("extract", "Extract the full isosurface to a binary PLY file");
    add_volume_options(*ex_cmd, ex.volume);
    ex_cmd->add_option("--iso", ex.iso, "Isovalue (default for the phantom: skin, 50)");
    ex_cmd->add_option("--out,-o", ex.out, "Output PLY file")->required();

    RenderOptions re;
    auto* re_cmd = add_render_command(app, re);
    WallOptions wall;
    auto* wall_cmd = add_wall_command(app, wall);
    bool ranks_needed = false;
    wall_cmd->add_flag("--ranks-needed", ranks_needed,
                       "Print the -np this wall file needs (1 + its tiles) and exit, without MPI");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line, then a pointer to --help (CLI11's own output spans several lines).
        std::fprintf(stderr, "isowall: error: %s (see isowall --help)\n", e.what());
        return 2;
    }

    try {
        if (info_cmd->parsed()) return run_info(info);
        if (ex_cmd->parsed()) return run_extract(ex);
        if (re_cmd->parsed()) return run_render(re);
        if (wall_cmd->parsed() && ranks_needed) {
            std::printf("%d\n", rank_count(load_wall(wall.wall)));
            return 0;
        }
        if (wall_cmd->parsed()) {
            std::tie(wall.fault_kind, wall.fault_rank) =
                parse_test_fault(std::getenv("ISOWALL_TEST_FAULT"));
            const char* env_rank = std::getenv("OMPI_COMM_WORLD_RANK");
            if (env_rank && std::atoi(env_rank) == wall.fault_rank)
                raise_test_signal(wall.fault_kind, "init");
            auto comm = make_mpi_comm(argc, argv, {wall.startup_timeout_s, wall.timeout_s});
            return run_wall(wall, *comm);
        }
    } catch (const std::exception& e) {
        std::fflush(stdout);
        std::fprintf(stderr, "isowall: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
