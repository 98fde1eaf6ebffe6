#pragma once
// Adaptive resolution (chapter 2.1.3): far from the eye a cell projects to less than a pixel, so
// the surface is extracted from meta-cells instead. A meta-cell of level i is the block of
// 2^i x 2^i x 2^i cells at a multiple of 2^i whose corners are the eight voxels at stride 2^i.
// Its activity and marching-cubes case come from those eight corners only, as in the text.
//
// Which level a cell is extracted at is a partition of the volume into units, decided top down:
// the meta-cell of the highest level containing the cell is one unit when it is coarse enough
// (ResolutionMap::coarse_enough); otherwise the question passes to the meta-cell one level below,
// down to the cell itself (ResolutionMap::level_of). The ray caster's octree walk and the
// propagator ask the same function, so every cell belongs to exactly one unit and a ray never
// seeds inside a unit of another level.
//
// Partial meta-cells at the volume's upper faces (dims not a multiple of 2^i) are never units: they
// fall back to the finer level, so every unit's eight corners are real voxels and no triangle is
// stretched over clamped indices.
//
// Two choices go beyond the text, both because the correctness C (section 4.2) counts a pixel the
// full surface covers and the adaptive one does not as wholly wrong, so "sub-pixel, hence
// invisible" does not hold on silhouettes and across cracks:
//   vertex placement: a long edge's vertex is interpolated between the two fine voxels on the edge
//     that bracket the crossing nearest the linear estimate from the edge's ends, so it lies on the
//     full-resolution surface, and its normal is the fine central-difference gradient there (with
//     the ends alone the shading error of the phantom's zoomed-out views about doubled). A long
//     edge is one line of 2^i + 1 voxels; faces and inside voxels are still never read.
//   refinement: where the exact ray walk finds the full-resolution surface inside a meta-cell whose
//     own triangles it misses, the meta-cell is drawn again at full resolution (RayHit::refine,
//     Propagator::refine), so a pixel whose ray sees the surface is not left empty. (What remains:
//     a ray that hits a triangle within rasterization precision of an edge whose other side no
//     group has drawn; full resolution has the same tie, where it is rarer.)
#include <array>
#include <cstdint>
#include <limits>
#include <ostream>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "common/core/camera.h"
#include "common/extract/marching_cubes.h"

namespace isowall {

// 8 x 8 x 8 cells (one octree node above the leaf bricks): the largest unit the walk tests.
inline constexpr int kMaxMetaLevel = 3;

// The array D of section 2.1.3 for one view.
struct ResolutionLevels {
    // d[i] in object units: a meta-cell of level i whose centre is farther than d[i] from the eye
    // projects to less than one pixel. +inf: level i is never used; 0: always (orthographic, where
    // the projected size does not depend on distance). d[0] is informative only: level 0 (the
    // cell) is the fallback everywhere.
    std::array<float, kMaxMetaLevel + 1> d = filled(std::numeric_limits<float>::infinity());
    glm::vec3 eye{0};    // object space
    int max_level = 0;   // levels above this are never used; 0 = full resolution
    bool refine = true;  // refinement on ray evidence (see above); false: the text's rule alone

    // The largest i in [1, max_level] with distance > d[i], else 0.
    int level_at(float distance) const {
        for (int i = max_level; i >= 1; --i)
            if (distance > d[static_cast<std::size_t>(i)]) return i;
        return 0;
    }

private:
    static constexpr std::array<float, kMaxMetaLevel + 1> filled(float x) {
        std::array<float, kMaxMetaLevel + 1> a{};
        for (float& e : a) e = x;
        return a;
    }
};

// D for a screen `height_px` pixels high seen through `frustum` from `camera` (its eye), for voxels
// of `spacing` (a meta-cell's size is 2^i times the largest spacing component, the conservative
// choice for anisotropic voxels).
//   perspective:  D[i] = 2^i * s_max / pixel_angle, pixel_angle = (frustum height / near) /
//                 height_px (the small-angle size of one pixel at the screen's centre);
//   orthographic: one pixel is frustum height / height_px object units at every distance, so D[i]
//                 is 0 when 2^i * s_max is less than that, else +inf.
// A tile's sub-frustum with the tile's height gives the same pixel size as the full screen.
ResolutionLevels resolution_levels(const Camera& camera, const Frustum& frustum, int height_px,
                                   glm::vec3 spacing, int max_level = kMaxMetaLevel);

std::ostream& operator<<(std::ostream& os, const ResolutionLevels& r);

// Corner values of the meta-cell of `level` at `base` (corner k at base + 2^level *
// kCornerOffset[k]); the meta-cell must be complete.
template <class T>
inline void meta_cell_corners(const VolumeView<T>& v, glm::ivec3 base, int level, double out[8]) {
    const int s = 1 << level;
    for (std::size_t k = 0; k < 8; ++k) {
        const auto& o = mc::kCornerOffset[k];
        out[k] = static_cast<double>(v.at(base.x + s * o[0], base.y + s * o[1], base.z + s * o[2]));
    }
}

// ResolutionLevels in voxel space for one volume: the level of each cell. Default-constructed, it
// is full resolution everywhere (level 0), and the walk and the propagation take exactly their
// full-resolution paths.
class ResolutionMap {
public:
    ResolutionMap() = default;
    ResolutionMap(const ResolutionLevels& levels, glm::vec3 spacing, glm::ivec3 cell_dims)
        : spacing_(spacing),
          cell_dims_(cell_dims),
          eye_(levels.eye),
          max_level_(levels.max_level),
          refine_(levels.refine) {
        for (std::size_t i = 0; i < levels.d.size(); ++i) d2_[i] = levels.d[i] * levels.d[i];
    }

    int max_level() const { return max_level_; }
    bool refine() const { return refine_; }

    // Whether the meta-cell of `level` >= 1 at `base` (a multiple of 2^level) may be a unit on its
    // own account: complete, and its centre beyond D[level]. A unit also needs no coarser unit
    // around it; level_of() and a top-down walk check that.
    bool coarse_enough(glm::ivec3 base, int level) const {
        const int s = 1 << level;
        if (base.x + s > cell_dims_.x || base.y + s > cell_dims_.y || base.z + s > cell_dims_.z)
            return false;
        const glm::vec3 centre = (glm::vec3(base) + 0.5f * static_cast<float>(s)) * spacing_;
        const glm::vec3 to = centre - eye_;
        return glm::dot(to, to) > d2_[static_cast<std::size_t>(level)];
    }

    // The level of the unit holding `cell`; the unit's first cell is cell & ~(2^level - 1).
    int level_of(glm::ivec3 cell) const {
        for (int i = max_level_; i >= 1; --i)
            if (coarse_enough(cell & ~((1 << i) - 1), i)) return i;
        return 0;
    }

    // False when no meta-cell of `level` inside the voxel box [lo, hi] can be coarse enough
    // (the whole box lies within D[level] of the eye): the walk then skips the level checks.
    bool may_coarsen(glm::vec3 lo, glm::vec3 hi, int level) const {
        if (level > max_level_) return false;
        const glm::vec3 a = lo * spacing_ - eye_, b = hi * spacing_ - eye_;
        const glm::vec3 far = glm::max(glm::abs(a), glm::abs(b));
        return glm::dot(far, far) > d2_[static_cast<std::size_t>(level)];
    }

private:
    glm::vec3 spacing_{1.0f};
    glm::ivec3 cell_dims_{0};
    glm::vec3 eye_{0};
    int max_level_ = 0;
    bool refine_ = false;
    std::array<float, kMaxMetaLevel + 1> d2_{};  // D[i]^2
};

// Where the surface crosses the edge of a meta-cell that runs 2^level voxels from pa along `axis`,
// whose end values va (at pa) and vb straddle iso: of the crossings between neighbouring voxels on
// the edge (at least one, an odd number), the one nearest the linear estimate from va and vb. The
// answer depends on the edge alone, so the (up to four) meta-cells sharing an edge share its
// vertex and a level has no cracks inside. Level 0: the linear estimate of emit_cell().
struct EdgeCrossing {
    int segment = 0;  // the crossing lies between voxels pa + segment and pa + segment + 1
    float frac = 0;   // and that far from the first of them
    float t() const { return static_cast<float>(segment) + frac; }  // voxels from pa
};

template <class T>
inline EdgeCrossing edge_crossing(const VolumeView<T>& v, glm::ivec3 pa, int axis, int level,
                                  double iso, double va, double vb) {
    EdgeCrossing best;
    best.frac = static_cast<float>((iso - va) / (vb - va));
    if (level == 0) return best;
    const int s = 1 << level;
    const float linear = static_cast<float>(s) * best.frac;
    float best_miss = std::numeric_limits<float>::max();
    glm::ivec3 p = pa;
    double f0 = va;
    for (int k = 0; k < s; ++k) {
        ++p[axis];
        const double f1 = k + 1 == s ? vb : static_cast<double>(v.at(p.x, p.y, p.z));
        if ((f0 >= iso) != (f1 >= iso)) {
            const auto frac = static_cast<float>((iso - f0) / (f1 - f0));
            const float miss = std::abs(static_cast<float>(k) + frac - linear);
            if (miss < best_miss) {
                best_miss = miss;
                best = {k, frac};
            }
        }
        f0 = f1;
    }
    return best;
}

// The triangles of a meta-cell in voxel space (three vertices each); returns the triangle count.
// Level 0 gives exactly cell_triangles().
template <class T>
int meta_cell_triangles(const VolumeView<T>& v, glm::ivec3 base, int level, double iso,
                        std::array<glm::vec3, 3 * mc::kMaxTriangles>& out) {
    double corner[8];
    meta_cell_corners(v, base, level, corner);
    const int cs = cell_case(corner, iso);
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    const int s = 1 << level;
    for (int i = 0; i < 3 * count; ++i) {
        const auto e = static_cast<std::size_t>(edges[static_cast<std::size_t>(i)]);
        const int ca = mc::kEdgeCorners[e][0], cb = mc::kEdgeCorners[e][1];
        const auto& oa = mc::kCornerOffset[static_cast<std::size_t>(ca)];
        const glm::ivec3 pa = base + s * glm::ivec3(oa[0], oa[1], oa[2]);
        const int axis = mc::kEdgeAxis[e];
        glm::vec3 p = glm::vec3(pa);
        p[axis] += edge_crossing(v, pa, axis, level, iso, corner[ca], corner[cb]).t();
        out[static_cast<std::size_t>(i)] = p;
    }
    return count;
}

// emit_cell() for a meta-cell: a vertex per long edge at its edge_crossing(), keyed in `cache` by
// (lower corner voxel, axis), which is unique as long as one cache sees one level. Its normal is
// the fine central-difference gradient interpolated between the two voxels that bracket the
// crossing: the normal the full-resolution surface has at that point. (Gradients at stride 2^level
// at the corners were tried: they smooth away shading the pixels show, and the phantom's zoomed-
// out C fell by 0.01 to 0.02.) Level 0 gives exactly emit_cell(). Returns the triangles added.
template <class T, class Cache>
inline int emit_meta_cell(const VolumeView<T>& v, glm::ivec3 base, int level, double iso, int cs,
                          const double corner[8], Cache& cache, Mesh& mesh) {
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    const glm::vec3 inv_step = 0.5f / v.spacing;
    const int s = 1 << level;
    for (int i = 0; i < 3 * count; ++i) {
        const int e = edges[static_cast<std::size_t>(i)];
        const int ca = mc::kEdgeCorners[static_cast<std::size_t>(e)][0];
        const int cb = mc::kEdgeCorners[static_cast<std::size_t>(e)][1];
        const auto& oa = mc::kCornerOffset[static_cast<std::size_t>(ca)];
        const glm::ivec3 pa = base + s * glm::ivec3(oa[0], oa[1], oa[2]);
        const int axis = mc::kEdgeAxis[static_cast<std::size_t>(e)];
        auto [slot, inserted] = cache.find_or_insert(pa, axis);
        if (inserted) {
            const EdgeCrossing x = edge_crossing(v, pa, axis, level, iso, corner[ca], corner[cb]);
            glm::ivec3 pa_fine = pa;
            pa_fine[axis] += x.segment;
            glm::ivec3 pb_fine = pa_fine;
            pb_fine[axis] += 1;
            glm::vec3 pos = glm::vec3(pa);
            pos[axis] += x.t();
            *slot = append_vertex(mesh, pos, gradient(v, pa_fine, inv_step),
                                  gradient(v, pb_fine, inv_step), x.frac, v.spacing);
        }
        mesh.indices.push_back(*slot);
    }
    return count;
}

}  // namespace isowall
