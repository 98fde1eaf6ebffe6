// Clip planes as values (core/clip.h): the operator's text, the part of a ray the planes keep,
// boxes wholly cut or wholly kept, and meshes cut at the planes with nothing left beyond them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/clip.h"

namespace isowall {
namespace {

ClipPlane parsed(const char* text) {
    std::string problem;
    const auto p = parse_clip_plane(text, problem);
    EXPECT_TRUE(p) << text << ": " << problem;
    return p.value_or(ClipPlane{});
}

TEST(ClipPlanes, AxisAndGeneralPlanesKeepTheSideTheyName) {
    const ClipPlane below = parsed("x<60");
    EXPECT_GE(below.side({59.5f, 0, 0}), 0);
    EXPECT_LT(below.side({60.5f, 0, 0}), 0);
    const ClipPlane above = parsed(" z > -4.5 ");
    EXPECT_GE(above.side({0, 0, -4}), 0);
    EXPECT_LT(above.side({0, 0, -5}), 0);
    const ClipPlane diagonal = parsed("1,1,0>10");
    EXPECT_NEAR(glm::length(diagonal.normal), 1.0f, 1e-6f);
    EXPECT_GE(diagonal.side({6, 5, 0}), 0);
    EXPECT_LT(diagonal.side({4, 5, 0}), 0);
    ClipSet two;
    two.add(below);
    two.add(above);
    EXPECT_EQ(clip_text(two), "x<60 z>-4.5");
    EXPECT_EQ(clip_text(ClipSet{}), "");
    // The operator's form reads back to the same plane.
    for (const ClipPlane& p : {below, above, diagonal}) {
        const ClipPlane again = parsed(clip_plane_text(p).c_str());
        EXPECT_NEAR(glm::length(again.normal - p.normal), 0.0f, 1e-6f) << clip_plane_text(p);
        EXPECT_NEAR(again.at, p.at, 1e-4f) << clip_plane_text(p);
    }
}

TEST(ClipPlanes, BadTextNamesWhatIsWrong) {
    for (const char* text : {"", "x", "x<", "x<<3", "x<3>2", "w<3", "x<abc", "0,0,0<1", "1,2<3",
                             "x<1e7", "1e9,0,0<1", "x<nan", "x<inf"}) {
        std::string problem;
        EXPECT_FALSE(parse_clip_plane(text, problem)) << text;
        EXPECT_FALSE(problem.empty()) << text;
    }
    std::string problem;
    EXPECT_FALSE(clip_box({0, 0, 0}, {10, 0, 10}, problem));
    EXPECT_NE(problem.find("Y0 < Y1"), std::string::npos) << problem;
    const auto box = clip_box({1, 2, 3}, {4, 5, 6}, problem);
    ASSERT_TRUE(box);
    EXPECT_EQ(box->count, 6u);
    EXPECT_TRUE(box->keeps({2, 3, 4}));
    EXPECT_FALSE(box->keeps({2, 3, 7}));
}

TEST(ClipPlanes, ARayStartsWhereItEntersTheKeptSpace) {
    const Ray ray{{0, 0, 0}, {2, 0, 0}};  // t counts half units of x
    ClipSet beyond;
    beyond.add(parsed("x>10"));
    auto s = kept_span(beyond, ray);
    ASSERT_TRUE(s);
    EXPECT_FLOAT_EQ(s->t0, 5);
    EXPECT_TRUE(std::isinf(s->t1));
    ClipSet slab = beyond;
    slab.add(parsed("x<30"));
    s = kept_span(slab, ray);
    ASSERT_TRUE(s);
    EXPECT_FLOAT_EQ(s->t1, 15);
    const auto c = clip_ray(slab, ray);
    ASSERT_TRUE(c);
    EXPECT_FLOAT_EQ(c->ray.o.x, 10);
    EXPECT_FLOAT_EQ(c->t_max, 10);
    ClipSet none = beyond;
    none.add(parsed("x<5"));
    EXPECT_FALSE(kept_span(none, ray));
    EXPECT_FALSE(clip_ray(none, ray));
    ClipSet aside;  // parallel to the ray, on the cut side
    aside.add(parsed("y>1"));
    EXPECT_FALSE(kept_span(aside, ray));
    const auto whole = clip_ray(ClipSet{}, ray);
    ASSERT_TRUE(whole);
    EXPECT_EQ(whole->t_max, std::numeric_limits<float>::max());
}

TEST(ClipPlanes, BoxesWhollyCutAndWhollyKept) {
    ClipSet c;
    c.add(parsed("x<10"));
    const Box3 left{{0, 0, 0}, {5, 5, 5}}, across{{8, 0, 0}, {12, 5, 5}},
        right{{11, 0, 0}, {15, 5, 5}};
    EXPECT_TRUE(keeps_whole(c, left));
    EXPECT_FALSE(cut_away(c, left));
    EXPECT_FALSE(keeps_whole(c, across));
    EXPECT_FALSE(cut_away(c, across));
    EXPECT_FALSE(keeps_whole(c, right));
    EXPECT_TRUE(cut_away(c, right));
    EXPECT_TRUE(keeps_some_voxel(c, {20, 20, 20}));
    ClipSet past;
    past.add(parsed("x>25"));
    EXPECT_FALSE(keeps_some_voxel(past, {20, 20, 20}));
    // Planes that each keep part of the box but keep nothing of it together.
    c.add(parsed("x>15"));
    EXPECT_FALSE(keeps_some_voxel(c, {20, 20, 20}));
    // A wedge: x + y > 30 and x < 12 meet inside the 20^3 box only where y > 18.
    ClipSet wedge;
    wedge.add(parsed("1,1,0>30"));
    wedge.add(parsed("x<12"));
    EXPECT_TRUE(keeps_some_voxel(wedge, {20, 20, 20}));
    EXPECT_FALSE(keeps_some_voxel(wedge, {20, 18, 20}));  // y at most 17
    EXPECT_TRUE(keeps_some_voxel(ClipSet{}, {20, 20, 20}));
}

TEST(ClipPlanes, VoxelPlanesInObjectSpaceFollowTheSpacing) {
    ClipSet voxel;
    voxel.add(parsed("x<10"));
    voxel.add(parsed("1,0,1>8"));
    const ClipSet object = in_object_space(voxel, {2, 1, 0.5f});
    for (const glm::vec3 v : {glm::vec3(9, 0, 4), glm::vec3(11, 0, 4), glm::vec3(2, 3, 5),
                              glm::vec3(5, 0, 2.5f), glm::vec3(3, 0, 6)})
        EXPECT_EQ(voxel.keeps(v), object.keeps(v * glm::vec3(2, 1, 0.5f))) << v.x << "," << v.z;
}

double area(const Mesh& m) {
    double a = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::vec3 p = m.positions[m.indices[t]], q = m.positions[m.indices[t + 1]],
                        r = m.positions[m.indices[t + 2]];
        a += 0.5 * glm::length(glm::cross(q - p, r - p));
    }
    return a;
}

TEST(ClipPlanes, AMeshIsCutAtThePlanesAndKeepsItsArea) {
    // A 10 x 10 square of 200 triangles on z = 0, normals +z.
    Mesh m;
    for (int y = 0; y <= 10; ++y)
        for (int x = 0; x <= 10; ++x) {
            m.positions.push_back({x, y, 0});
            m.normals.push_back({0, 0, 1});
        }
    for (std::uint32_t y = 0; y < 10; ++y)
        for (std::uint32_t x = 0; x < 10; ++x) {
            const std::uint32_t i = y * 11 + x;
            m.indices.insert(m.indices.end(), {i, i + 1, i + 12, i, i + 12, i + 11});
        }
    ClipSet c;
    c.add(parsed("x<3.3"));
    c.add(parsed("1,1,0>4"));  // a diagonal through the triangles
    Mesh cut = m;
    clip_mesh(cut, c);
    ASSERT_FALSE(cut.empty());
    for (const std::uint32_t i : cut.indices)
        for (const ClipPlane& p : c) EXPECT_GE(p.side(cut.positions[i]), -1e-4f);
    for (const glm::vec3& n : cut.normals) EXPECT_NEAR(n.z, 1.0f, 1e-6f);
    // The kept part: x in [0, 3.3], y in [0, 10], above x + y = 4.
    const double want = 3.3 * 10 - (4 * 4 - 0.7 * 0.7) / 2;
    EXPECT_NEAR(area(cut), want, 1e-3);
    std::vector<bool> used(cut.vertex_count());  // vertices of no kept triangle are gone
    for (const std::uint32_t i : cut.indices) used[i] = true;
    EXPECT_EQ(std::count(used.begin(), used.end(), false), 0);
    Mesh same = m;
    clip_mesh(same, ClipSet{});
    EXPECT_EQ(same.indices, m.indices);
}

}  // namespace
}  // namespace isowall
