#pragma once
// The subcommands of the isowall program. Each returns the process exit code.
#include <string>
#include <vector>

#include "cli/clip_option.h"
#include "cli/colour_option.h"
#include "cli/engine_cli.h"
#include "cli/volume_options.h"

namespace isowall {

struct InfoOptions {
    VolumeOptions volume;
};

struct ExtractOptions {
    VolumeOptions volume;
    std::optional<double> iso;
    ClipOptions clip;
    std::string out;
    std::string compress = "none";  // a .glb's: none or meshopt
};

struct RenderOptions {
    VolumeOptions volume;
    std::vector<std::string> iso;  // one isovalue, or surfaces VALUE[:COLOUR[:OPACITY]]
    ClipOptions clip;
    ColourOptions colour;
    std::string size = "1600x1200";
    std::string out = "isowall.png";
    std::string depth_out;
    std::string gl = "osmesa";
    std::string projection = "perspective";
    std::vector<double> orbit;  // yaw pitch in degrees
    double zoom = 1.0;

    // Progressive engine (the default) or the full surface.
    bool full = false;
    EngineCli engine;
    std::string timeline;                    // CSV path
    std::vector<double> snapshots;           // correctness thresholds in percent
    std::string snapshot_measure = "final";  // "final" (share of final pixels) or "c" (1 - E)
    std::vector<std::size_t> snapshot_rays;
    bool no_measure = false;
    bool against_full = false;   // also measure the final image against the full surface's
    bool against_truth = false;  // and against the truth, with the fidelity gate (--against-truth)
    bool warm_up = false;        // one untimed frame first (a running wall's steady state)
    int threads = 0;             // the engine's threads (and the octree build's); 0: every core
    bool quiet = false;
};

int run_info(const InfoOptions& o);
int run_extract(const ExtractOptions& o);
int run_render(const RenderOptions& o);

}  // namespace isowall
