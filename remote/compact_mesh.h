#pragma once
// The body of the `compact` group encoding (remote/group_codec.h): quantised positions,
// octahedral normals and meshoptimizer's index codec. Byte layout:
//   vertex count V u32, triangle count T u32, box min 3 x f32, box max 3 x f32,
//   positions V x 3 x u16 (0..65535 across the box on each axis),
//   normals V x 2 x i16 (octahedral, snorm16),
//   index bytes u32, then meshopt_encodeIndexBuffer's bytes for the 3T indices.
#include <array>
#include <cstdint>

#include <glm/vec3.hpp>

#include "core/mesh.h"
#include "remote/byte_io.h"

namespace isowall::remote {

// A unit normal as two snorm16 coordinates on the octahedron |x| + |y| + |z| = 1 unfolded onto
// a square: 4 bytes for a direction the float triple stores in 12, with an error under 0.01
// degree everywhere (8-bit codes would err by about 0.5 degree, enough to shift a shaded pixel).
std::array<std::int16_t, 2> oct_encode(glm::vec3 n);
// Always finite and unit, for any code.
glm::vec3 oct_decode(std::array<std::int16_t, 2> code);

// grid_step > 0: positions on one grid of that step (see encode_group), else in the mesh's own box.
void put_compact_mesh(ByteWriter& w, const Mesh& mesh, float grid_step = 0);
Mesh get_compact_mesh(ByteReader& r);

}  // namespace isowall::remote
