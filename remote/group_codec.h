#pragma once
// How a group travels from the extraction server to the client (the dissertation's
// section 4.2 and its open problem 5.2.3). Four encodings, from the base case to ours:
//   vertices      every triangle as three separate vertices, float32 position + normal each,
//                 no index (section 4.2's case 1): 72 bytes a triangle
//   indexed       the indexed face set the extractor makes: float32 positions and normals,
//                 uint16 indices (uint32 for a group of more than 65536 vertices) (case 2)
//   compact       positions quantised to 16 bits per axis inside the group's bounding box (sent
//                 as floats), normals as octahedral 2 x 16 bits, indices through meshoptimizer's
//                 index codec after its vertex cache and vertex fetch orders
//   compact_zstd  the compact bytes through zstd (level kZstdLevel)
//   cells         what marching cubes needs, not what it made: the group's units and the voxel
//                 values that triangulate them (remote/cell_codec.h); the client runs marching
//                 cubes and gets the server's triangles and normals. Needs the volume.
//
// Bytes: [version u8][encoding u8][group header][body]; compact_zstd's body is the u64 size of
// the compact message, then one zstd frame holding that whole message (its own version and
// encoding bytes included). A cells body follows its header after a packing byte: 0, the body as
// it is, to the end (range-coded, zstd made it about 15 bytes a group larger, frame and
// size included); 1, the u64 size of the body and one zstd frame holding it, where that is smaller
// (a body of floating-point voxels, sent as byte planes). The group header is id u32, seed 3 x i32,
// level i32, iso f64, refinement u8. Group::cells is not sent: it is the server's bookkeeping of
// which cells a pass took, and the client draws only the mesh.
//
// What decoding gives back: `vertices` gives an unindexed mesh (indices 0, 1, 2, ...); `indexed`
// gives the mesh as it was; `compact` and `compact_zstd` give the same triangles with the same
// winding, but vertices reordered, triangles reordered and rotated (first corner changes), and
// vertices no triangle uses dropped. Positions are within the box's extent / 65535 per axis of
// the original (half of that, plus float rounding), normals within kOctNormalMaxErrorDeg.
//
// Decoding is for hostile input: every count is checked against the limits below and against
// the bytes left before anything is allocated, indices against the vertex count, and every float
// must be finite; anything else throws WireError naming the field.
#include <cstdint>
#include <ostream>
#include <span>
#include <vector>

#include "extract/group.h"
#include "remote/cell_codec.h"
#include "volume/volume.h"
#include "wire/wire.h"

namespace isowall::remote {

enum class GroupEncoding : std::uint8_t {
    vertices = 0,
    indexed = 1,
    compact = 2,
    compact_zstd = 3,
    cells = 4
};
inline constexpr GroupEncoding kAllGroupEncodings[] = {
    GroupEncoding::vertices, GroupEncoding::indexed, GroupEncoding::compact,
    GroupEncoding::compact_zstd, GroupEncoding::cells};
const char* to_string(GroupEncoding e);
inline std::ostream& operator<<(std::ostream& os, GroupEncoding e) {
    return os << to_string(e);
}

// 2: `indexed` sends uint16 indices for groups of at most kMaxNarrowIndexedVertices vertices.
// 3: a cells body's range coder lets a young probability learn fast (remote/range_coder.h), its
// values are predicted axis by axis (cell_predict.h): the same bytes mean other values, so a
// client of version 2 must refuse them; and the body goes through zstd only where that is
// smaller (the packing byte).
inline constexpr std::uint8_t kGroupCodecVersion = 3;
inline constexpr std::size_t kMaxNarrowIndexedVertices = 65536;
// One propagation pass makes a few thousand triangles (max_count 1000 cells); the whole skin of
// the shared CT head at iso 40 is 0.72 M. 4 M triangles (288 MiB as `vertices`) bounds what one
// group may claim, and so what a decoder may allocate for one.
inline constexpr std::uint32_t kMaxGroupTriangles = 1u << 22;
inline constexpr std::uint32_t kMaxGroupVertices = 3 * kMaxGroupTriangles;
// zstd level: 1-3 are the fast ones; the compact bytes are already dense, so higher levels
// gain little and cost the server's time per group.
inline constexpr int kZstdLevel = 3;
// A zstd frame may claim at most this many times its own size once decompressed. Compact bytes
// shrink by well under 2x; the cap keeps a few hostile bytes from claiming a huge buffer.
inline constexpr std::uint64_t kMaxZstdExpansion = 64;
// The largest angle between a unit normal and its 2 x 16-bit octahedral code, decoded (measured
// over every code direction in tests/remote_codec_test.cpp, with margin).
inline constexpr double kOctNormalMaxErrorDeg = 0.01;

// `volume` (cells): the volume the group was extracted from. A group `cells` cannot carry (see
// remote/cell_codec.h), or any group when `volume` is null, goes as compact_zstd instead, and so
// does a coarse pass (level >= 1) whose compact_zstd bytes are fewer: the encoding byte of the
// result says which.
// grid_step (compact encodings): 0 quantises each group in its own box, so a vertex two groups
// share may decode to two points a quantum apart, and a pixel may see through the crack between
// them. A step > 0 (a power of two, at least the whole volume's extent / 65534, see
// position_grid_step) puts every group's positions on one grid: a shared vertex decodes alike in
// every group, and no crack opens. A group too large for 65535 steps falls back to its own box.
// exact (cells): see encode_cell_body; empty unless the group went in two messages.
std::vector<std::uint8_t> encode_group(const Group& group, GroupEncoding encoding,
                                       float grid_step = 0, const Volume* volume = nullptr,
                                       std::vector<std::uint8_t>* exact = nullptr);
// The smallest power of two at least `extent` / 65534: the grid step for a volume of that largest
// extent (object units).
float position_grid_step(float extent);
// Throws WireError on anything malformed, truncated, of another version, or with trailing bytes.
// `x`: a cells group's exact offsets, and whether it was stepped (remote/cell_codec.h).
Group decode_group(std::span<const std::uint8_t> bytes, const CellExact& x = {});
// The encoding named by encoded bytes (their second byte), checked.
GroupEncoding encoding_of(std::span<const std::uint8_t> bytes);

}  // namespace isowall::remote
