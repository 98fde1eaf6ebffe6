#include "remote/cell_codec.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "extract/edge_cache.h"
#include "remote/cell_values.h"
#include "remote/cell_voxels.h"
#include "remote/group_codec.h"
#include "volume/load_checks.h"

namespace isowall::remote {
namespace {

using namespace cells;

constexpr std::uint32_t kMaxUnits = kMaxGroupTriangles;
// A unit's place costs one decision, at least 0.022 bits (range_coder.h): at most 364 a byte.
constexpr std::uint64_t kMaxPlacesPerByte = 384;

// How a body's normals come (its `normals` byte): from the gradients' voxels, or from the faces
// around each vertex (nothing sent).
enum class Normals : std::uint8_t { gradients = 0, faces = 1 };
// A body of face normals steps every phase (a coarse pass); one of gradient normals only the
// gradients' voxels, the last phase (a full-resolution group sent to a step first).
int first_stepped_phase(Normals n) {
    return n == Normals::faces ? 0 : cells::kValuePhases - 1;
}

// The units' triangles, as both sides emit them: the same order, the same vertex per edge.
template <class View>
Mesh triangulate(const View& v, const std::vector<Unit>& units, const Corners& corners,
                 const std::vector<int>& cases, double iso, std::size_t triangles) {
    Mesh mesh;
    mesh.indices.reserve(3 * triangles);
    HashEdgeCache cache(v.dims, 2 * units.size());
    for (std::size_t i = 0; i < units.size(); ++i)
        emit_meta_cell(v, units[i].base, units[i].level, iso, cases[i], corners[i].data(), cache,
                       mesh);
    return mesh;
}

std::vector<int> cases_of(const Corners& corners, double iso, std::size_t& triangles) {
    std::vector<int> cases(corners.size());
    triangles = 0;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        cases[i] = cell_case(corners[i].data(), iso);
        triangles +=
            static_cast<std::size_t>(mc::kTriangleCount[static_cast<std::size_t>(cases[i])]);
    }
    return cases;
}

// A coarse pass's values travel to a step of an eighth of the median difference its crossed
// edges span (cells::Bins; a power of two, 4 or more, else exact): its vertices then move by at
// most a sixteenth of such an edge, far under the error of the level itself, and a value costs
// log2(step) bits less. Its normals come from its faces, which need no exact values.
constexpr double kCoarseStepOfEdge = 1.0 / 8;

// A full-resolution group's gradient voxels (phase 3: the values that only make its normals) may
// go to a step of a quarter of that median first, their exact offsets after (cell_exact.h): the
// vertices stay where they are, so every pixel the surface covers is covered, and the shading
// moves a little. Over the shared 16-bit volumes this drew the image to C = 99.6-99.8% of the
// exact one, and its first message was 11-15% smaller than the exact group on one frame's groups
// (the codec test), the 8-bit volumes' 4-15%.
constexpr double kGradientStepOfEdge = 1.0 / 4;

// The step's shift for `units`: a power of two near `of_edge` times the median difference their
// crossed edges span; 0 (exact) under 4.
template <class View>
int value_shift(const Held<View>& h, const std::vector<Unit>& units, int bits, double of_edge) {
    std::vector<double> spans;
    double c[8];
    for (const Unit& u : units) {
        h.corners(u, c);
        for (const auto& ends : mc::kEdgeCorners)
            if ((c[ends[0]] >= h.iso) != (c[ends[1]] >= h.iso))
                spans.push_back(std::abs(c[ends[0]] - c[ends[1]]));
    }
    if (spans.empty()) return 0;
    auto mid = spans.begin() + static_cast<long>(spans.size() / 2);
    std::nth_element(spans.begin(), mid, spans.end());
    const double step = *mid * of_edge;
    const int shift = step >= 1 ? std::ilogb(step) : 0;
    return shift < 2 ? 0 : std::min(shift, bits - 2);
}

// ---- encoder and decoder, per voxel type -------------------------------------------------------

// The units whose triangles make the group's mesh: the active ones of its pass, or every active
// cell of a refinement's meta-cell; nullopt when one is not a complete unit of the volume.
template <class View>
std::optional<std::vector<Unit>> units_of(const Group& g, const Held<View>& h) {
    std::vector<Unit> all;
    if (g.refinement) {
        const int s = 1 << g.level;
        for (int z = 0; z < s; ++z)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) all.push_back({g.seed + glm::ivec3(x, y, z), 0});
    } else {
        for (std::size_t i = 0; i < g.cells.size(); ++i)
            all.push_back({g.cells[i], g.level_of_cell(i)});
    }
    std::vector<Unit> units;
    double c[8];
    for (const Unit& u : all) {
        if (u.level > kMaxUnitLevel) return std::nullopt;
        if (!complete(u, h.dims)) {
            if (g.refinement) continue;  // a cell past the volume holds no triangles
            return std::nullopt;
        }
        h.corners(u, c);
        const int cs = cell_case(c, h.iso);
        if (cs != 0 && cs != 255) units.push_back(u);
    }
    return units;
}

template <class T>
std::optional<std::vector<std::uint8_t>> encode_typed(const Group& g, const Volume& volume,
                                                      std::vector<std::uint8_t>* exact, T) {
    const VolumeView<T> view = volume.view<T>();
    const Held<VolumeView<T>> h{view, volume.dims(), g.iso};
    auto units = units_of(g, h);
    if (!units || units->empty() || units->size() > kMaxUnits) return std::nullopt;
    sort_units(*units, h.dims);
    // The mesh must be the marching cubes of these units: the same triangle count, at least.
    std::size_t triangles = 0;
    double c[8];
    for (const Unit& u : *units) {
        h.corners(u, c);
        triangles += static_cast<std::size_t>(
            mc::kTriangleCount[static_cast<std::size_t>(cell_case(c, h.iso))]);
    }
    if (triangles != g.mesh.triangle_count()) return std::nullopt;
    const VoxelBox box = box_of(*units, h.dims);
    if (box.voxels() > kMaxCellBoxVoxels) return std::nullopt;
    // A coarse pass's vertices lie 2^level apart, so their gradients share few voxels: its
    // normals go as such (it is drawn only until the full resolution replaces it).
    const Normals normals = g.level >= 1 && !g.refinement ? Normals::faces : Normals::gradients;
    ByteWriter w;
    w.put(static_cast<std::uint8_t>(volume.type()));
    for (int a = 0; a < 3; ++a) w.put(static_cast<std::int32_t>(h.dims[a]));
    for (int a = 0; a < 3; ++a) w.put(volume.spacing()[a]);
    w.put(static_cast<std::uint8_t>(normals));
    RangeEncoder coder;
    if (!put_units(w, coder, *units)) return std::nullopt;
    BoxVoxels<T> sent(box, h.dims, volume.spacing());
    PhaseVoxels<T> named(sent, box);
    const bool faces = normals == Normals::faces;
    const int bits = 8 * static_cast<int>(sizeof(T));
    int shift = 0;
    if (std::is_integral_v<T> && (faces || exact))
        shift = value_shift(h, *units, bits, faces ? kCoarseStepOfEdge : kGradientStepOfEdge);
    ExactBitsWriter offsets;
    ValueWriter<T> values(w, coder, g.iso, shift, first_stepped_phase(normals),
                          exact && !faces ? &offsets : nullptr);
    each_phase(h, named, *units, !faces,
               [&](const std::vector<std::uint32_t>& at) { values.phase(sent, view, box, at); });
    values.finish();
    if (exact) *exact = offsets.take();
    return w.take();
}

template <class T>
Mesh decode_typed(ByteReader& r, glm::ivec3 dims, glm::vec3 spacing, double iso, Normals normals,
                  const std::vector<UnitBucket>& buckets, const CellExact& x, T) {
    ValueReader<T> values(r, iso, first_stepped_phase(normals), normals == Normals::gradients);
    const std::vector<Unit> units =
        get_units(r, values.coder(), buckets, dims, kMaxPlacesPerByte * values.stream_bytes());
    // Every unit's corners are voxels no other phase sends, and each voxel is a corner of at
    // most eight units: the values of at least one voxel for every eight units must follow.
    if (units.size() > 8 * values.max_named())
        r.fail("units: " + std::to_string(units.size()) +
               " units, more than the voxel values received can name");
    const VoxelBox box = box_of(units, dims);
    if (box.voxels() > kMaxCellBoxVoxels)
        r.fail("units: spread over " + std::to_string(box.voxels()) + " voxels, over the limit " +
               std::to_string(kMaxCellBoxVoxels));
    BoxVoxels<T> held(box, dims, spacing);
    const Held<BoxVoxels<T>> h{held, dims, iso};
    PhaseVoxels<T> named(held, box, &r, values.max_named());
    const Corners corners =
        each_phase(h, named, units, normals == Normals::gradients,
                   [&](const std::vector<std::uint32_t>& at) { values.phase(held, box, at); });
    values.finish();
    // A coarse pass's values went to a step of their own, which nothing undoes (the reader keeps
    // only a gradients body's stepped values).
    const bool undoable = values.stepped();
    if (x.stepped) *x.stepped = undoable;
    if (x.exact_bytes) *x.exact_bytes = undoable ? values.exact_bytes() : 0;
    if (x.exact) {
        if (!undoable) r.fail("exact values: the body has no values to make exact");
        values.apply_exact(held, *x.exact);
    }
    std::size_t triangles = 0;
    const std::vector<int> cases = cases_of(corners, iso, triangles);
    if (triangles > kMaxGroupTriangles)
        r.fail("units: " + std::to_string(triangles) + " triangles, over the limit " +
               std::to_string(kMaxGroupTriangles));
    // Without the gradients' voxels the normals emitted are placeholders, replaced below.
    Mesh mesh = triangulate(held, units, corners, cases, iso, triangles);
    if (normals == Normals::faces) normals_from_faces(mesh);
    return mesh;
}

}  // namespace

std::optional<std::vector<std::uint8_t>> encode_cell_body(const Group& group, const Volume& volume,
                                                          std::vector<std::uint8_t>* exact) {
    if (exact) exact->clear();
    if (!std::isfinite(group.iso)) return std::nullopt;
    return dispatch_voxel_type(volume.type(),
                               [&](auto t) { return encode_typed(group, volume, exact, t); });
}

Mesh decode_cell_body(ByteReader& r, double iso, const CellExact& x) {
    const auto type = r.get<std::uint8_t>();
    if (type > static_cast<std::uint8_t>(VoxelType::f64))
        r.fail("voxel type: expected 0.." + std::to_string(static_cast<int>(VoxelType::f64)) +
               ", got " + std::to_string(type));
    glm::ivec3 dims;
    for (int a = 0; a < 3; ++a) {
        dims[a] = r.get<std::int32_t>();
        if (dims[a] < 2 || dims[a] > kMaxCellVolumeSide)
            r.fail("volume dims: expected 2.." + std::to_string(kMaxCellVolumeSide) + ", got " +
                   std::to_string(dims[a]));
    }
    glm::vec3 spacing;
    for (int a = 0; a < 3; ++a) {
        spacing[a] = r.get<float>();
        if (!(spacing[a] > 0) || !std::isfinite(spacing[a]))
            r.fail("spacing: expected a positive finite number, got " + std::to_string(spacing[a]));
        // As a volume that loads (load_checks.h): a side past it puts positions past a float.
        if (double(spacing[a]) * (dims[a] - 1) > kMaxVolumeSide)
            r.fail("spacing: " + std::to_string(spacing[a]) + " makes the volume " +
                   std::to_string(double(spacing[a]) * (dims[a] - 1)) +
                   " units a side, over the limit " + std::to_string(kMaxVolumeSide));
    }
    const auto normals = r.get<std::uint8_t>();
    if (normals > static_cast<std::uint8_t>(Normals::faces))
        r.fail("normals: expected 0 (gradients) or 1 (faces), got " + std::to_string(normals));
    const std::vector<UnitBucket> buckets = get_unit_buckets(r, dims, kMaxUnits);
    return dispatch_voxel_type(static_cast<VoxelType>(type), [&](auto t) {
        return decode_typed(r, dims, spacing, iso, static_cast<Normals>(normals), buckets, x, t);
    });
}

}  // namespace isowall::remote