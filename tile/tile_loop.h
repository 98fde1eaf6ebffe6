#pragma once
// A tile rank of a wall run: frames of its own frustum until the master says quit. Two threads:
// the communication thread receives from the master and from helpers into a TileInbox (raising
// the stop flag when a new view or quit arrives); the frame thread (the caller's) runs the jobs
// the master hands it (tile/tile_jobs.h), for its own tile or another's, sends progress at every
// progress point, lands helpers' results, answers snapshot requests from the frame being built,
// and at quit sends its figures, trace and final image, then stays until the master releases it
// (a helper's result may still be on its way to it).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "comm/host_slots.h"
#include "core/test_fault.h"
#include "engine/progressive_engine.h"
#include "extract/surface_extractor.h"
#include "render/renderer.h"
#include "tile/frame_show.h"

namespace isowall {

class StoreClient;  // tile/store_client.h

struct TileSetup {
    SurfaceExtractor& extractor;
    Renderer& renderer;       // the tile's own frame
    Renderer& help_renderer;  // the regions it fills for other tiles
    EngineOptions engine;
    TestFault fault;         // the fault tests' hook (core/test_fault.h); none by default
    bool measure = false;    // keep each job's result for the emulated correctness curve
    double timeout_s = 120;  // the master silent this long (not even alive messages) ends the job
    int tile_width = 0, tile_height = 0;  // when known: the frame is sized at start-up
    // Where the frame is shown as it builds (a window, a preview for the control window); each
    // is paced on its own (tile/frame_show.h).
    std::vector<FrameShow*> shows = {};
    // CPU seconds so far of the threads that read the volume for this rank (a store's pager),
    // charged to the trace's io stage; empty for a volume in memory.
    std::function<double()> io_cpu_s = {};
    // The store's chunks when this rank's host cannot see it: the master's answers go here.
    StoreClient* store_client = nullptr;
    // The host's compute slots (--emulate-cores): a job runs while holding one; none: no limit.
    HostSlots* slots = nullptr;
    // Renderers for a picture's other surfaces (tile/layered_jobs.h), two a surface; empty: the
    // rank draws one surface.
    std::function<std::unique_ptr<Renderer>()> make_renderer = {};
    // The extractor of a time step of a series (volume/time_steps.h), opened on first use and
    // kept while it is in use; `extractor` is step 0's. Empty: the volume has one step.
    std::function<SurfaceExtractor&(std::uint32_t step)> step_extractor = {};
};

// How much longer than a limit a tile rank waits before it names a silent master: ranks after the
// first wait a little longer each, so that one names it before mpirun ends the others.
inline double tile_grace_s(int rank) {
    return 0.5 * (rank <= 1 ? 0 : rank - 1 < 8 ? rank - 1 : 8);
}

// Returns 0 after quit; throws on any failure (the caller's single failure path reports it).
int run_tile(Comm& comm, TileSetup& setup);

}  // namespace isowall
