#pragma once
// `isowall wall`: the display-wall run. Rank 0 (the master, master/wall_master.h) reads the wall
// file, computes each tile's off-axis frustum from one wall camera, sends every tile rank its
// view, gathers the tile images into a mosaic of the virtual screen and prints the per-rank table.
// Ranks 1..T each run a tile (tile/tile_loop.h). The same code runs under MPI and in process.
#include <optional>
#include <string>
#include <vector>

#include "cli/clip_option.h"
#include "cli/colour_option.h"
#include "cli/engine_cli.h"
#include "cli/volume_options.h"
#include "comm/comm.h"
#include "core/test_fault.h"
#include "wall_protocol/protocol.h"

namespace isowall {

struct WallOptions {
    VolumeOptions volume;
    std::string wall;
    std::vector<std::string> iso;  // one isovalue, or surfaces VALUE[:COLOUR[:OPACITY]]
    ClipOptions clip;
    ColourOptions colour;
    std::string out = "mosaic.png";
    std::string tiles_out;  // folder for per-tile images (optional)
    std::string gl = "osmesa";
    EngineCli engine;
    std::string script;  // script file, "-" for the master's console, empty: one frame
    // The control window on the master's display (master/control_window.h): after the script,
    // if any, the operator drives the wall from it until Escape. Every rank parses the same
    // command line, so tiles know from this that the master wants their previews.
    bool control = false;
    std::string control_display;  // empty: $DISPLAY
    // The browser page (app/wall_http.h), served by the master: its port (0: any free port;
    // -1: none), address, token and TLS files. Tiles send previews when either this or the
    // control window is on.
    int http_port = -1;
    std::string http_listen = "127.0.0.1";
    std::string token;
    std::string tls_cert, tls_key;
    std::vector<std::string> allow_hosts;  // --allow-host
    double timeout_s = 120;                // a wall silent this long ends the job
    double startup_timeout_s = 600;        // the same while the tiles load the volume and start
    std::string trace;                     // prefix: PREFIX.json (Chrome trace) and PREFIX.csv
    std::vector<float> orbit, pan;         // the first view: yaw pitch; dx dy (empty: none)
    float zoom = 1;
    bool balance = true;  // the screen-region scheduler migrates jobs
    // "auto": regions planned from the work (master/region_plan.h); WxH a fixed grid, or "tile"
    std::string region = "auto";
    // Which asking rank gets the next job: "arrival" (the first to ask) or "emulated" (the one
    // with the earliest CPU clock: for emulating a cluster on fewer cores than ranks).
    std::string dispatch = "arrival";
    bool measure = false;     // emulated wall-wide correctness curves
    bool windows = false;     // each tile shows its frame in a window on its display
    bool region_clip = true;  // propagation stays within each job's region
    // Where a tile rank reads a store given as --volume: "auto", from its own host when the
    // folder is there, else from the master over the wall's messages; "master", always from the
    // master (to try a cluster's set-up on one machine).
    std::string bricks_from = "auto";
    // Threads each rank may use (the octree build, and the engine's threads casting and
    // propagating side by side): ranks share nodes, so this is the rank's budget, not the
    // machine's core count. 0: the rank's share of its node (rank_budget in wall_run.cpp).
    int threads = 0;
    // At most this many tile ranks of a host run a job at once (comm/host_slots.h): a cluster
    // with a core per rank emulated on a host with this many cores. 0: no limit.
    int emulate_cores = 0;
    // Test hook (ISOWALL_TEST_FAULT=KIND:RANK, core/test_fault.h): the rank named fails in
    // the way named (tile: hang, exit, throw; master: throw; either: stop or kill at a moment).
    TestFault fault;
    // When set, the master also leaves every tile's figures here (by rank; for tests).
    std::vector<TileResultMsg>* results_out = nullptr;
};

// Every rank calls this. Any failure on any rank ends the whole job through one path: one line
// on stderr naming the rank and the cause, then comm.abort() (which under MPI ends every rank,
// and in process wakes every rank with CommAborted). Returns the rank's exit code otherwise.
int run_wall(const WallOptions& o, Comm& comm);

// "WxH" (each side 1..32768) or "tile" (0x0: one region per tile); nullopt when malformed.
std::optional<std::pair<int, int>> parse_region(const std::string& spec);

}  // namespace isowall
