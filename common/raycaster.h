#pragma once
// Seed finding by ray casting (chapter 2.1.1): a front-to-back walk of the min/max octree in voxel
// space, down to the cells of active leaf bricks, which are stepped through in ray order (3D DDA).
//   exact:       the first active cell whose marching-cubes triangles the ray hits (Moller-
//                Trumbore); when a cell's triangles miss, the walk resumes (Figure 2.2).
//   approximate: the first active cell the ray enters (section 3.1.1).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "common/marching_cubes.h"
#include "common/octree.h"
#include "common/ray.h"

namespace isowall {

enum class IntersectMode { exact, approximate };

struct RayHit {
    bool found = false;
    glm::ivec3 cell{0};
    float t = 0;  // ray parameter of the hit (exact) or of the cell entry (approximate)
};

// The triangles of cell c in voxel space (three vertices each); returns the triangle count.
template <class T>
int cell_triangles(const VolumeView<T>& v, glm::ivec3 c, double iso,
                   std::array<glm::vec3, 3 * mc::kMaxTriangles>& out) {
    double corner[8];
    cell_corners(v, c, corner);
    const int cs = cell_case(corner, iso);
    const int count = mc::kTriangleCount[static_cast<std::size_t>(cs)];
    const auto& edges = mc::kTriangleEdges[static_cast<std::size_t>(cs)];
    for (int i = 0; i < 3 * count; ++i) {
        const auto e = static_cast<std::size_t>(edges[static_cast<std::size_t>(i)]);
        const int ca = mc::kEdgeCorners[e][0], cb = mc::kEdgeCorners[e][1];
        const auto& oa = mc::kCornerOffset[static_cast<std::size_t>(ca)];
        glm::vec3 p = glm::vec3(c + glm::ivec3(oa[0], oa[1], oa[2]));
        p[mc::kEdgeAxis[e]] += static_cast<float>((iso - corner[ca]) / (corner[cb] - corner[ca]));
        out[static_cast<std::size_t>(i)] = p;
    }
    return count;
}

template <class T>
class RayCaster {
public:
    RayCaster(const VolumeView<T>& volume, const MinMaxOctree<T>& octree)
        : v_(volume), octree_(octree) {}

    // `ray` in voxel space. Stops at t_max (e.g. the depth already drawn at this pixel).
    RayHit cast(const Ray& ray, double iso, IntersectMode mode,
                float t_max = std::numeric_limits<float>::max()) {
        ray_ = ray;
        for (int a = 0; a < 3; ++a)
            inv_d_[a] = std::abs(ray.d[a]) > 1e-20f ? 1.0f / ray.d[a] : std::copysign(1e30f, ray.d[a]);
        iso_ = iso;
        mode_ = mode;
        t_max_ = t_max;
        hit_ = {};
        cells_tested_ = 0;
        visit(octree_.level_count() - 1, glm::ivec3(0));
        return hit_;
    }
    std::size_t cells_tested() const { return cells_tested_; }

private:
    // Returns true when the ray has been answered (hit found or walk ended).
    bool visit(int level, glm::ivec3 n) {
        const OctreeShape& shape = octree_.shape();
        const glm::ivec3 b = shape.cell_begin(level, n), e = shape.cell_end(level, n);
        float t0, t1;
        if (!intersect_box(ray_, inv_d_, glm::vec3(b), glm::vec3(e), t0, t1)) return false;
        if (t1 < 0 || t0 > t_max_) return false;
        if (!octree_.active(level, n, iso_)) return false;
        if (level == 0) return walk_brick(b, e, std::max(t0, 0.0f), std::min(t1, t_max_));
        // Children front to back: sort by entry parameter.
        const auto& below = shape.levels[static_cast<std::size_t>(level - 1)];
        const glm::ivec3 c0 = 2 * n, c1 = glm::min(c0 + 2, below.dims);
        std::array<std::pair<float, glm::ivec3>, 8> kids;
        int count = 0;
        for (int z = c0.z; z < c1.z; ++z)
            for (int y = c0.y; y < c1.y; ++y)
                for (int x = c0.x; x < c1.x; ++x) {
                    const glm::ivec3 k(x, y, z);
                    float k0, k1;
                    if (!intersect_box(ray_, inv_d_, glm::vec3(shape.cell_begin(level - 1, k)),
                                       glm::vec3(shape.cell_end(level - 1, k)), k0, k1))
                        continue;
                    if (k1 < 0 || k0 > t_max_) continue;
                    kids[static_cast<std::size_t>(count++)] = {k0, k};
                }
        // Insertion sort: at most eight children.
        for (int i = 1; i < count; ++i)
            for (int j = i; j > 0 && kids[static_cast<std::size_t>(j)].first <
                                         kids[static_cast<std::size_t>(j - 1)].first;
                 --j)
                std::swap(kids[static_cast<std::size_t>(j)], kids[static_cast<std::size_t>(j - 1)]);
        for (int i = 0; i < count; ++i)
            if (visit(level - 1, kids[static_cast<std::size_t>(i)].second)) return true;
        return false;
    }

    // 3D DDA through the cells of one leaf brick [b, e) from t0 to t1.
    bool walk_brick(glm::ivec3 b, glm::ivec3 e, float t0, float t1) {
        const glm::vec3 p = ray_.at(t0);
        glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor(p)), b, e - 1);
        glm::ivec3 step;
        glm::vec3 t_next, t_delta;
        for (int a = 0; a < 3; ++a) {
            if (ray_.d[a] > 0) {
                step[a] = 1;
                t_next[a] = (static_cast<float>(c[a] + 1) - ray_.o[a]) * inv_d_[a];
                t_delta[a] = inv_d_[a];
            } else if (ray_.d[a] < 0) {
                step[a] = -1;
                t_next[a] = (static_cast<float>(c[a]) - ray_.o[a]) * inv_d_[a];
                t_delta[a] = -inv_d_[a];
            } else {
                step[a] = 0;
                t_next[a] = std::numeric_limits<float>::max();
                t_delta[a] = std::numeric_limits<float>::max();
            }
        }
        const InsideTest<T> inside(iso_);
        for (;;) {
            ++cells_tested_;
            if (test_cell(c, inside)) return true;
            const int a = t_next.x < t_next.y ? (t_next.x < t_next.z ? 0 : 2)
                                              : (t_next.y < t_next.z ? 1 : 2);
            if (t_next[a] > t1) return false;
            c[a] += step[a];
            if (c[a] < b[a] || c[a] >= e[a]) return false;
            t_next[a] += t_delta[a];
        }
    }

    bool test_cell(glm::ivec3 c, const InsideTest<T>& inside) {
        const std::size_t base = v_.index(c.x, c.y, c.z);
        const std::size_t sy = static_cast<std::size_t>(v_.dims.x);
        const std::size_t sz = sy * static_cast<std::size_t>(v_.dims.y);
        const int n = inside(v_.data[base]) + inside(v_.data[base + 1]) + inside(v_.data[base + sy]) +
                      inside(v_.data[base + sy + 1]) + inside(v_.data[base + sz]) +
                      inside(v_.data[base + sz + 1]) + inside(v_.data[base + sz + sy]) +
                      inside(v_.data[base + sz + sy + 1]);
        if (n == 0 || n == 8) return false;
        if (mode_ == IntersectMode::approximate) {
            float t0, t1;
            intersect_box(ray_, inv_d_, glm::vec3(c), glm::vec3(c + 1), t0, t1);
            hit_ = {true, c, std::max(t0, 0.0f)};
            return true;
        }
        const int count = cell_triangles(v_, c, iso_, tris_);
        bool any = false;
        float best = std::numeric_limits<float>::max();
        for (int i = 0; i < count; ++i) {
            float t;
            const auto k = static_cast<std::size_t>(3 * i);
            if (intersect_triangle(ray_, tris_[k], tris_[k + 1], tris_[k + 2], 0.0f, t) && t < best) {
                best = t;
                any = true;
            }
        }
        if (!any || best > t_max_) return false;  // the walk resumes past this cell
        hit_ = {true, c, best};
        return true;
    }

    const VolumeView<T>& v_;
    const MinMaxOctree<T>& octree_;
    Ray ray_;
    glm::vec3 inv_d_{0};
    double iso_ = 0;
    IntersectMode mode_ = IntersectMode::exact;
    float t_max_ = 0;
    RayHit hit_;
    std::size_t cells_tested_ = 0;
    std::array<glm::vec3, 3 * mc::kMaxTriangles> tris_{};
};

}  // namespace isowall
