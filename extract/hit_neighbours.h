#pragma once
// The cells beside a ray's hit that may hold the triangles its pixel needs.
//
// An exact seed ray hits the first marching-cubes triangle on its way (Moller-Trumbore). When the
// pixel's centre lies on the edge that cell A's triangle shares with cell B's (up to rounding),
// the ray may meet A's triangle while the rasteriser gives the pixel to B's. If A was extracted
// and B was not (propagation stopped at A), the ray finds A visited and seeds nothing, and the
// pixel stays empty in the final picture: a pinhole. The shared edge lies on the face between A
// and B, so the engine seeds the unvisited cells across the faces, edges and corner of A that lie
// within a margin of the hit point. It does so once the region's every ray is cast, and only for
// the hits whose pixel shows nothing then and the cells no ray has seeded by then: most hits near
// a group's frontier are on pixels its triangles do cover, or beside cells that their own pixels'
// rays seed later, and seeding those too would split the picture into many more groups (on a
// screen coarser than the volume's cells, most of them too small to show).
#include <array>
#include <cstddef>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/ray.h"
#include "extract/raycaster.h"

namespace isowall {

// A cell to seed at the region's end if it is still unvisited and `pixel` (the screen's) still
// shows nothing then, with the ray through that pixel.
struct BesideSeed {
    glm::ivec3 cell;
    Ray ray;
    glm::ivec2 pixel;
};

struct HitNeighbours {
    std::array<glm::ivec3, 7> cells{};
    int count = 0;
};

// The cells next to `cell` (whose corner is at `cell` in voxel space) that share a face, an edge
// or the corner with it within `margin` cells of `p` (the hit, voxel space), inside the volume's
// cells [0, cell_dims). At most 7: across the 3 nearest faces, their 3 edges and their corner.
inline HitNeighbours hit_neighbours(glm::ivec3 cell, glm::vec3 p, glm::ivec3 cell_dims,
                                    float margin) {
    glm::ivec3 step{0};
    for (int a = 0; a < 3; ++a) {
        const float f = p[a] - float(cell[a]);
        if (f < margin && cell[a] > 0) step[a] = -1;
        if (f > 1.0f - margin && cell[a] + 1 < cell_dims[a]) step[a] = 1;
    }
    HitNeighbours out;
    for (int m = 1; m < 8; ++m) {
        const glm::ivec3 d{(m & 1) ? step.x : 0, (m & 2) ? step.y : 0, (m & 4) ? step.z : 0};
        if (((m & 1) && step.x == 0) || ((m & 2) && step.y == 0) || ((m & 4) && step.z == 0))
            continue;
        out.cells[std::size_t(out.count++)] = cell + d;
    }
    return out;
}

// How near a face (in cells) a hit must be for the cell across it to be seeded: the hits above
// lie on the face up to float rounding; a twentieth of a cell is far above that and keeps the
// candidates to the hits near a face.
inline constexpr float kHitNeighbourMargin = 0.05f;

// The cells an exact hit on an already visited cell of full resolution seeds instead: its
// unvisited neighbours near the hit (`ray` in object space, `spacing` the volume's). None for
// any other hit: a meta-cell's own rule is refinement (RayHit::refine), and an approximate hit's
// point is where the ray entered the cell, not the surface.
template <class Visited>
HitNeighbours unvisited_beside_hit(const RayHit& hit, const Ray& ray, bool exact, glm::vec3 spacing,
                                   glm::ivec3 cell_dims, const Visited& visited) {
    HitNeighbours out;
    if (!exact || hit.refine || hit.level != 0) return out;
    const glm::vec3 p = (ray.o + hit.t * ray.d) / spacing;
    const HitNeighbours all = hit_neighbours(hit.cell, p, cell_dims, kHitNeighbourMargin);
    for (int i = 0; i < all.count; ++i)
        if (!visited(all.cells[std::size_t(i)]))
            out.cells[std::size_t(out.count++)] = all.cells[std::size_t(i)];
    return out;
}

}  // namespace isowall
