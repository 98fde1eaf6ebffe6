#include "remote/compact_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <meshoptimizer.h>
#include <glm/geometric.hpp>

#include "remote/group_codec.h"

namespace isowall::remote {
namespace {

constexpr float kQuantMax = 65535.0f;
constexpr float kSnormMax = 32767.0f;
constexpr unsigned kFifoCache = 16;  // vertices: below any GPU cache, as meshoptimizer advises

std::int16_t to_snorm16(float v) {
    return static_cast<std::int16_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * kSnormMax));
}
float from_snorm16(std::int16_t v) {
    return std::max(static_cast<float>(v) / kSnormMax, -1.0f);
}
float sign_not_zero(float v) {
    return v >= 0 ? 1.0f : -1.0f;
}

// The extractor's mesh put in the order the index codec codes best: triangles in vertex cache
// order, then vertices in the order those triangles first use them (so most new indices are
// "next vertex", a few bits each). Vertices no triangle uses are dropped. The FIFO cache order
// is meshoptimizer's fast one: on the phantom's frame (isowall_bench_codec) it gives 6.78 bytes
// a triangle at 8.5 M triangles/s, the full optimizer 6.62 at 2.7 M/s, no reordering 8.23.
struct Reordered {
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> old_of_new;  // the mesh's vertex behind each new vertex
};

Reordered reorder(const Mesh& mesh) {
    Reordered out;
    const std::size_t n = mesh.indices.size(), v = mesh.vertex_count();
    out.indices.resize(n);
    meshopt_optimizeVertexCacheFifo(out.indices.data(), mesh.indices.data(), n, v, kFifoCache);
    std::vector<std::uint32_t> remap(v);
    const std::size_t used =
        meshopt_optimizeVertexFetchRemap(remap.data(), out.indices.data(), n, v);
    meshopt_remapIndexBuffer(out.indices.data(), out.indices.data(), n, remap.data());
    out.old_of_new.resize(used);
    for (std::size_t i = 0; i < v; ++i)
        if (remap[i] != ~0u) out.old_of_new[remap[i]] = static_cast<std::uint32_t>(i);
    return out;
}

// The box on the grid of `step`: its min a multiple of step, its max 65535 steps on, so a decoder's
// step, (max - min) / 65535 in double, is `step` exactly and every position decodes to a multiple
// of it. False when the mesh does not fit (or step is 0): the mesh's own box is used then.
bool grid_box(const Box3& tight, float step, Box3& out) {
    if (!(step > 0)) return false;
    for (int a = 0; a < 3; ++a) {
        const double lo = std::floor(double{tight.min[a]} / step) * step;
        const double hi = lo + double{kQuantMax} * step;
        if (!(double{tight.max[a]} <= hi - step) || float(lo) != lo || float(hi) != hi)
            return false;
        out.min[a] = float(lo);
        out.max[a] = float(hi);
    }
    return true;
}

void put_positions(ByteWriter& w, const Mesh& mesh, const std::vector<std::uint32_t>& old_of_new,
                   float grid_step) {
    Box3 box;
    for (std::uint32_t o : old_of_new) box.merge(mesh.positions[o]);
    if (old_of_new.empty()) box = Box3{glm::vec3(0), glm::vec3(0)};
    if (Box3 on_grid; !old_of_new.empty() && grid_box(box, grid_step, on_grid)) box = on_grid;
    w.put_raw(std::span<const float>(&box.min.x, 3));
    w.put_raw(std::span<const float>(&box.max.x, 3));
    const glm::vec3 extent = box.max - box.min;
    // The scale in double: 65535 / extent overflows a float for an extent under about 2e-34 (a
    // decoded hostile box can be that small), and an infinite scale put every position on one of
    // the box's ends (fuzz/regressions/group_codec/compact-tiny-extent-snaps-to-box-ends).
    glm::dvec3 scale(0);
    for (int a = 0; a < 3; ++a) scale[a] = extent[a] > 0 ? kQuantMax / double{extent[a]} : 0.0;
    std::vector<std::uint16_t> q(3 * old_of_new.size());
    for (std::size_t i = 0; i < old_of_new.size(); ++i) {
        const glm::dvec3 p = glm::dvec3(mesh.positions[old_of_new[i]] - box.min) * scale;
        for (int a = 0; a < 3; ++a)
            q[3 * i + a] =
                static_cast<std::uint16_t>(std::lround(std::clamp(p[a], 0.0, double{kQuantMax})));
    }
    w.put_raw(std::span<const std::uint16_t>(q));
}

// The box and the quantised positions; the box must be finite and not inverted, so every
// decoded position is finite and inside it.
void get_positions(ByteReader& r, std::uint32_t vertex_count, std::vector<glm::vec3>& out) {
    glm::vec3 lo, hi;
    r.get_raw(std::span(&lo.x, 3));
    r.get_raw(std::span(&hi.x, 3));
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !std::isfinite(hi[a] - lo[a]) ||
            lo[a] > hi[a])
            r.fail("box: expected finite min <= max, got axis " + std::to_string(a) + " [" +
                   std::to_string(lo[a]) + ", " + std::to_string(hi[a]) + "]");
    }
    // In double, rounded to float once: a float step of a denormal extent is off by up to half
    // the smallest denormal, which 65535 steps multiplied past the quantisation bound
    // (fuzz/regressions/group_codec/compact-denormal-box-step-rounding).
    const glm::dvec3 step = (glm::dvec3(hi) - glm::dvec3(lo)) / double{kQuantMax};
    std::vector<std::uint16_t> q(3 * std::size_t{vertex_count});
    r.get_raw(std::span(q));
    out.resize(vertex_count);
    for (std::size_t i = 0; i < vertex_count; ++i)
        for (int a = 0; a < 3; ++a)
            out[i][a] = std::min(static_cast<float>(lo[a] + q[3 * i + a] * step[a]), hi[a]);
}

void get_indices(ByteReader& r, std::uint32_t triangle_count, std::uint32_t vertex_count,
                 std::vector<std::uint32_t>& out) {
    const auto size = r.get<std::uint32_t>();
    const auto coded = r.get_span(size);
    if (triangle_count == 0) {
        if (size != 0) r.fail("indices: " + std::to_string(size) + " bytes for no triangle");
        return;
    }
    // The codec spends at least one byte on every triangle, so a claimed count larger than the
    // coded bytes is refused before 12 bytes a triangle are allocated for it.
    if (triangle_count > size)
        r.fail("indices: " + std::to_string(triangle_count) + " triangles in " +
               std::to_string(size) + " coded bytes");
    out.resize(3 * std::size_t{triangle_count});
    const int rc = meshopt_decodeIndexBuffer(out.data(), out.size(), sizeof(std::uint32_t),
                                             coded.data(), coded.size());
    if (rc != 0) r.fail("indices: meshopt_decodeIndexBuffer failed (" + std::to_string(rc) + ")");
    for (std::uint32_t i : out)
        if (i >= vertex_count)
            r.fail("indices: index " + std::to_string(i) + " >= vertex count " +
                   std::to_string(vertex_count));
}

}  // namespace

std::array<std::int16_t, 2> oct_encode(glm::vec3 n) {
    const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
    if (!(l1 > 0) || !std::isfinite(l1)) return {0, to_snorm16(1.0f)};  // no direction: +z
    n /= l1;
    float x = n.x, y = n.y;
    if (n.z < 0) {  // fold the lower half over the diagonals
        x = (1 - std::abs(n.y)) * sign_not_zero(n.x);
        y = (1 - std::abs(n.x)) * sign_not_zero(n.y);
    }
    return {to_snorm16(x), to_snorm16(y)};
}

glm::vec3 oct_decode(std::array<std::int16_t, 2> code) {
    glm::vec3 n(from_snorm16(code[0]), from_snorm16(code[1]), 0);
    n.z = 1 - std::abs(n.x) - std::abs(n.y);
    const float t = std::max(-n.z, 0.0f);
    n.x += n.x >= 0 ? -t : t;
    n.y += n.y >= 0 ? -t : t;
    return glm::normalize(n);  // |n| >= 1/sqrt(3): never a division by zero
}

void put_compact_mesh(ByteWriter& w, const Mesh& mesh, float grid_step) {
    const Reordered ro = reorder(mesh);
    w.put(static_cast<std::uint32_t>(ro.old_of_new.size()));
    w.put(static_cast<std::uint32_t>(mesh.triangle_count()));
    put_positions(w, mesh, ro.old_of_new, grid_step);
    std::vector<std::int16_t> normals(2 * ro.old_of_new.size());
    for (std::size_t i = 0; i < ro.old_of_new.size(); ++i) {
        const auto c = oct_encode(mesh.normals[ro.old_of_new[i]]);
        normals[2 * i] = c[0];
        normals[2 * i + 1] = c[1];
    }
    w.put_raw(std::span<const std::int16_t>(normals));
    if (ro.indices.empty()) {
        w.put(std::uint32_t{0});
        return;
    }
    std::vector<std::uint8_t> coded(
        meshopt_encodeIndexBufferBound(ro.indices.size(), ro.old_of_new.size()));
    coded.resize(meshopt_encodeIndexBuffer(coded.data(), coded.size(), ro.indices.data(),
                                           ro.indices.size()));
    w.put(static_cast<std::uint32_t>(coded.size()));
    w.put_raw(std::span<const std::uint8_t>(coded));
}

Mesh get_compact_mesh(ByteReader& r) {
    const auto vertex_count = r.get<std::uint32_t>();
    const auto triangle_count = r.get<std::uint32_t>();
    if (vertex_count > kMaxGroupVertices)
        r.fail("vertex count " + std::to_string(vertex_count) + " over the limit " +
               std::to_string(kMaxGroupVertices));
    if (triangle_count > kMaxGroupTriangles)
        r.fail("triangle count " + std::to_string(triangle_count) + " over the limit " +
               std::to_string(kMaxGroupTriangles));
    // Box, positions and normals: 24 + 10 bytes a vertex must be there before any is allocated.
    r.need_elements(vertex_count, 10, "vertices");
    Mesh mesh;
    get_positions(r, vertex_count, mesh.positions);
    std::vector<std::array<std::int16_t, 2>> codes(vertex_count);
    r.get_raw(std::span(codes));
    mesh.normals.resize(vertex_count);
    for (std::size_t i = 0; i < vertex_count; ++i) mesh.normals[i] = oct_decode(codes[i]);
    get_indices(r, triangle_count, vertex_count, mesh.indices);
    return mesh;
}

}  // namespace isowall::remote
