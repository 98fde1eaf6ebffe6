#include "extract/mc_tables.h"
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <set>
#include <utility>
#include <vector>

namespace isowall::mc {
namespace {

using Tri = std::array<int, 3>;
using Segment = std::pair<int, int>;  // directed, (edge id, edge id)
using Vec3 = std::array<double, 3>;

bool inside(int mc_case, int corner) {
    return (mc_case >> corner) & 1;
}

bool edge_crossed(int mc_case, int e) {
    return inside(mc_case, kEdgeCorners[e][0]) != inside(mc_case, kEdgeCorners[e][1]);
}

std::vector<Tri> triangles(int mc_case) {
    std::vector<Tri> tris;
    for (int t = 0; t < kTriangleCount[mc_case]; ++t) {
        tris.push_back({kTriangleEdges[mc_case][3 * t], kTriangleEdges[mc_case][3 * t + 1],
                        kTriangleEdges[mc_case][3 * t + 2]});
    }
    return tris;
}

// A cube face is (axis, side): the corners whose bit `axis` equals `side`.
bool edge_on_face(int e, int axis, int side) {
    const int bit = 1 << axis;
    return ((kEdgeCorners[e][0] & bit) != 0) == (side == 1) &&
           ((kEdgeCorners[e][1] & bit) != 0) == (side == 1);
}

bool share_face(int e0, int e1) {
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
            if (edge_on_face(e0, axis, side) && edge_on_face(e1, axis, side)) return true;
        }
    }
    return false;
}

// Triangle sides used by exactly one triangle, in the direction that triangle walks them.
std::vector<Segment> boundary_segments(int mc_case) {
    std::map<Segment, int> undirected;
    for (const Tri& t : triangles(mc_case)) {
        for (int i = 0; i < 3; ++i) {
            const int a = t[i], b = t[(i + 1) % 3];
            ++undirected[{std::min(a, b), std::max(a, b)}];
        }
    }
    std::vector<Segment> boundary;
    for (const Tri& t : triangles(mc_case)) {
        for (int i = 0; i < 3; ++i) {
            const int a = t[i], b = t[(i + 1) % 3];
            if (undirected[{std::min(a, b), std::max(a, b)}] == 1) boundary.push_back({a, b});
        }
    }
    return boundary;
}

std::set<Segment> segments_on_face(int mc_case, int axis, int side) {
    std::set<Segment> out;
    for (const Segment& s : boundary_segments(mc_case)) {
        if (edge_on_face(s.first, axis, side) && edge_on_face(s.second, axis, side)) {
            out.insert(s);
        }
    }
    return out;
}

int find_root(std::array<int, 12>& parent, int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

// Connected pieces of the case's surface (vertices joined by triangle sides).
int component_count(int mc_case) {
    std::array<int, 12> parent{};
    std::iota(parent.begin(), parent.end(), 0);
    for (const Tri& t : triangles(mc_case)) {
        parent[find_root(parent, t[1])] = find_root(parent, t[0]);
        parent[find_root(parent, t[2])] = find_root(parent, t[0]);
    }
    std::set<int> roots;
    for (int e = 0; e < 12; ++e) {
        if (edge_crossed(mc_case, e)) roots.insert(find_root(parent, e));
    }
    return static_cast<int>(roots.size());
}

Vec3 corner_position(int c) {
    return {double(kCornerOffset[c][0]), double(kCornerOffset[c][1]), double(kCornerOffset[c][2])};
}

// With samples +1 inside and -1 outside, linear interpolation puts the vertex at the midpoint.
Vec3 edge_midpoint(int e) {
    const Vec3 a = corner_position(kEdgeCorners[e][0]);
    const Vec3 b = corner_position(kEdgeCorners[e][1]);
    return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
}

Vec3 sub(const Vec3& a, const Vec3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

Vec3 summed_normal(int mc_case) {
    Vec3 n{0, 0, 0};
    for (const Tri& t : triangles(mc_case)) {
        const Vec3 p0 = edge_midpoint(t[0]);
        const Vec3 c = cross(sub(edge_midpoint(t[1]), p0), sub(edge_midpoint(t[2]), p0));
        for (int i = 0; i < 3; ++i) n[i] += c[i];
    }
    return n;
}

TEST(McTables, CornerAndEdgeConventions) {
    for (int c = 0; c < 8; ++c) {
        EXPECT_EQ(kCornerOffset[c][0], c & 1) << "corner " << c;
        EXPECT_EQ(kCornerOffset[c][1], (c >> 1) & 1) << "corner " << c;
        EXPECT_EQ(kCornerOffset[c][2], (c >> 2) & 1) << "corner " << c;
    }
    for (int e = 0; e < 12; ++e) {
        const int axis_bit = 1 << kEdgeAxis[e];
        EXPECT_EQ(kEdgeAxis[e], e / 4) << "edge " << e;
        EXPECT_EQ(kEdgeCorners[e][0] & axis_bit, 0) << "edge " << e << " lower corner";
        EXPECT_EQ(kEdgeCorners[e][1], kEdgeCorners[e][0] | axis_bit) << "edge " << e;
    }
    std::set<std::pair<int, int>> distinct;
    for (const auto& ec : kEdgeCorners) distinct.insert({ec[0], ec[1]});
    EXPECT_EQ(distinct.size(), 12u);
}

TEST(McTables, EmptyAndFullCellsMakeNothing) {
    EXPECT_EQ(kTriangleCount[0], 0);
    EXPECT_EQ(kTriangleCount[255], 0);
    EXPECT_EQ(kTriangleEdges[0][0], -1);
    EXPECT_EQ(kTriangleEdges[255][0], -1);
}

TEST(McTables, VerticesLieOnCrossedEdges) {
    for (int c = 0; c < 256; ++c) {
        for (int i = 0; i < 3 * kTriangleCount[c]; ++i) {
            const int e = kTriangleEdges[c][i];
            ASSERT_TRUE(e >= 0 && e < 12) << "case " << c << " slot " << i << ": " << e;
            EXPECT_TRUE(edge_crossed(c, e)) << "case " << c << " slot " << i << " edge " << e;
        }
    }
}

TEST(McTables, TriangleCountMatchesRow) {
    int max_count = 0;
    for (int c = 0; c < 256; ++c) {
        const int n = kTriangleCount[c];
        max_count = std::max(max_count, n);
        ASSERT_LE(n, kMaxTriangles) << "case " << c;
        int used = 0;
        while (kTriangleEdges[c][used] != -1) ++used;
        EXPECT_EQ(used, 3 * n) << "case " << c;
        for (int i = used; i < 3 * kMaxTriangles + 1; ++i) {
            EXPECT_EQ(kTriangleEdges[c][i], -1) << "case " << c << " slot " << i;
        }
    }
    EXPECT_EQ(max_count, kMaxTriangles);
}

// Inside one cell the triangles must form disks: every triangle side is shared by two
// triangles walking it in opposite directions, or lies on a cube face and belongs to one
// boundary loop. Anything else would leave a hole or a fold the neighbours cannot close.
TEST(McTables, CellSurfaceIsClosedExceptOnFaces) {
    for (int c = 1; c < 255; ++c) {
        std::map<Segment, int> directed;
        for (const Tri& t : triangles(c)) {
            EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
                << "case " << c << " degenerate triangle";
            for (int i = 0; i < 3; ++i) ++directed[{t[i], t[(i + 1) % 3]}];
        }
        std::array<int, 12> out_degree{}, in_degree{};
        std::set<Segment> undirected;
        for (const auto& [seg, count] : directed) {
            const auto [a, b] = seg;
            undirected.insert({std::min(a, b), std::max(a, b)});
            EXPECT_EQ(count, 1) << "case " << c << " side " << a << "->" << b << " repeated";
            if (directed.count({b, a})) continue;  // interior side, walked both ways
            EXPECT_TRUE(share_face(a, b))
                << "case " << c << ": boundary side " << a << "->" << b << " is off the faces";
            ++out_degree[a];
            ++in_degree[b];
        }
        int vertices = 0;
        for (int e = 0; e < 12; ++e) {
            if (!edge_crossed(c, e)) continue;
            ++vertices;
            EXPECT_EQ(out_degree[e], 1) << "case " << c << " edge " << e;
            EXPECT_EQ(in_degree[e], 1) << "case " << c << " edge " << e;
        }
        // Each piece is a disk (Euler characteristic 1), so V - E + F counts the pieces.
        const int euler = vertices - static_cast<int>(undirected.size()) + kTriangleCount[c];
        EXPECT_EQ(euler, component_count(c)) << "case " << c;
    }
}

// Two cells sharing a face see the same four corner signs there; they must put the same
// segments on it, walked in opposite directions, or the mesh cracks along the face.
TEST(McTables, SharedFacesCarryMatchingSegments) {
    int compared = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const int bit = 1 << axis;
        // Edge on the low face of the upper cell -> the same edge on the high face of the lower.
        std::array<int, 12> to_high{};
        to_high.fill(-1);
        for (int e = 0; e < 12; ++e) {
            if (!edge_on_face(e, axis, 0)) continue;
            for (int f = 0; f < 12; ++f) {
                if (kEdgeCorners[f][0] == (kEdgeCorners[e][0] | bit) &&
                    kEdgeCorners[f][1] == (kEdgeCorners[e][1] | bit)) {
                    to_high[e] = f;
                }
            }
            ASSERT_NE(to_high[e], -1) << "axis " << axis << " edge " << e;
        }
        for (int lower = 0; lower < 256; ++lower) {
            for (int upper = 0; upper < 256; ++upper) {
                bool agree = true;
                for (int corner = 0; corner < 8; ++corner) {
                    if ((corner & bit) && inside(lower, corner) != inside(upper, corner ^ bit)) {
                        agree = false;
                    }
                }
                if (!agree) continue;
                ++compared;
                const std::set<Segment> high = segments_on_face(lower, axis, 1);
                std::set<Segment> low_mapped;
                for (const auto& [a, b] : segments_on_face(upper, axis, 0)) {
                    low_mapped.insert({to_high[b], to_high[a]});  // reversed
                }
                EXPECT_EQ(high, low_mapped) << "axis " << axis << ": lower cell case " << lower
                                            << ", upper cell case " << upper;
                bool face_crossed = false;
                for (int e = 0; e < 12; ++e) {
                    if (edge_on_face(e, axis, 1) && edge_crossed(lower, e)) face_crossed = true;
                }
                EXPECT_EQ(!high.empty(), face_crossed) << "axis " << axis << " case " << lower;
            }
        }
    }
    EXPECT_EQ(compared, 3 * 16 * 16 * 16);
}

TEST(McTables, SingleCornerNormalPointsAwayFromIt) {
    // Case 1: corner 0 alone inside; the normal must point toward (1, 1, 1).
    const Vec3 n = summed_normal(1);
    EXPECT_GT(n[0], 0);
    EXPECT_GT(n[1], 0);
    EXPECT_GT(n[2], 0);
    // Case 254: corner 0 alone outside; the normal must point toward corner 0.
    const Vec3 m = summed_normal(254);
    EXPECT_LT(m[0], 0);
    EXPECT_LT(m[1], 0);
    EXPECT_LT(m[2], 0);
}

TEST(McTables, NormalsPointFromInsideToOutside) {
    int checked = 0;
    for (int c = 1; c < 255; ++c) {
        if (component_count(c) != 1) continue;
        ++checked;
        Vec3 in{0, 0, 0}, out{0, 0, 0};
        int n_in = 0, n_out = 0;
        for (int corner = 0; corner < 8; ++corner) {
            Vec3& sum = inside(c, corner) ? in : out;
            (inside(c, corner) ? n_in : n_out) += 1;
            const Vec3 p = corner_position(corner);
            for (int i = 0; i < 3; ++i) sum[i] += p[i];
        }
        Vec3 toward_out{};
        for (int i = 0; i < 3; ++i) toward_out[i] = out[i] / n_out - in[i] / n_in;
        const Vec3 n = summed_normal(c);
        EXPECT_GT(dot(n, toward_out), 0)
            << "case " << c << " normal (" << n[0] << ", " << n[1] << ", " << n[2] << ")";
    }
    EXPECT_GT(checked, 100);
}

}  // namespace
}  // namespace isowall::mc
