#pragma once
// The ray side of the FE + Embree peer, the OSPRay way on a CPU: an Embree 3 BVH over
// the whole extracted surface, then one primary ray per pixel in 8-wide packets
// (rtcIntersect8), screen tiles shared by the threads. The view is isowall's own
// (front_full_view, pixel_ray), so its hit pixels can be checked against the pixels
// `isowall render` covers.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bench/peer/peer_mesh.h"
#include "core/camera.h"

namespace isowall::peer {

struct TraceView {
    Camera camera;
    Frustum frustum;
    int width = 0, height = 0;
};

// The view `isowall render` uses by default: the front full view of `bounds`, perspective.
TraceView front_view(const Box3& bounds, int width, int height);

struct TraceResult {
    double bvh_s = 0;   // geometry buffers and rtcCommitScene (the BVH build)
    double rays_s = 0;  // every primary ray
    std::size_t hit_pixels = 0;
    std::vector<std::uint8_t> hits;  // width * height from the top row: 1 where the ray hit
};

// Builds the BVH over `mesh` and casts one ray through every pixel centre; `threads` threads for
// both (Embree's build threads, then ours over the tiles). Throws std::runtime_error naming the
// Embree call that failed.
TraceResult trace(const PeerMesh& mesh, const TraceView& view, int threads);

}  // namespace isowall::peer
