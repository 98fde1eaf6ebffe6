#pragma once
// A tile rank of a wall run: frames of its own frustum until the master says quit. Two threads:
// the communication thread receives from the master into a TileInbox (raising the stop flag when
// a new view or quit arrives); the frame thread (the caller's) runs the engine, sends progress at
// every progress point, answers snapshot requests from the frame being built, and at quit sends
// its figures, trace and final image.
#include <string>

#include "comm/comm.h"
#include "common/extract/surface_extractor.h"
#include "tile/progressive_engine.h"
#include "tile/renderer.h"

namespace isowall {

// Test hooks for fault handling (ISOWALL_TEST_FAULT=KIND:RANK): after its first view a tile
// "hang"s (stops answering until the job ends), "exit"s at once (process only; never in process),
// or "throw"s an error.
struct TileFault {
    std::string kind;  // empty: none
};

struct TileSetup {
    SurfaceExtractor& extractor;
    Renderer& renderer;
    EngineOptions engine;
    TileFault fault;
};

// Returns 0 after quit; throws on any failure (the caller's single failure path reports it).
int run_tile(Comm& comm, TileSetup& setup);

}  // namespace isowall
