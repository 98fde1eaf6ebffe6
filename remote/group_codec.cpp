#include "remote/group_codec.h"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include <zstd.h>

#include "remote/byte_io.h"
#include "remote/cell_codec.h"
#include "remote/compact_mesh.h"

namespace isowall::remote {
namespace {

constexpr const char* kWhat = "group";
// The largest level a group may claim: a meta-cell of 2^30 cells a side is past any volume.
constexpr int kMaxLevel = 30;
// The largest compact message: the header, 34 bytes a vertex (box included once) and
// meshoptimizer's bound of 16 bytes a triangle is far above what its codec writes.
constexpr std::uint64_t kMaxCompactBytes =
    std::uint64_t{kMaxGroupVertices} * 10 + std::uint64_t{kMaxGroupTriangles} * 16 + 256;
// The largest cells body: every voxel of the largest box as a float64, and the units' gaps.
constexpr std::uint64_t kMaxCellBytes =
    kMaxCellBoxVoxels * 8 + std::uint64_t{kMaxGroupTriangles} * 10 + 256;

// ---- the group header ----------------------------------------------------------------------

void put_header(ByteWriter& w, const Group& g) {
    w.put(g.id);
    w.put(static_cast<std::int32_t>(g.seed.x));
    w.put(static_cast<std::int32_t>(g.seed.y));
    w.put(static_cast<std::int32_t>(g.seed.z));
    w.put(static_cast<std::int32_t>(g.level));
    w.put(g.iso);
    w.put(static_cast<std::uint8_t>(g.refinement ? 1 : 0));
}

Group get_header(ByteReader& r) {
    Group g;
    g.id = r.get<std::uint32_t>();
    g.seed.x = r.get<std::int32_t>();
    g.seed.y = r.get<std::int32_t>();
    g.seed.z = r.get<std::int32_t>();
    g.level = r.get<std::int32_t>();
    if (g.level < 0 || g.level > kMaxLevel)
        r.fail("level: expected 0.." + std::to_string(kMaxLevel) + ", got " +
               std::to_string(g.level));
    g.iso = r.get<double>();
    if (!std::isfinite(g.iso))
        r.fail("iso: expected a finite number, got " + std::to_string(g.iso));
    const auto refinement = r.get<std::uint8_t>();
    if (refinement > 1) r.fail("refinement: expected 0 or 1, got " + std::to_string(refinement));
    g.refinement = refinement == 1;
    return g;
}

// ---- float arrays --------------------------------------------------------------------------

void get_finite_vec3s(ByteReader& r, std::vector<glm::vec3>& out, std::size_t n,
                      const char* field) {
    out.resize(n);
    r.get_raw(std::span(out));
    for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
            if (!std::isfinite(out[i][a]))
                r.fail(std::string(field) + " " + std::to_string(i) +
                       ": expected a finite number, got " + std::to_string(out[i][a]));
}

std::uint32_t get_count(ByteReader& r, std::uint32_t limit, const char* field) {
    const auto n = r.get<std::uint32_t>();
    if (n > limit)
        r.fail(std::string(field) + " " + std::to_string(n) + " over the limit " +
               std::to_string(limit));
    return n;
}

// ---- vertices: three separate vertices a triangle --------------------------------------------

void put_vertices(ByteWriter& w, const Mesh& m) {
    w.put(static_cast<std::uint32_t>(m.triangle_count()));
    std::vector<glm::vec3> corners(m.indices.size());
    for (std::size_t i = 0; i < m.indices.size(); ++i) corners[i] = m.positions[m.indices[i]];
    w.put_raw(std::span<const glm::vec3>(corners));
    for (std::size_t i = 0; i < m.indices.size(); ++i) corners[i] = m.normals[m.indices[i]];
    w.put_raw(std::span<const glm::vec3>(corners));
}

Mesh get_vertices(ByteReader& r) {
    const std::uint32_t triangles = get_count(r, kMaxGroupTriangles, "triangle count");
    r.need_elements(triangles, 3 * 2 * sizeof(glm::vec3), "triangles");
    const std::size_t n = 3 * std::size_t{triangles};
    Mesh m;
    get_finite_vec3s(r, m.positions, n, "position");
    get_finite_vec3s(r, m.normals, n, "normal");
    m.indices.resize(n);
    std::iota(m.indices.begin(), m.indices.end(), 0u);
    return m;
}

// ---- indexed: the extractor's indexed face set -----------------------------------------------

// Indices are uint16 when every one fits (at most 65536 vertices, as in every group the engine
// makes), else uint32: what a GL program uploads. The decoder tells which from the vertex count.
bool narrow_indices(std::size_t vertices) {
    return vertices <= kMaxNarrowIndexedVertices;
}

void put_indexed(ByteWriter& w, const Mesh& m) {
    w.put(static_cast<std::uint32_t>(m.vertex_count()));
    w.put(static_cast<std::uint32_t>(m.triangle_count()));
    w.put_raw(std::span<const glm::vec3>(m.positions));
    w.put_raw(std::span<const glm::vec3>(m.normals));
    if (!narrow_indices(m.vertex_count())) {
        w.put_raw(std::span<const std::uint32_t>(m.indices));
        return;
    }
    const std::vector<std::uint16_t> narrow(m.indices.begin(), m.indices.end());
    w.put_raw(std::span<const std::uint16_t>(narrow));
}

Mesh get_indexed(ByteReader& r) {
    const std::uint32_t vertices = get_count(r, kMaxGroupVertices, "vertex count");
    const std::uint32_t triangles = get_count(r, kMaxGroupTriangles, "triangle count");
    r.need_elements(vertices, 2 * sizeof(glm::vec3), "vertices");
    Mesh m;
    get_finite_vec3s(r, m.positions, vertices, "position");
    get_finite_vec3s(r, m.normals, vertices, "normal");
    const std::size_t n = 3 * std::size_t{triangles};
    if (narrow_indices(vertices)) {
        r.need_elements(triangles, 3 * sizeof(std::uint16_t), "triangles");
        std::vector<std::uint16_t> narrow(n);
        r.get_raw(std::span(narrow));
        m.indices.assign(narrow.begin(), narrow.end());
    } else {
        r.need_elements(triangles, 3 * sizeof(std::uint32_t), "triangles");
        m.indices.resize(n);
        r.get_raw(std::span(m.indices));
    }
    for (std::uint32_t i : m.indices)
        if (i >= vertices)
            r.fail("index " + std::to_string(i) + " >= vertex count " + std::to_string(vertices));
    return m;
}

// How a cells body follows its header: as it is, or through zstd when that is smaller (a body of
// floating-point voxels, whose byte planes the range coder does not code).
enum class CellPacking : std::uint8_t { as_it_is = 0, zstd = 1 };

// ---- compact + zstd ------------------------------------------------------------------------

void put_zstd(ByteWriter& w, const std::vector<std::uint8_t>& compact) {
    w.put(static_cast<std::uint64_t>(compact.size()));
    std::vector<std::uint8_t> frame(ZSTD_compressBound(compact.size()));
    const std::size_t n =
        ZSTD_compress(frame.data(), frame.size(), compact.data(), compact.size(), kZstdLevel);
    if (ZSTD_isError(n))
        throw std::runtime_error(std::string("group codec: ZSTD_compress: ") +
                                 ZSTD_getErrorName(n));
    w.put_raw(std::span<const std::uint8_t>(frame.data(), n));
}

// The compact message inside the frame; its size is checked against the limits, the frame's
// own claim and the expansion cap before it is allocated.
std::vector<std::uint8_t> get_zstd(ByteReader& r, std::uint64_t limit) {
    const auto size = r.get<std::uint64_t>();
    const auto frame = r.get_span(r.remaining());
    if (size > limit || size > frame.size() * kMaxZstdExpansion)
        r.fail("zstd: " + std::to_string(size) + " bytes claimed from a frame of " +
               std::to_string(frame.size()));
    if (ZSTD_getFrameContentSize(frame.data(), frame.size()) != size)
        r.fail("zstd: the frame's content size is not the " + std::to_string(size) +
               " bytes claimed");
    std::vector<std::uint8_t> out(static_cast<std::size_t>(size));
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), frame.data(), frame.size());
    if (ZSTD_isError(n)) r.fail(std::string("zstd: ") + ZSTD_getErrorName(n));
    if (n != size)
        r.fail("zstd: " + std::to_string(n) + " bytes, " + std::to_string(size) + " claimed");
    return out;
}

void check_encodable(const Group& g) {
    const Mesh& m = g.mesh;
    if (m.normals.size() != m.positions.size() || m.indices.size() % 3 != 0 ||
        m.vertex_count() > kMaxGroupVertices || m.triangle_count() > kMaxGroupTriangles ||
        g.level < 0 || g.level > kMaxLevel)
        throw std::invalid_argument("encode_group: group " + std::to_string(g.id) +
                                    " cannot be encoded (" + std::to_string(m.vertex_count()) +
                                    " positions, " + std::to_string(m.normals.size()) +
                                    " normals, " + std::to_string(m.indices.size()) +
                                    " indices, level " + std::to_string(g.level) + ")");
    for (std::uint32_t i : m.indices)
        if (i >= m.vertex_count())
            throw std::invalid_argument("encode_group: index " + std::to_string(i) +
                                        " >= vertex count " + std::to_string(m.vertex_count()));
}

}  // namespace

const char* to_string(GroupEncoding e) {
    switch (e) {
        case GroupEncoding::vertices:
            return "vertices";
        case GroupEncoding::indexed:
            return "indexed";
        case GroupEncoding::compact:
            return "compact";
        case GroupEncoding::compact_zstd:
            return "compact+zstd";
        case GroupEncoding::cells:
            return "cells";
    }
    return "unknown";
}

float position_grid_step(float extent) {
    if (!(extent > 0) || !std::isfinite(extent)) return 0;
    return std::exp2(std::ceil(std::log2(double{extent} / 65534.0)));
}

std::vector<std::uint8_t> encode_group(const Group& group, GroupEncoding encoding, float grid_step,
                                       const Volume* volume, std::vector<std::uint8_t>* exact) {
    check_encodable(group);
    if (exact) exact->clear();
    if (encoding == GroupEncoding::cells) {
        const auto body = volume ? encode_cell_body(group, *volume, exact) : std::nullopt;
        if (!body) return encode_group(group, GroupEncoding::compact_zstd, grid_step);
        ByteWriter w;
        w.put(kGroupCodecVersion);
        w.put(static_cast<std::uint8_t>(encoding));
        put_header(w, group);
        ByteWriter packed;
        put_zstd(packed, *body);
        const std::vector<std::uint8_t> zstd = packed.take();
        const CellPacking packing =
            zstd.size() < body->size() ? CellPacking::zstd : CellPacking::as_it_is;
        w.put(static_cast<std::uint8_t>(packing));
        w.put_raw(std::span<const std::uint8_t>(packing == CellPacking::zstd ? zstd : *body));
        std::vector<std::uint8_t> cells = w.take();
        // A coarse pass's corners lie 2^level apart, where neighbours predict them poorly: cells
        // may then be the larger, on a small pass (before coarse values went to a step, cthead's
        // meta-cells of 4 took 8.8 bytes a triangle against 6.7).
        if (group.level == 0 || group.refinement) return cells;
        std::vector<std::uint8_t> compact =
            encode_group(group, GroupEncoding::compact_zstd, grid_step);
        return compact.size() < cells.size() ? compact : cells;
    }
    if (encoding == GroupEncoding::compact_zstd) {
        const auto compact = encode_group(group, GroupEncoding::compact, grid_step);
        ByteWriter w;
        w.put(kGroupCodecVersion);
        w.put(static_cast<std::uint8_t>(encoding));
        put_zstd(w, compact);
        return w.take();
    }
    ByteWriter w;
    w.put(kGroupCodecVersion);
    w.put(static_cast<std::uint8_t>(encoding));
    put_header(w, group);
    switch (encoding) {
        case GroupEncoding::vertices:
            put_vertices(w, group.mesh);
            break;
        case GroupEncoding::indexed:
            put_indexed(w, group.mesh);
            break;
        default:
            put_compact_mesh(w, group.mesh, grid_step);
            break;
    }
    return w.take();
}

GroupEncoding encoding_of(std::span<const std::uint8_t> bytes) {
    ByteReader r(bytes, kWhat);
    const auto version = r.get<std::uint8_t>();
    if (version != kGroupCodecVersion)
        r.fail("version " + std::to_string(version) + ", expected " +
               std::to_string(kGroupCodecVersion));
    const auto e = r.get<std::uint8_t>();
    if (e > static_cast<std::uint8_t>(GroupEncoding::cells))
        r.fail("encoding: expected 0..4, got " + std::to_string(e));
    return static_cast<GroupEncoding>(e);
}

Group decode_group(std::span<const std::uint8_t> bytes, const CellExact& x) {
    if (x.stepped) *x.stepped = false;
    const GroupEncoding encoding = encoding_of(bytes);
    ByteReader r(bytes.subspan(2), kWhat);
    if (encoding == GroupEncoding::compact_zstd) {
        const std::vector<std::uint8_t> compact = get_zstd(r, kMaxCompactBytes);
        if (encoding_of(compact) != GroupEncoding::compact)
            r.fail("zstd: the frame holds a " + std::string(to_string(encoding_of(compact))) +
                   " group, expected compact");
        if (x.exact) r.fail("exact values: only a cells group takes them");
        return decode_group(compact);
    }
    Group g = get_header(r);
    if (x.exact && encoding != GroupEncoding::cells)
        r.fail("exact values: only a cells group takes them");
    if (encoding == GroupEncoding::cells) {
        const auto packing = r.get<std::uint8_t>();
        if (packing > static_cast<std::uint8_t>(CellPacking::zstd))
            r.fail("cells packing: expected 0 (as it is) or 1 (zstd), got " +
                   std::to_string(packing));
        const bool zstd = packing == static_cast<std::uint8_t>(CellPacking::zstd);
        const std::vector<std::uint8_t> unpacked =
            zstd ? get_zstd(r, kMaxCellBytes) : std::vector<std::uint8_t>{};
        const std::span<const std::uint8_t> body =
            zstd ? std::span<const std::uint8_t>(unpacked) : r.get_span(r.remaining());
        ByteReader cells(body, kWhat);
        g.mesh = decode_cell_body(cells, g.iso, x);
        cells.finish();
        return g;
    }
    switch (encoding) {
        case GroupEncoding::vertices:
            g.mesh = get_vertices(r);
            break;
        case GroupEncoding::indexed:
            g.mesh = get_indexed(r);
            break;
        default:
            g.mesh = get_compact_mesh(r);
            break;
    }
    r.finish();
    return g;
}

}  // namespace isowall::remote
