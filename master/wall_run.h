#pragma once
// `isowall wall`: the display-wall run under mpirun. Rank 0 (the master) reads the wall file,
// computes each tile's off-axis frustum from one wall camera, sends every tile rank its view,
// gathers the tile images into a mosaic of the virtual screen (bezel gaps as dark bars, overlaps
// blended) and prints the per-rank table. Ranks 1..T each run the progressive engine on their
// own frustum.
#include <string>

#include "comm/comm.h"
#include "master/engine_cli.h"
#include "master/volume_options.h"

namespace isowall {

struct WallOptions {
    VolumeOptions volume;
    std::string wall;
    std::optional<double> iso;
    std::string out = "mosaic.png";
    std::string tiles_out;  // folder for per-tile images (optional)
    std::string gl = "osmesa";
    EngineCli engine;
    std::string script;       // script file, "-" for the master's console, empty: one frame
    double timeout_s = 120;   // a tile silent this long ends the job
    std::string trace;        // prefix: PREFIX.json (Chrome trace) and PREFIX.csv
};

int run_wall(const WallOptions& o, Comm& comm);

}  // namespace isowall
