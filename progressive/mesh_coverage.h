#pragma once
// The pixels a mesh covers, found on the CPU from its triangles: what a renderer would draw, with
// no read-back. The dynamic grid sizes its grid from the first piece of surface a region finds
// (section 3.1.2); reading that from the renderer waits for everything drawn before it (the
// frame's clear included) and costs a read of the region, 2.6 ms at 1600x1200 on the 512 head,
// on the one thread every other one then waits for.
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/camera.h"
#include "core/mesh.h"

namespace isowall {

// Sets covered[y * rect.width + x] to 1 where a triangle of `mesh` (object space), seen through
// `view` (object -> view space) and `frustum` on a width x height screen, covers the centre of
// pixel (rect.x + x, rect.y + y) (y from the top); other entries are left as they are, so
// several meshes can be added. `covered` must hold rect.width * rect.height entries. Both faces
// count (the renderer draws back faces too); a pixel centre on an edge counts, so two triangles
// sharing an edge leave no gap. A triangle with a corner behind the near plane or past the far
// plane, which the renderer would clip, is left out.
void add_mesh_coverage(const Mesh& mesh, const glm::mat4& view, const Frustum& frustum, int width,
                       int height, const PixelRect& rect, std::vector<std::uint8_t>& covered);

}  // namespace isowall
