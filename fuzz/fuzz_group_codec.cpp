// Harness: the group decoder (remote/group_codec.h). The bytes are one encoded group, in any of
// the five encodings (the second byte picks it). A group that decodes must be drawable: every
// index below the vertex count, every float finite, at most kMaxGroupTriangles triangles. It is
// then encoded again in its own encoding and decoded again:
//   vertices, indexed          the bytes come back exactly, and so does the decoded group;
//   compact, compact_zstd      (vertices and triangles reordered, triangles rotated, unused
//                              vertices dropped) as many triangles, the same header, unit
//                              normals, and on each axis the sorted corner coordinates and the
//                              sorted triangle centroids within one quantisation step of the
//                              re-encoded box (its extent / 65535) plus float rounding.
// fuzz.sh runs this with -malloc_limit_mb=64: no decoder sizes anything from a claimed count.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "fuzz/fuzz_check.h"
#include "fuzz/fuzz_mesh.h"
#include "remote/group_codec.h"

namespace {

using isowall::fuzz::check;
using namespace isowall;
using namespace isowall::remote;

void check_drawable(const Group& g) {
    check(std::isfinite(g.iso), "iso is finite");
    isowall::fuzz::check_drawable_mesh(g.mesh);
}

bool same_header(const Group& a, const Group& b) {
    return a.id == b.id && a.key() == b.key();
}

bool same_mesh(const Mesh& a, const Mesh& b) {
    return a.positions == b.positions && a.normals == b.normals && a.indices == b.indices;
}

// The per-axis bound on how far a compact round trip may move a position: one quantisation step
// of the box the encoder takes (the used vertices' bounds), plus a few float roundings of the
// box's coordinates and extent (and of the smallest denormal, for a denormal box).
double quantisation_bound(const Mesh& m, int axis) {
    if (m.indices.empty()) return 0;
    double lo = m.positions[m.indices[0]][axis], hi = lo;
    for (std::uint32_t i : m.indices) {
        lo = std::min<double>(lo, m.positions[i][axis]);
        hi = std::max<double>(hi, m.positions[i][axis]);
    }
    const double extent = hi - lo, magnitude = std::max(std::abs(lo), std::abs(hi));
    return extent / 65535 + std::ldexp(extent + magnitude, -20) +
           4 * double{std::numeric_limits<float>::denorm_min()};
}

// Each axis's corner coordinates and triangle centroids (as sums of three), sorted: a
// reordering and rotation of the triangles leaves them alike, and moving each corner by at most
// `bound` moves each sorted entry by at most `bound` (three times that for the sums).
void check_sorted_close(const Mesh& a, const Mesh& b, int axis, double bound) {
    const std::size_t n = a.indices.size();
    std::vector<double> ca(n), cb(n), sa(n / 3), sb(n / 3);
    for (std::size_t i = 0; i < n; ++i) {
        ca[i] = a.positions[a.indices[i]][axis];
        cb[i] = b.positions[b.indices[i]][axis];
        sa[i / 3] += ca[i];
        sb[i / 3] += cb[i];
    }
    for (auto* v : {&ca, &cb, &sa, &sb}) std::sort(v->begin(), v->end());
    for (std::size_t i = 0; i < n; ++i)
        check(std::abs(ca[i] - cb[i]) <= bound, "compact round trip: corners within a step");
    for (std::size_t i = 0; i < n / 3; ++i)
        check(std::abs(sa[i] - sb[i]) <= 3 * bound,
              "compact round trip: triangle centroids within a step");
}

// What the encoder made must decode: a WireError here is a finding, not the decoder saying no.
Group decode_again(const std::vector<std::uint8_t>& bytes) {
    try {
        return decode_group(bytes);
    } catch (const isowall::WireError&) {
        check(false, "a re-encoded group decodes");
        throw;
    }
}

void check_compact_round_trip(const Group& g, GroupEncoding encoding) {
    const Group again = decode_again(encode_group(g, encoding));
    check_drawable(again);
    check(same_header(g, again), "compact round trip: the same header");
    check(again.mesh.triangle_count() == g.mesh.triangle_count(),
          "compact round trip: the same triangle count");
    for (const glm::vec3& n : again.mesh.normals)
        check(std::abs(std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z) - 1) <= 1e-5f,
              "compact normals are unit");
    for (int axis = 0; axis < 3; ++axis)
        check_sorted_close(g.mesh, again.mesh, axis, quantisation_bound(g.mesh, axis));
}

void check_group(std::span<const std::uint8_t> bytes) {
    const Group g = decode_group(bytes);
    check_drawable(g);
    const GroupEncoding encoding = encoding_of(bytes);
    // cells: its round trips need the volume (tests/remote_cell_codec_test.cpp); here the decoded
    // mesh must be drawable, and the body's own harness (cell_body) explores it past zstd.
    if (encoding == GroupEncoding::cells) return;
    if (encoding == GroupEncoding::compact || encoding == GroupEncoding::compact_zstd) {
        check_compact_round_trip(g, encoding);
        return;
    }
    const std::vector<std::uint8_t> again = encode_group(g, encoding);
    check(std::equal(again.begin(), again.end(), bytes.begin(), bytes.end()),
          "encode(decode(bytes)) == bytes");
    const Group g2 = decode_again(again);
    check(same_header(g, g2) && same_mesh(g.mesh, g2.mesh), "decode(encode(group)) == group");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        check_group(std::span(data, size));
    } catch (const isowall::WireError&) {
    }
    return 0;
}
