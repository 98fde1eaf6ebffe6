// Harness: the cells body decoder (remote/cell_codec.h), past the zstd frame that wraps it on the
// wire. The bytes are an isovalue (f64) and a body. A body that decodes must give a drawable mesh:
// one normal a position, every index below the vertex count, at most kMaxGroupTriangles
// triangles, every position and normal finite (NaN voxels place no vertex, marching_cubes.h).
// fuzz.sh runs this with -malloc_limit_mb=64: the decoder holds only the bricks of voxels whose
// values the bytes carry, and a brick directory of at most 1 MiB.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "fuzz/fuzz_check.h"
#include "remote/cell_codec.h"
#include "remote/group_codec.h"

namespace {

using isowall::fuzz::check;
using namespace isowall;
using namespace isowall::remote;

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void check_body(std::span<const std::uint8_t> bytes) {
    double iso = 0;
    if (bytes.size() < sizeof iso) return;
    std::memcpy(&iso, bytes.data(), sizeof iso);
    if (!std::isfinite(iso)) return;  // the group header refuses it before the body
    ByteReader r(bytes.subspan(sizeof iso), "cells");
    const Mesh m = decode_cell_body(r, iso);
    r.finish();
    check(m.normals.size() == m.positions.size(), "one normal a position");
    check(m.indices.size() % 3 == 0, "three indices a triangle");
    check(m.triangle_count() <= kMaxGroupTriangles, "at most kMaxGroupTriangles triangles");
    for (std::uint32_t i : m.indices) check(i < m.vertex_count(), "every index < vertex count");
    for (const glm::vec3& p : m.positions) check(finite(p), "every position is finite");
    for (const glm::vec3& n : m.normals) check(finite(n), "every normal is finite");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        check_body(std::span(data, size));
    } catch (const isowall::WireError&) {
    }
    return 0;
}
