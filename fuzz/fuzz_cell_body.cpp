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
#include "fuzz/fuzz_mesh.h"
#include "remote/cell_codec.h"
#include "remote/group_codec.h"

namespace {

using namespace isowall;
using namespace isowall::remote;

void check_body(std::span<const std::uint8_t> bytes) {
    double iso = 0;
    if (bytes.size() < sizeof iso) return;
    std::memcpy(&iso, bytes.data(), sizeof iso);
    if (!std::isfinite(iso)) return;  // the group header refuses it before the body
    ByteReader r(bytes.subspan(sizeof iso), "cells");
    const Mesh m = decode_cell_body(r, iso);
    r.finish();
    isowall::fuzz::check_drawable_mesh(m);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        check_body(std::span(data, size));
    } catch (const isowall::WireError&) {
    }
    return 0;
}
