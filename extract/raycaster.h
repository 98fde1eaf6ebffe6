#pragma once
// Seed finding by ray casting (chapter 2.1.1): a front-to-back walk of the min/max octree in voxel
// space, down to the cells of active leaf bricks, which are stepped through in ray order (3D DDA).
//   exact:       the first active cell whose marching-cubes triangles the ray hits (Moller-
//                Trumbore); when a cell's triangles miss, the walk resumes (Figure 2.2).
//   approximate: the first active cell the ray enters (section 3.1.1).
// With a ResolutionMap (adaptive resolution, chapter 2.1.3) the walk stops at the unit a far region
// is extracted at: an octree node, a leaf brick or an eighth of one that is a meta-cell unit is
// tested as one cell (activity and triangles from its eight corners), and a leaf brick holding
// units of several levels is walked by front-to-back subdivision instead of the DDA. Where a
// meta-cell's triangles miss the ray, the exact walk also steps through its cells and reports a
// full-resolution hit as a refinement (RayHit::refine).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/ray.h"
#include "extract/adaptive.h"
#include "extract/marching_cubes.h"
#include "volume/octree.h"

namespace isowall {

enum class IntersectMode { exact, approximate };

struct RayHit {
    bool found = false;
    glm::ivec3 cell{0};  // the cell, or the first cell of the meta-cell
    float t = 0;         // ray parameter of the hit (exact) or of the cell entry (approximate)
    int level = 0;       // 0: a cell; i >= 1: the meta-cell of 2^i cells per side at `cell`
    // Exact walk with adaptive resolution only: the meta-cell's own triangles miss the ray, but
    // its full-resolution triangles are hit (in fine_cell, at t). The meta-cell needs refining
    // for this pixel to show the surface.
    bool refine = false;
    glm::ivec3 fine_cell{0};
};

// glm::clamp on ivec3, written out: GCC 12 left glm's version out of line in the walk (2.5% of a
// render's samples under perf, once per node stepped).
inline glm::ivec3 clamp_cells(glm::ivec3 v, glm::ivec3 lo, glm::ivec3 hi) {
    return {std::min(std::max(v.x, lo.x), hi.x), std::min(std::max(v.y, lo.y), hi.y),
            std::min(std::max(v.z, lo.z), hi.z)};
}

template <class T>
class RayCaster {
  public:
    RayCaster(const VolumeView<T>& volume, const MinMaxOctree<T>& octree)
        : v_(volume), octree_(octree) {}

    // The resolution of the following casts; default-constructed: full resolution.
    void set_resolution(const ResolutionMap& resolution) { resolution_ = resolution; }

    // `ray` in voxel space. Stops at t_max (e.g. the depth already drawn at this pixel).
    RayHit cast(const Ray& ray, double iso, IntersectMode mode,
                float t_max = std::numeric_limits<float>::max()) {
        ray_ = ray;
        inv_d_ = inverse_direction(ray);
        iso_ = iso;
        inside_ = InsideTest<T>(iso);
        mode_ = mode;
        t_max_ = t_max;
        hit_ = {};
        cells_tested_ = 0;
        walk();
        return hit_;
    }
    std::size_t cells_tested() const { return cells_tested_; }

  private:
    // Hierarchical DDA: from the ray's entry into the volume, find the largest octree node around
    // the current point that cannot hold the surface and jump to its exit; where the leaf brick
    // is active, test the coarsest unit around it (adaptive resolution) or step through its
    // cells. Half the time per ray of a recursive front-to-back descent that tests every child's
    // box and sorts the children at every level (full resolution: intersection 0.88 s -> 0.42 s
    // for the 1.05 M rays of vhp_ct_head skin at 1600x1200; with meta-cells, every ray of the
    // same head 0.73 s -> 0.36 s, same groups and triangles).
    void walk() {
        const OctreeShape& shape = octree_.shape();
        float t, t_end;
        if (!intersect_box(ray_, inv_d_, glm::vec3(0), glm::vec3(shape.cell_dims), t, t_end))
            return;
        t = std::max(t, 0.0f);
        t_end = std::min(t_end, t_max_);
        const glm::ivec3 leaf_dims = shape.levels[0].dims;
        const int levels = octree_.level_count();
        // Steps past a node's exit by this much (in cells) to land in the next node; it grows
        // with t so that t + nudge is a different float even far from the eye (a fixed 1e-4 is
        // below one ulp once t passes ~1000, and the walk would never advance).
        auto nudge = [](float at) { return 1e-4f + 4e-7f * std::abs(at); };
        while (t <= t_end) {
            const glm::vec3 p = ray_.at(t + nudge(t));
            const glm::ivec3 brick = clamp_cells(
                glm::ivec3(glm::floor(p)) >> OctreeShape::kLeafLog2, glm::ivec3(0), leaf_dims - 1);
            int skip = -1;  // the highest level whose node around p is inactive
            while (skip + 1 < levels && !octree_.active(skip + 1, brick >> (skip + 1), iso_))
                ++skip;
            // Past an inactive node, or the active unit or brick around p.
            const int unit = skip < 0 ? unit_node(brick) : -1;
            const int level = skip >= 0 ? skip : std::max(unit, 0);
            const glm::ivec3 n = brick >> level;
            float n0, n1;
            intersect_box(ray_, inv_d_, glm::vec3(shape.cell_begin(level, n)),
                          glm::vec3(shape.cell_end(level, n)), n0, n1);
            if (skip < 0 && active_node(unit, n, t, std::min(n1, t_end))) return;
            t = std::max(n1, t + nudge(t));
        }
    }

    // The octree level of the coarsest unit around active leaf brick `brick`, as a descent from
    // the root meets it: a node of level L is a whole meta-cell of level L + kLeafLog2, a unit
    // when coarse enough; -1 when none is (the brick's own cells or meta-cells then).
    int unit_node(glm::ivec3 brick) const {
        const OctreeShape& shape = octree_.shape();
        const int top =
            std::min(octree_.level_count() - 1, resolution_.max_level() - OctreeShape::kLeafLog2);
        for (int level = top; level >= 0; --level)
            if (resolution_.coarse_enough(shape.cell_begin(level, brick >> level),
                                          level + OctreeShape::kLeafLog2))
                return level;
        return -1;
    }

    // Answers the ray in active node `n`, of level `unit` (a unit) or of the leaf level (unit -1),
    // which it crosses from t0 to t1; true when answered (hit found).
    bool active_node(int unit, glm::ivec3 n, float t0, float t1) {
        const OctreeShape& shape = octree_.shape();
        if (unit >= 0) return test_unit(shape.cell_begin(unit, n), unit + OctreeShape::kLeafLog2);
        const glm::ivec3 b = shape.cell_begin(0, n), e = shape.cell_end(0, n);
        if (resolution_.may_coarsen(glm::vec3(b), glm::vec3(e), 1))
            return walk_meta(b, OctreeShape::kLeafLog2);
        return walk_brick(b, e, t0, t1);
    }

    // 3D DDA through the cells of one leaf brick [b, e) from t0 to t1.
    bool walk_brick(glm::ivec3 b, glm::ivec3 e, float t0, float t1) {
        const glm::vec3 p = ray_.at(t0);
        CellWalk walk(ray_, inv_d_, clamp_cells(glm::ivec3(glm::floor(p)), b, e - 1));
        for (;;) {
            if (test_unit(walk.cell, 0)) return true;
            if (!walk.next(b, e, t1)) return false;
        }
    }

    // Front to back through the eight children (meta-cells of level - 1, clipped to the volume)
    // of the meta-cell of `level` at `base`, none of which has a coarser unit around it.
    bool walk_meta(glm::ivec3 base, int level) {
        const int k = level - 1, s = 1 << k;
        const glm::ivec3 dims = octree_.shape().cell_dims;
        std::array<std::pair<float, glm::ivec3>, 8> kids;
        int count = 0;
        for (int i = 0; i < 8; ++i) {
            const glm::ivec3 c = base + s * glm::ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1);
            if (c.x >= dims.x || c.y >= dims.y || c.z >= dims.z) continue;
            float k0, k1;
            if (!intersect_box(ray_, inv_d_, glm::vec3(c), glm::vec3(glm::min(c + s, dims)), k0,
                               k1))
                continue;
            if (k1 < 0 || k0 > t_max_) continue;
            kids[static_cast<std::size_t>(count++)] = {k0, c};
        }
        for (int i = 1; i < count; ++i)
            for (int j = i; j > 0 && kids[static_cast<std::size_t>(j)].first <
                                         kids[static_cast<std::size_t>(j - 1)].first;
                 --j)
                std::swap(kids[static_cast<std::size_t>(j)], kids[static_cast<std::size_t>(j - 1)]);
        for (int i = 0; i < count; ++i) {
            const glm::ivec3 c = kids[static_cast<std::size_t>(i)].second;
            if (k == 0 || resolution_.coarse_enough(c, k)) {
                if (test_unit(c, k)) return true;
            } else if (walk_meta(c, k)) {
                return true;
            }
        }
        return false;
    }

    // A cell (level 0) or a meta-cell unit, judged by its eight corners. The DDA calls this for
    // every cell it steps through, so an inactive cell costs only its classification.
    bool test_unit(glm::ivec3 base, int level) {
        ++cells_tested_;
        const int cs = meta_cell_case(v_, base, level, inside_);
        if (cs != 0 && cs != 255 && hit_unit(base, level)) return true;
        // The meta-cell's triangles miss the ray (or it has none), but the full-resolution
        // surface inside it may not: on a silhouette or across a crack at a resolution boundary
        // a sub-pixel difference uncovers a whole pixel. The exact walk looks at its cells.
        if (level == 0 || mode_ != IntersectMode::exact || !resolution_.refine()) return false;
        const int s = 1 << level;
        float t0, t1;
        intersect_box(ray_, inv_d_, glm::vec3(base), glm::vec3(base + s), t0, t1);
        if (!walk_brick(base, base + s, std::max(t0, 0.0f), std::min(t1, t_max_))) return false;
        hit_.refine = true;
        hit_.fine_cell = hit_.cell;
        hit_.cell = base;
        hit_.level = level;
        return true;
    }

    // Whether the ray hits the active unit: approximate, where it enters the unit; exact, on the
    // unit's triangles no farther than t_max (else the walk resumes past it). Sets hit_.
    bool hit_unit(glm::ivec3 base, int level) {
        if (mode_ == IntersectMode::approximate) {
            float t0, t1;
            intersect_box(ray_, inv_d_, glm::vec3(base), glm::vec3(base + (1 << level)), t0, t1);
            hit_ = {true, base, std::max(t0, 0.0f), level, false, base};
            return true;
        }
        const int count = meta_cell_triangles(v_, base, level, iso_, tris_);
        bool any = false;
        float best = std::numeric_limits<float>::max();
        for (int i = 0; i < count; ++i) {
            float t;
            const auto k = static_cast<std::size_t>(3 * i);
            if (intersect_triangle(ray_, tris_[k], tris_[k + 1], tris_[k + 2], 0.0f, t) &&
                t < best) {
                best = t;
                any = true;
            }
        }
        if (!any || best > t_max_) return false;
        hit_ = {true, base, best, level, false, base};
        return true;
    }

    const VolumeView<T>& v_;
    const MinMaxOctree<T>& octree_;
    Ray ray_;
    glm::vec3 inv_d_{0};
    double iso_ = 0;
    InsideTest<T> inside_{0.0};
    IntersectMode mode_ = IntersectMode::exact;
    float t_max_ = 0;
    RayHit hit_;
    std::size_t cells_tested_ = 0;
    ResolutionMap resolution_;
    std::array<glm::vec3, 3 * mc::kMaxTriangles> tris_{};
};

}  // namespace isowall
