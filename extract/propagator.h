#pragma once
// Limited propagation from a seed cell (chapter 2.1.2, section 3.2): breadth first over active
// face neighbours (a face whose four corners straddle the isovalue is crossed by the surface, so
// the cell behind it is active), bounded by
//   max_count:    at most m cells per pass;
//   cutoff_angle: cells whose direction from the eye is more than theta from the seed ray, and
//                 cells where the surface folds back (their distance angle falls below the largest
//                 of their predecessors' by more than the tolerance: Figure 2.5).
// Each pass yields one group: an indexed face set triangulated through the interpolant cache,
// which is reset per pass (section 3.3.4).
// With a ResolutionMap (chapter 2.1.3) a pass runs at the level of its seed's unit: over meta-cells
// of that level (face neighbours at stride 2^level, active by their corner signs), and it stops at
// the resolution boundary: a neighbour that belongs to a unit of another level is not entered.
// A unit is marked visited at its first cell with the pass's group id: units are disjoint, so a
// unit is either wholly visited or not at all, a ray's hit names the unit's first cell, and a
// neighbour that is not the first cell of a unit of the pass's level is not entered anyway.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "core/camera.h"
#include "core/clip.h"
#include "core/sample_cull.h"
#include "extract/adaptive.h"
#include "extract/footprint.h"
#include "extract/group.h"
#include "extract/marching_cubes.h"
#include "extract/visited.h"

namespace isowall {

enum class PropagationMode { max_count, cutoff_angle };

// Keeps a pass to the cells whose projection may touch one screen region (a wall job's region,
// or a tile): `clip_from_voxel` maps voxel space to the clip space of that region's own frustum,
// and a cell is entered when its centre, widened by its projected half-diagonal, falls inside
// NDC [-1, 1]^2. A cell left out stays unvisited, so a later ray that hits it seeds it then: the
// image is the same, but no pass extracts surface that its region cannot show.
struct ScreenClip {
    bool active = false;
    glm::mat4 clip_from_voxel{1.0f};
    float ndc_per_unit = 1;       // max(|P00|, |P11|) of the projection: NDC per view unit at w = 1
    float half_diagonal = 0.87f;  // half the diagonal of one cell, in object units

    bool may_touch(glm::vec3 centre, int stride) const {
        const glm::vec4 c = clip_from_voxel * glm::vec4(centre, 1.0f);
        if (c.w <= 1e-6f) return true;  // at or behind the eye: no bound
        const float r = half_diagonal * float(stride) * ndc_per_unit / c.w;
        return std::abs(c.x / c.w) - r <= 1.0f && std::abs(c.y / c.w) - r <= 1.0f;
    }
};

// The pixel centres of the frame a pass's triangles are drawn into (the whole frame's, not a
// region's). Drawn at one sample a pixel a triangle writes a fragment only where it covers a pixel
// centre, and a unit's triangles lie inside the unit, so a unit whose projected box holds no centre
// has no triangle that could show: it is visited and propagated through, but not triangulated.
// Where cells are smaller than a pixel this is most of them. Only units wholly inside the frame
// are judged: the visited cells of one frame also serve other frames of the same virtual screen
// (a wall rank's jobs for other tiles), whose pixel centres continue this frame's grid outside it.
// Inactive: every unit is triangulated (groups kept for other views, as a remote server's cache
// keeps them).
struct SampleGrid {
    bool active = false;
    glm::mat4 clip_from_voxel{1.0f};  // projection * view * voxel-to-object
    glm::mat4 voxel_from_clip{1.0f};  // its inverse, for the rays of pixel centres
    int width = 0, height = 0;
    // The nearest footprint sample of the frame at each pixel so far (null: none kept), to skip
    // the walks of units behind it.
    SampleDepths* depths = nullptr;

    // Where the unit of `stride` cells at `base` projects.
    enum class Reach { unbounded, past_frame, inside };
    struct WindowBox {
        Reach reach = Reach::unbounded;
        float x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    };
    WindowBox window_box(glm::ivec3 base, int stride) const {
        // The eight corners in clip space: the base corner plus the matrix's columns per axis.
        const glm::vec4 c0 = clip_from_voxel * glm::vec4(glm::vec3(base), 1.0f);
        const glm::vec4 step[3] = {clip_from_voxel[0] * float(stride),
                                   clip_from_voxel[1] * float(stride),
                                   clip_from_voxel[2] * float(stride)};
        WindowBox b;
        b.x0 = b.y0 = std::numeric_limits<float>::max();
        b.x1 = b.y1 = -b.x0;
        for (int k = 0; k < 8; ++k) {
            const glm::vec4 c = c0 + ((k & 1) ? step[0] : glm::vec4(0)) +
                                ((k & 2) ? step[1] : glm::vec4(0)) +
                                ((k & 4) ? step[2] : glm::vec4(0));
            if (!(c.w > 1e-6f)) return b;  // at or behind the eye, or not finite: no bound
            const glm::vec2 w = ndc_to_window(c.x / c.w, c.y / c.w, width, height);
            b.x0 = std::min(b.x0, w.x);
            b.x1 = std::max(b.x1, w.x);
            b.y0 = std::min(b.y0, w.y);
            b.y1 = std::max(b.y1, w.y);
        }
        // A unit reaching past the frame may hold centres of a neighbouring frame (a wall's other
        // tiles, which the same visited cells serve): only a unit wholly inside is judged.
        b.reach = b.x0 < 0 || b.y0 < 0 || b.x1 > float(width) || b.y1 > float(height)
                      ? Reach::past_frame
                      : Reach::inside;
        return b;
    }

    bool may_cover_a_centre(glm::ivec3 base, int stride) const {
        const WindowBox b = window_box(base, stride);
        if (b.reach != Reach::inside) return true;
        return box_holds_a_centre(b.x0, b.x1, b.y0, b.y1, width, height);
    }

    FootprintGrid footprint() const { return {clip_from_voxel, voxel_from_clip, width, height}; }
};

inline constexpr float kRadiansPerDegree = 3.14159265358979f / 180.0f;

struct PropagationParams {
    PropagationMode mode = PropagationMode::max_count;
    // Chosen over every shared volume, not one: scripts/bench_defaults.py times C = 99% (final
    // pixels) for each volume at both README isovalues and each candidate, median of 3 rotated
    // rounds, and picks the value whose worst ratio to each case's best is smallest (ties: the
    // geometric mean). 2000 came from vhp_ct_head alone; the 2026-11-26 sweep picked 1000 (worst
    // ratio 1.68 against 2000's 2.13; docs/benchmarks.md).
    int max_count = 1000;
    float cutoff_rad = 2.0f * kRadiansPerDegree;    // 2 degrees
    float foldback_rad = 0.5f * kRadiansPerDegree;  // 0.5 degree
    bool interpolant_cache = true;
    // Visible-surface rule: a unit where the surface faces away from the eye (the
    // gradient of its corners, against the direction to the eye, has the opposite sign to the
    // seed's, which the seed ray saw from the front) is drawn but not propagated from. A pass
    // then stops one unit past a silhouette instead of running on over the back of the surface;
    // what it leaves out stays unvisited, so a later ray that sees it seeds it then.
    bool facing_only = false;
    // Count mode: a pass that fills max_count lists the units it had to leave out
    // (Group::frontier), so the engine can go on from those its picture still misses
    // (engine/beside_seeds.h).
    bool keep_frontier = false;
    ScreenClip clip;     // inactive: no limit on screen
    SampleGrid samples;  // inactive: every unit triangulated
    // The view's clip planes in object space (core/clip.h): a unit wholly cut away is never
    // entered (it stays unvisited, and no ray reaches it), and the group's triangles are cut at
    // the planes.
    ClipSet cut;
};

// The most frontier units one pass lists: a pass of max_count units has a rim of a few times
// sqrt(max_count) units, each met from one to three taken neighbours.
inline constexpr std::size_t kMaxFrontier = 4096;

// The value gradient of a unit from its eight corners (differences across the unit, voxel space
// per unit side): the direction the surface's normal takes, up to sign.
inline glm::vec3 corner_gradient(const double corner[8]) {
    double g[3] = {0, 0, 0};
    for (std::size_t k = 0; k < 8; ++k)
        for (std::size_t a = 0; a < 3; ++a)
            g[a] += mc::kCornerOffset[k][a] ? corner[k] : -corner[k];
    return {static_cast<float>(g[0]), static_cast<float>(g[1]), static_cast<float>(g[2])};
}

// Without the interpolant cache every triangle gets its own three vertices (the "caching off"
// row of Table 3.4).
struct NoEdgeCache {
    std::pair<std::uint32_t*, bool> find_or_insert(glm::ivec3, int) { return {&scratch, true}; }
    std::uint32_t scratch = 0;
};

template <class T>
class Propagator {
  public:
    explicit Propagator(const VolumeView<T>& v) : v_(v), cache_(v.dims, 4096) {}

    // The resolution of the following passes; default-constructed: full resolution.
    void set_resolution(const ResolutionMap& resolution) { resolution_ = resolution; }

    // Seconds spent triangulating (marching cubes) in the last propagate() call; the rest of the
    // call is the propagation proper (queue, neighbour tests, criteria).
    double last_extract_s() const { return extract_s_; }

    // `eye` and `ray_dir` in voxel space (for the angle criteria). `interrupted` is polled every
    // few hundred cells so a long pass stops promptly when the view changes.
    Group propagate(glm::ivec3 seed, std::uint32_t group_id, double iso, const PropagationParams& p,
                    glm::vec3 eye, glm::vec3 ray_dir, VisitedCells& visited,
                    const std::function<bool()>& interrupted = {}) {
        extract_s_ = 0;
        Group g;
        g.id = group_id;
        const int level = resolution_.level_of(seed);
        const int stride = 1 << level;
        seed &= ~(stride - 1);  // the unit's first cell
        g.seed = seed;
        g.level = level;
        g.iso = iso;
        // A border unit finer than a uniform level's is not this level's (adaptive.h).
        if (!resolution_.finer_units() && level < resolution_.max_level()) return g;
        if (!p.cut.empty() && cut_away(p.cut, unit_box(seed, stride))) return g;
        if (!visited.claim(seed, group_id, level)) return g;
        cache_.clear();
        const glm::vec3 dir = glm::normalize(ray_dir);
        const float cos_cutoff = std::cos(p.cutoff_rad);
        auto centre = [](glm::ivec3 c, int l) { return glm::vec3(c) + 0.5f * float(1 << l); };
        auto angle_of = [&](glm::ivec3 c, int l) {
            const glm::vec3 to = glm::normalize(centre(c, l) - eye);
            return std::acos(std::clamp(glm::dot(to, dir), -1.0f, 1.0f));
        };
        queue_.clear();
        queue_.push_back(
            {seed, p.mode == PropagationMode::cutoff_angle ? angle_of(seed, level) : 0.0f, level});
        double timed_s = 0;
        std::size_t timed_units = 0;
        float seed_facing = 0;  // the seed's side, for facing_only; 0 until the seed is seen
        int taken = 1;
        std::size_t taken_cells = std::size_t{1} << (3 * level);
        const glm::ivec3 cells = visited.dims();
        const InsideTest<T> inside(iso);
        // Takes the unit of `l` at `u` into this pass when the criteria allow; false when the
        // pass is full (count mode).
        auto take = [&](glm::ivec3 u, int l, float from_angle) {
            if (visited.contains(u, l)) return true;
            const int st = 1 << l;
            if (p.clip.active && !p.clip.may_touch(centre(u, l), st)) return true;
            if (!p.cut.empty() && cut_away(p.cut, unit_box(u, st))) return true;
            float max_angle = from_angle;
            if (p.mode == PropagationMode::max_count) {
                if (taken >= p.max_count) {
                    if (p.keep_frontier && g.frontier.size() < kMaxFrontier)
                        g.frontier.push_back(u);
                    return false;
                }
            } else {
                const glm::vec3 to = glm::normalize(centre(u, l) - eye);
                if (glm::dot(to, dir) < cos_cutoff) return true;
                const float a = std::acos(std::clamp(glm::dot(to, dir), -1.0f, 1.0f));
                if (a < from_angle - p.foldback_rad) return true;  // folds back
                max_angle = std::max(max_angle, a);
            }
            // Another thread's pass may have taken it since contains(): the claim decides.
            if (!visited.claim(u, group_id, l)) return true;
            ++taken;
            taken_cells += std::size_t{1} << (3 * l);
            queue_.push_back({u, max_angle, l});
            return true;
        };
        while (!queue_.empty()) {
            const QueueEntry item = queue_.front();
            queue_.pop_front();
            g.cells.push_back(item.cell);
            if (item.level != level && g.cell_levels.empty())
                g.cell_levels.assign(g.cells.size() - 1, static_cast<std::uint8_t>(level));
            if (!g.cell_levels.empty())
                g.cell_levels.push_back(static_cast<std::uint8_t>(item.level));
            if ((g.cells.size() & 255) == 0 && interrupted && interrupted()) break;
            // Two clock reads cost about as much as a small cell's triangulation, so only one
            // unit in kTimedEvery is timed and the pass's extraction time is scaled from them.
            const bool timed = (g.cells.size() - 1) % kTimedEvery == 0;
            const auto t0 =
                timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
            double corner[8];
            // A footprint unit: its crossed faces by its voxels, its picture by its pixels.
            const bool footprint = item.level > 0 && resolution_.footprint();
            int cs = 0, faces = 0;
            if (footprint) {
                const UnitBlock<T> block(v_, item.cell, item.level, inside);
                faces = block.crossed_faces();
                emit_footprint(block, iso, p, g.mesh);
                if (p.facing_only) meta_cell_corners(v_, item.cell, item.level, corner);
            } else {
                const bool shows =
                    !p.samples.active || p.samples.may_cover_a_centre(item.cell, 1 << item.level);
                cs = triangulate(item.cell, item.level, iso, p, g.mesh, corner, shows);
            }
            if (timed) {
                timed_s +=
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                ++timed_units;
            }
            const int stride = 1 << item.level;
            if (p.facing_only) {
                const glm::vec3 to_eye = eye - centre(item.cell, item.level);
                const float facing = glm::dot(corner_gradient(corner), to_eye);
                if (seed_facing == 0) seed_facing = facing;
                if (facing * seed_facing < 0) continue;  // folds away: no neighbours from here
            }
            for (int f = 0; f < 6; ++f) {
                const int axis = f >> 1, side = f & 1;
                if (footprint) {
                    if (!((faces >> f) & 1)) continue;
                } else {
                    // The face's four corners: those with bit `axis` equal to `side`.
                    int on_face = 0;
                    for (int k = 0; k < 8; ++k)
                        if (((k >> axis) & 1) == side) on_face += (cs >> k) & 1;
                    if (on_face == 0 || on_face == 4) continue;  // the surface does not cross it
                }
                // The cell just across the face, at the unit's first corner.
                glm::ivec3 nb = item.cell;
                nb[axis] = side ? nb[axis] + stride : nb[axis] - 1;
                if (nb[axis] < 0 || nb[axis] >= cells[axis]) continue;
                const int nl = resolution_.max_level() > 0 ? resolution_.level_of(nb) : 0;
                if (nl != item.level && !resolution_.cross_levels()) continue;
                if (nl >= item.level)  // one unit across the face, as large or larger
                    take(nb & ~((1 << nl) - 1), nl, item.max_angle);
                else  // finer units (a resolution boundary): the pass goes on into them
                    take_finer_across(nb, axis, f ^ 1, stride, iso, inside, take, item.max_angle);
            }
        }
        visited.add_count(taken_cells);
        clip_mesh(g.mesh, p.cut);
        if (timed_units > 0)
            extract_s_ =
                timed_s * static_cast<double>(g.cells.size()) / static_cast<double>(timed_units);
        return g;
    }

    // The refinement group of the meta-cell of `level` at `base`: its active cells triangulated at
    // full resolution, sharing vertices through the interpolant cache.
    Group refine(glm::ivec3 base, int level, std::uint32_t group_id, double iso,
                 const PropagationParams& p) {
        const auto t0 = std::chrono::steady_clock::now();
        Group g;
        g.id = group_id;
        g.seed = base;
        g.level = level;
        g.iso = iso;
        g.refinement = true;
        cache_.clear();
        triangulate_cells(base, level, iso, p, g.mesh);
        clip_mesh(g.mesh, p.cut);
        extract_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return g;
    }

    // Marks the unit of `level` at `base` (its first cell); false when it was taken already.
    static bool insert(VisitedCells& visited, glm::ivec3 base, int level, std::uint32_t group_id) {
        return visited.insert(base, group_id, level);
    }

  private:
    // The object-space box of the unit of `stride` cells a side at `base`.
    Box3 unit_box(glm::ivec3 base, int stride) const {
        return {glm::vec3(base) * v_.spacing, glm::vec3(base + stride) * v_.spacing};
    }

    static constexpr std::size_t kTimedEvery = 16;

    // Triangulates the unit of `level` at `c` (a cell at level 0), unless not `emit`, and returns
    // its case.
    int triangulate(glm::ivec3 c, int level, double iso, const PropagationParams& p, Mesh& mesh,
                    double corner[8], bool emit = true) {
        meta_cell_corners(v_, c, level, corner);
        const int cs = cell_case(corner, iso);
        if (!emit) return cs;
        if (p.interpolant_cache) {
            emit_meta_cell(v_, c, level, iso, cs, corner, cache_, mesh);
        } else {
            NoEdgeCache none;
            emit_meta_cell(v_, c, level, iso, cs, corner, none, mesh);
        }
        return cs;
    }

    // The cells of the meta-cell of `level` at `base` at full resolution, those that may cover a
    // pixel centre triangulated.
    void triangulate_cells(glm::ivec3 base, int level, double iso, const PropagationParams& p,
                           Mesh& mesh) {
        const int s = 1 << level;
        double corner[8];
        for (int z = 0; z < s; ++z)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) {
                    const glm::ivec3 c = base + glm::ivec3(x, y, z);
                    triangulate(c, 0, iso, p, mesh, corner,
                                !p.samples.active || p.samples.may_cover_a_centre(c, 1));
                }
    }

    // A footprint unit's picture: inside the frame, a sample triangle for each pixel centre whose
    // ray meets the full-resolution surface in it; reaching past the frame (whose neighbouring
    // frames' centres are not known here) or with no sample grid, its cells' full-resolution
    // triangles.
    void emit_footprint(const UnitBlock<T>& block, double iso, const PropagationParams& p,
                        Mesh& mesh) {
        const int s = block.side();
        const glm::ivec3 base = block.base();
        const SampleGrid::WindowBox box =
            p.samples.active ? p.samples.window_box(base, s) : SampleGrid::WindowBox{};
        // A unit a clip plane cuts: its pixels' first hits may lie on the cut side, where the
        // picture shows what lies behind them, so it is drawn whole and cut (clip_mesh).
        if (box.reach != SampleGrid::Reach::inside ||
            (!p.cut.empty() && !keeps_whole(p.cut, unit_box(base, s)))) {
            triangulate_cells(base, block.level(), iso, p, mesh);
            return;
        }
        const FootprintGrid grid = p.samples.footprint();
        unit_cells_.reset(s);
        SampleDepths* depths = p.samples.depths;
        const glm::vec3 centre = glm::vec3(base) + 0.5f * static_cast<float>(s);
        const SampleShape shape =
            SampleShape::at(grid, centre, grid.ray_through(grid.window(centre)).d);
        if (!shape.usable) return;
        // Pixel (x, y) has its centre at (x + 0.5, y + 0.5).
        const int x0 = static_cast<int>(std::ceil(box.x0 - 0.5f));
        const int x1 = static_cast<int>(std::floor(box.x1 - 0.5f));
        const int y0 = static_cast<int>(std::ceil(box.y0 - 0.5f));
        const int y1 = static_cast<int>(std::floor(box.y1 - 0.5f));
        for (int y = std::max(y0, 0); y <= std::min(y1, grid.height - 1); ++y)
            for (int x = std::max(x0, 0); x <= std::min(x1, grid.width - 1); ++x) {
                const Ray ray = grid.centre_ray(x, y);
                const FootprintHit hit =
                    first_hit_in_unit(v_, block, iso, ray, unit_cells_, depths, x, y);
                if (!hit.found) continue;
                append_sample_triangle(hit, shape, v_.spacing, mesh);
                if (depths) depths->take(x, y, hit.t);
            }
    }

    const VolumeView<T>& v_;
    HashEdgeCache cache_;
    UnitCells unit_cells_;  // a footprint unit's cells, shared by its centres' rays
    ResolutionMap resolution_;
    double extract_s_ = 0;
    struct QueueEntry {
        glm::ivec3 cell;  // the unit's first cell
        float max_angle;  // largest distance angle along the path from the seed
        int level;        // the unit's level
    };

    // The units finer than a unit of `stride` cells that touch its face, in the slab of cells
    // at nb[axis] (nb: the cell across the face at the unit's first corner), handed to `take`
    // when their own corners cross the isovalue. Each unit once: at its first cell on the face.
    // `toward`: the face of those units that lies on the shared face.
    template <class Take>
    bool take_finer_across(glm::ivec3 nb, int axis, int toward, int stride, double iso,
                           const InsideTest<T>& inside, Take& take, float from_angle) {
        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        const glm::ivec3 cells = v_.cell_dims();
        for (int j = 0; j < stride && nb[a2] + j < cells[a2]; ++j)
            for (int i = 0; i < stride && nb[a1] + i < cells[a1]; ++i) {
                glm::ivec3 q = nb;
                q[a1] += i;
                q[a2] += j;
                const int l = resolution_.level_of(q);
                const glm::ivec3 u = q & ~((1 << l) - 1);
                if (u[a1] != q[a1] || u[a2] != q[a2]) continue;  // met at its first cell already
                if (l > 0 && resolution_.footprint()) {
                    // A footprint unit, entered where the fine surface crosses into it.
                    if (!face_straddles(v_, u, l, toward, inside)) continue;
                } else {
                    double corner[8];
                    meta_cell_corners(v_, u, l, corner);
                    const int cs = cell_case(corner, iso);
                    if (cs == 0 || cs == 255) continue;
                }
                if (!take(u, l, from_angle)) return false;
            }
        return true;
    }
    std::deque<QueueEntry> queue_;
};

}  // namespace isowall
