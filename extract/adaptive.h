#pragma once
// Adaptive resolution (chapter 2.1.3): far from the eye a cell projects to less than a pixel, so
// the surface is extracted from meta-cells instead. A meta-cell of level i is the block of
// 2^i x 2^i x 2^i cells at a multiple of 2^i whose corners are the eight voxels at stride 2^i.
// Its activity and marching-cubes case come from those eight corners only, as in the text. The
// marching-cubes functions (marching_cubes.h) take the level: a cell is the meta-cell of level 0.
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
//   vertex placement (edge_crossing, emit_meta_cell): a long edge's vertex is interpolated
//     between the two fine voxels on the edge that bracket the crossing nearest the linear
//     estimate from the edge's ends, so it lies on the full-resolution surface, and its normal is
//     the fine central-difference gradient there (with the ends alone the shading error of the
//     phantom's zoomed-out views about doubled). A long edge is one line of 2^i + 1 voxels; faces
//     and inside voxels are still never read.
//   refinement: where the exact ray walk finds the full-resolution surface inside a meta-cell whose
//     own triangles it misses, the meta-cell is drawn again at full resolution (RayHit::refine,
//     Propagator::refine), so a pixel whose ray sees the surface is not left empty. (What remains:
//     a ray that hits a triangle within rasterization precision of an edge whose other side no
//     group has drawn; full resolution has the same tie, where it is rarer.)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <ostream>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/camera.h"
#include "extract/marching_cubes.h"
#include "volume/lod_error.h"

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
    // The error rule (volume/lod_error.h): a meta-cell is also coarse enough only where its
    // error, projected, is at most error_px pixels. Infinite: no error rule (distance alone).
    float error_px = std::numeric_limits<float>::infinity();
    float pixel_slope = 0;  // perspective: one pixel's object size per unit of distance
    float pixel_size = 0;   // orthographic: one pixel's object size
    // A propagation pass goes on into units of another level (the boundaries the error rule
    // draws anywhere); false: it stops there (uniform levels, whose groups name one level).
    bool cross_levels = true;
    // Units finer than max_level (where a meta-cell of it would pass the volume's border) are
    // extracted, as cells or smaller meta-cells; false: they are not (uniform levels: a coarse
    // pass of progressive LOD leaves the border's cells to the full resolution, so every group it
    // sends is of its own level and the client, which switches to a finer level at the first
    // finer group, does not take a border sliver for the start of the next pass).
    bool finer_units = true;
    // Footprint units (footprint.h): a meta-cell unit is entered where the full-resolution
    // surface crosses its face and shows the full-resolution surface at the pixel centres it
    // holds, instead of its own coarse triangles; rays walk cells, and nothing needs refining.
    bool footprint = false;

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
// `pixels` is the projected size below which a meta-cell is taken: 1 is the text's rule (a
// meta-cell smaller than a pixel, so its triangles are smaller still); 2 lets a meta-cell reach
// two pixels, so that its triangles are about a pixel and a volume with more voxels than the
// screen has pixels draws about as many triangles as one matched to the screen;
// infinity, no size limit. `error_px`: the error rule's bound (infinite: off).
ResolutionLevels resolution_levels(const Camera& camera, const Frustum& frustum, int height_px,
                                   glm::vec3 spacing, int max_level = kMaxMetaLevel,
                                   float pixels = 1.0f,
                                   float error_px = std::numeric_limits<float>::infinity());

std::ostream& operator<<(std::ostream& os, const ResolutionLevels& r);

// Every unit at meta-cells of 2^level cells per side wherever the meta-cell is complete (the
// volume's border falls back to cells), without refinement: a coarse level of progressive LOD
// (section 4.1.3). level 0 is full resolution.
inline ResolutionLevels uniform_levels(int level) {
    ResolutionLevels levels;
    if (level <= 0) return levels;
    level = level < kMaxMetaLevel ? level : kMaxMetaLevel;
    levels.d[static_cast<std::size_t>(level)] = 0;  // every distance is past D[level]
    levels.max_level = level;
    levels.refine = false;
    levels.cross_levels = false;
    levels.finer_units = false;
    return levels;
}

// ResolutionLevels in voxel space for one volume: the level of each cell. Default-constructed, it
// is full resolution everywhere (level 0), and the walk and the propagation take exactly their
// full-resolution paths.
class ResolutionMap {
  public:
    ResolutionMap() = default;
    // `errors`: the volume's meta-cell errors, for the error rule; it must outlive the map.
    // Without them (or with levels.error_px infinite) the distance rule decides alone.
    ResolutionMap(const ResolutionLevels& levels, glm::vec3 spacing, glm::ivec3 cell_dims,
                  const LodErrors* errors = nullptr)
        : spacing_(spacing),
          cell_dims_(cell_dims),
          eye_(levels.eye),
          max_level_(levels.max_level),
          refine_(levels.refine),
          cross_levels_(levels.cross_levels),
          finer_units_(levels.finer_units),
          footprint_(levels.footprint) {
        for (std::size_t i = 0; i < levels.d.size(); ++i) d2_[i] = levels.d[i] * levels.d[i];
        if (errors && !errors->empty() && std::isfinite(levels.error_px)) {
            // error (cells) * s_max <= error_px * (pixel_slope * distance + pixel_size), the
            // object-space bound of lod_error.h against the pixel at the meta-cell's distance.
            errors_ = errors;
            const float s_max = std::max({spacing.x, spacing.y, spacing.z});
            const float k = levels.error_px * levels.pixel_slope / s_max;
            const float c = levels.error_px * levels.pixel_size / s_max;
            err_k2_ = k * k;
            err_c2_ = c * c;
        }
    }

    int max_level() const { return max_level_; }
    bool refine() const { return refine_; }
    bool cross_levels() const { return cross_levels_; }
    bool finer_units() const { return finer_units_; }
    bool footprint() const { return footprint_; }

    // Whether the meta-cell of `level` >= 1 at `base` (a multiple of 2^level) may be a unit on its
    // own account: complete, and its centre beyond D[level]. A unit also needs no coarser unit
    // around it; level_of() and a top-down walk check that.
    bool coarse_enough(glm::ivec3 base, int level) const {
        const int s = 1 << level;
        if (base.x + s > cell_dims_.x || base.y + s > cell_dims_.y || base.z + s > cell_dims_.z)
            return false;
        const glm::vec3 centre = (glm::vec3(base) + 0.5f * static_cast<float>(s)) * spacing_;
        const glm::vec3 to = centre - eye_;
        const float dist2 = glm::dot(to, to);
        if (!(dist2 > d2_[static_cast<std::size_t>(level)])) return false;
        if (!errors_) return true;
        const float e = errors_->cells(level, base);
        return e * e <= err_k2_ * dist2 + err_c2_;
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
    bool cross_levels_ = false;
    bool finer_units_ = true;
    bool footprint_ = false;
    std::array<float, kMaxMetaLevel + 1> d2_{};  // D[i]^2
    const LodErrors* errors_ = nullptr;          // null: no error rule
    float err_k2_ = 0, err_c2_ = 0;              // the error rule's bound, squared (see above)
};

}  // namespace isowall
