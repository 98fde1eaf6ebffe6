// Harness: the cells body decoder (remote/cell_codec.h), past the zstd frame that wraps it on the
// wire. The bytes are an isovalue (f64) and a body. A body that decodes must give a drawable mesh:
// one normal a position, every index below the vertex count, at most kMaxGroupTriangles
// triangles, every position and normal finite (NaN voxels place no vertex, marching_cubes.h).
// A body whose gradients' voxels went to a step (a shift byte is enough to make one) is decoded
// again with exact values (cell_exact.h): as many bytes as it takes, from the input's own bytes
// (any offset in a bin is a value), and one byte short and one over (WireError).
// fuzz.sh runs this with -malloc_limit_mb=64: the decoder holds only the bricks of voxels whose
// values the bytes carry, and a brick directory of at most 1 MiB.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

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
    const auto body = bytes.subspan(sizeof iso);
    ByteReader r(body, "cells");
    bool stepped = false;
    std::size_t need = 0;
    const Mesh m = decode_cell_body(r, iso, {nullptr, &stepped, &need});
    r.finish();
    isowall::fuzz::check_drawable_mesh(m);
    if (!stepped) return;
    for (const std::size_t n : {need, need + 1, need == 0 ? 0 : need - 1}) {
        std::vector<std::uint8_t> exact(n);
        for (std::size_t i = 0; i < n; ++i) exact[i] = body[i % body.size()];
        const std::span<const std::uint8_t> bits(exact);
        try {
            ByteReader again(body, "cells");
            isowall::fuzz::check_drawable_mesh(decode_cell_body(again, iso, {&bits, nullptr}));
            again.finish();
        } catch (const isowall::WireError&) {  // stray unused bits, a value past the type
        }
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        check_body(std::span(data, size));
    } catch (const isowall::WireError&) {
    }
    return 0;
}
