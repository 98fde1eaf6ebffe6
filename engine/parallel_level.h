#pragma once
// One ray-order level cast over several threads (EngineOptions::threads): each thread takes the
// next pixel, casts its ray on its own extractor worker and propagates from an unvisited hit (the
// units' claims keep passes apart, extract/visited.h); the calling thread is worker 0 and,
// between its own rays, hands the groups found so far to `draw` in the order of their ids, so the
// drawing (the renderer's context is the caller's) never leaves it.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>

#include "core/view.h"
#include "extract/hit_neighbours.h"
#include "extract/surface_extractor.h"

namespace isowall {

struct LevelJob {
    SurfaceExtractor& ex;
    const std::vector<glm::ivec2>& pixels;  // region-local
    glm::ivec2 origin;                      // the region's corner on the screen
    const FrameView& view;
    glm::mat4 view_inverse;
    IntersectMode mode;
    const PropagationParams& params;         // propagation (with the region's clip)
    const PropagationParams& refine_params;  // refinement
    const std::function<bool()>& stopped;    // polled between rays and inside passes
    std::uint32_t first_id;                  // the first group id to hand out
    // Not null: the level is these seeds instead of `pixels` (frontier seeds, beside_seeds.h):
    // each still unvisited is propagated from, with no ray cast.
    const std::vector<BesideSeed>* seeds = nullptr;
    // The groups of the visited cells the rays meet are wanted (LevelTally::seen).
    bool want_seen = false;
    std::size_t size() const { return seeds ? seeds->size() : pixels.size(); }
};

// A group found by a worker, with the seconds of its pass and of marching cubes in it. A pass
// whose seed another worker took first has no cell, and a refinement done already has no
// triangle: neither is a group to draw.
struct FoundGroup {
    Group group;
    double pass_s = 0, extract_s = 0;
};

struct LevelTally {
    std::size_t rays = 0, hits = 0;
    double intersect_s = 0;  // summed over the threads
    // CPU seconds (CLOCK_THREAD_CPUTIME_ID) of the threads other than the caller, each from its
    // start to its end, summed; and the largest one (the caller's own CPU is its thread clock).
    double workers_cpu_s = 0, busiest_worker_cpu_s = 0;
    std::uint32_t next_id = 0;  // the first id not handed out
    // Unvisited cells beside hits on visited ones, for the region's end (hit_neighbours.h).
    std::vector<BesideSeed> beside;
    // With LevelJob::want_seen: the group of each visited cell a ray met (repeats included).
    std::vector<std::uint32_t> seen;
};

// Casts every pixel of `job` on `threads` threads (at most the extractor's workers). `draw` and
// `between_rays` (given the rays cast so far, all threads) run on the calling thread only:
// between_rays once as soon as the other threads have started (the caller may then present what
// the level before drew, while they cast) and after each of the caller's own rays. An exception
// on any thread stops the others and is rethrown here once all have ended.
LevelTally cast_level_parallel(const LevelJob& job, int threads,
                               const std::function<void(FoundGroup&)>& draw,
                               const std::function<void(std::size_t)>& between_rays);

}  // namespace isowall
