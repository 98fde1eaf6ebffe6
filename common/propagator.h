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
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <vector>

#include <glm/geometric.hpp>

#include "common/marching_cubes.h"
#include "common/visited.h"

namespace isowall {

enum class PropagationMode { max_count, cutoff_angle };

struct PropagationParams {
    PropagationMode mode = PropagationMode::max_count;
    int max_count = 8000;
    float cutoff_rad = 0.0349f;    // 2 degrees
    float foldback_rad = 0.0087f;  // 0.5 degree
    bool interpolant_cache = true;
};

struct Group {
    std::uint32_t id = 0;
    glm::ivec3 seed{0};
    Mesh mesh;  // object space
    std::vector<glm::ivec3> cells;  // the cells this pass took, in BFS order
};

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
        g.seed = seed;
        if (!visited.insert(seed, group_id)) return g;
        cache_.clear();
        const glm::vec3 dir = glm::normalize(ray_dir);
        const float cos_cutoff = std::cos(p.cutoff_rad);
        auto angle_of = [&](glm::ivec3 c) {
            const glm::vec3 to = glm::normalize(glm::vec3(c) + 0.5f - eye);
            return std::acos(std::clamp(glm::dot(to, dir), -1.0f, 1.0f));
        };
        queue_.clear();
        queue_.push_back({seed, p.mode == PropagationMode::cutoff_angle ? angle_of(seed) : 0.0f});
        int taken = 1;
        const glm::ivec3 cells = visited.dims();
        while (!queue_.empty()) {
            const QueueEntry item = queue_.front();
            queue_.pop_front();
            g.cells.push_back(item.cell);
            if ((g.cells.size() & 255) == 0 && interrupted && interrupted()) break;
            const auto t0 = std::chrono::steady_clock::now();
            const int cs = triangulate(item.cell, iso, p, g.mesh);
            extract_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            for (int f = 0; f < 6; ++f) {
                const int axis = f >> 1, side = f & 1;
                // The face's four corners: those with bit `axis` equal to `side`.
                int on_face = 0;
                for (int k = 0; k < 8; ++k)
                    if (((k >> axis) & 1) == side) on_face += (cs >> k) & 1;
                if (on_face == 0 || on_face == 4) continue;  // the surface does not cross it
                glm::ivec3 nb = item.cell;
                nb[axis] += side ? 1 : -1;
                if (nb[axis] < 0 || nb[axis] >= cells[axis]) continue;
                if (visited.contains(nb)) continue;
                float max_angle = item.max_angle;
                if (p.mode == PropagationMode::max_count) {
                    if (taken >= p.max_count) continue;
                } else {
                    const glm::vec3 to = glm::normalize(glm::vec3(nb) + 0.5f - eye);
                    if (glm::dot(to, dir) < cos_cutoff) continue;
                    const float a = std::acos(std::clamp(glm::dot(to, dir), -1.0f, 1.0f));
                    if (a < item.max_angle - p.foldback_rad) continue;  // folds back
                    max_angle = std::max(max_angle, a);
                }
                visited.insert(nb, group_id);
                ++taken;
                queue_.push_back({nb, max_angle});
            }
        }
        return g;
    }

private:
    int triangulate(glm::ivec3 c, double iso, const PropagationParams& p, Mesh& mesh) {
        double corner[8];
        cell_corners(v_, c, corner);
        const int cs = cell_case(corner, iso);
        if (p.interpolant_cache) {
            emit_cell(v_, c, iso, cs, corner, cache_, mesh);
        } else {
            NoEdgeCache none;
            emit_cell(v_, c, iso, cs, corner, none, mesh);
        }
        return cs;
    }

    const VolumeView<T>& v_;
    HashEdgeCache cache_;
    double extract_s_ = 0;
    struct QueueEntry {
        glm::ivec3 cell;
        float max_angle;  // largest distance angle along the path from the seed
    };
    std::deque<QueueEntry> queue_;
};

}  // namespace isowall
