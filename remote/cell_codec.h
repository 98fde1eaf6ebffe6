#pragma once
// The body of the `cells` group encoding (remote/group_codec.h; the dissertation's
// open problem 5.2.3): a group sent as what marching cubes needs, not what it made. The client
// runs the project's own marching cubes (extract/marching_cubes.h) on what it receives and
// gets the server's triangles: the same positions and the same normals, the interpolated
// central-difference gradients, to the bit, with nothing quantised at full resolution. A coarse
// pass (level >= 1: drawn only until the full resolution replaces it) is sent cheaper: no normals
// (its vertices lie 2^level apart and their gradients share few voxels, so the client takes each
// vertex's normal from the faces around it, the area-weighted mean; they differ from the
// gradients' by 28 degrees on average on the head), and its values to a step (cell_values.h:
// bins aligned on the isovalue keep every unit's case; only where the surface cuts an edge moves,
// by 0.03 of an edge on average). On the 256-wide head at 1 Mbit/s, C = 90% came in 0.112 s
// (with exact values through zstd: 0.283; with 8-bit normals sent too: 0.342).
//
// What travels: the group's units (the cells, or meta-cells of a level, whose triangles the mesh
// is) and the values of the voxels marching cubes reads to triangulate them, in three phases, each
// one's voxels named by what the previous phases gave, so no voxel position is sent:
//   1. the eight corners of every unit (they give its case and its crossed edges);
//   2. the inner voxels of every crossed edge of a meta-cell (level >= 1): a long edge's vertex is
//      the crossing between fine voxels nearest the linear estimate (edge_crossing);
//   3. the six neighbours of the two voxels that bracket each crossing: the gradients there give
//      the vertex's normal (not for a coarse pass).
// Each phase's voxels go in increasing linear index (z, then y, then x), without those of an
// earlier phase. Integer values go as the difference to a prediction from their known neighbours
// (at 1 voxel, axis by axis; else the mean of those at 2, else 4 voxels), coded in context through
// a binary range coder (cell_values.h, range_coder.h); floating-point values as they are, in byte
// planes.
//
// A full-resolution group may go in two messages on a slow link: first with its gradients'
// voxels to a step (only the shading moves: C = 99.6-99.8% of the exact image on the shared 16-bit
// volumes), then their exact offsets (remote/cell_exact.h; the view protocol's ExactMsg), after
// which the client decodes the body again with them and has the server's triangles to the bit.
//
// Byte layout: voxel type u8, volume dims 3 x i32, spacing 3 x f32, normals u8 (0 from the
// gradients, 1 from the faces), bucket count u8; per bucket (a level's units) level u8, unit count
// u32, and its box in that level's grid of units as origin and size, 3 + 3 LEB128 (cell_units.h);
// the value step's shift u8 (with face normals it steps every phase, with gradient normals only
// phase 3); the range coder's stream, its length u32 first (the boxes'
// occupancy, a bit a place, then the integer values); floating-point values' planes.
// group_codec.cpp sends it as it is, or through zstd where that is smaller.
//
// A group whose mesh is not the marching cubes of its units (a mesh from elsewhere, units past the
// volume) or whose units spread over more than kMaxCellBoxVoxels has no cells body: the encoder
// returns nullopt and the caller sends another encoding. The decoder checks every count against
// the bytes left and the limits before it allocates, every unit against the volume, and fails with
// WireError naming the field.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/mesh.h"
#include "extract/group.h"
#include "remote/byte_io.h"
#include "volume/volume.h"

namespace isowall::remote {

// The box a decoder holds voxels in: the units' extent and one voxel around it, of which it keeps
// only the 4x4x4 bricks that hold voxels it receives (and a directory of 4 bytes a brick). A
// propagation pass of the engine spans a few thousand units, far under this.
inline constexpr std::uint64_t kMaxCellBoxVoxels = std::uint64_t{1} << 24;
// The largest volume side a cells body may name.
inline constexpr int kMaxCellVolumeSide = 1 << 20;

// The cells body of `group`, extracted from `volume` at group.iso; nullopt when the group cannot
// be sent this way (see above). With `exact`, a full-resolution group of integer voxels may send
// its gradients' voxels to a step (the values that make only its normals: every vertex stays
// where it is, the shading moves a little) and their exact offsets go to *exact (cell_exact.h),
// for a later message; *exact is left empty when the body is exact as it is.
std::optional<std::vector<std::uint8_t>> encode_cell_body(
    const Group& group, const Volume& volume, std::vector<std::uint8_t>* exact = nullptr);

// What decoding a body may take and tell beside its mesh.
struct CellExact {
    // The exact offsets encode_cell_body gave for this body: the mesh is then the exact one.
    // WireError when they do not fit the body's stepped values, or the body has none.
    const std::span<const std::uint8_t>* exact = nullptr;
    bool* stepped = nullptr;  // set: whether the body went to a step that exact offsets undo
    std::size_t* exact_bytes = nullptr;  // set: how many bytes of them it takes (0: exact)
};
// The mesh a cells body gives at `iso`; throws WireError on anything malformed or truncated.
Mesh decode_cell_body(ByteReader& r, double iso, const CellExact& x = {});

}  // namespace isowall::remote
