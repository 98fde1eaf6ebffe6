// Triangles that cover no pixel centre (core/sample_cull.h): which are kept, and, drawn, that the
// frame is the same with them or without them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/sample_cull.h"

namespace isowall {
namespace {

// A 10x10 frame whose clip matrix maps x, y in [0, 10] to the whole frame (window = object).
glm::mat4 window_clip() {
    return glm::ortho(0.0f, 10.0f, 0.0f, 10.0f, -1.0f, 1.0f);
}

Mesh one_triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    Mesh m;
    m.positions = {a, b, c};
    m.normals.assign(3, glm::vec3(0, 0, 1));
    m.indices = {0, 1, 2};
    return m;
}

std::size_t kept(const Mesh& m, int w = 10, int h = 10, glm::mat4 clip = window_clip()) {
    Mesh out;
    SampleCullScratch scratch;
    return keep_sampled_triangles(m, clip, w, h, out, scratch);
}

TEST(SampleCull, ATriangleOverAPixelCentreIsKept) {
    EXPECT_EQ(kept(one_triangle({2.2f, 2.2f, 0}, {2.8f, 2.2f, 0}, {2.5f, 2.8f, 0})), 1u);
}

TEST(SampleCull, ATriangleBetweenCentresIsLeftOut) {
    // Inside the square between the centres (2.5, 2.5) and (3.5, 3.5), touching neither.
    EXPECT_EQ(kept(one_triangle({2.6f, 2.6f, 0}, {3.4f, 2.6f, 0}, {3.0f, 3.4f, 0})), 0u);
    // A sliver along x = 3 between two rows of centres.
    EXPECT_EQ(kept(one_triangle({0.1f, 3.0f, 0}, {9.9f, 3.0f, 0}, {5.0f, 3.1f, 0})), 0u);
}

TEST(SampleCull, ACentreInTheBoxButOutsideTheTriangleLeavesItOut) {
    // The box [2, 3] x [2, 2.6] holds the centre (2.5, 2.5); the triangle passes under it.
    EXPECT_EQ(kept(one_triangle({2.0f, 2.0f, 0}, {3.0f, 2.6f, 0}, {3.0f, 2.2f, 0})), 0u);
    EXPECT_EQ(kept(one_triangle({2.0f, 2.0f, 0}, {3.0f, 2.2f, 0}, {3.0f, 2.6f, 0})),
              0u);  // wound back
    // The same triangle a little higher covers it.
    EXPECT_EQ(kept(one_triangle({2.0f, 2.4f, 0}, {3.0f, 3.0f, 0}, {3.0f, 2.4f, 0})), 1u);
}

TEST(SampleCull, ACentreOnTheBoxEdgeOrWithinTheMarginKeepsIt) {
    EXPECT_EQ(kept(one_triangle({2.5f, 2.5f, 0}, {2.9f, 2.5f, 0}, {2.7f, 2.9f, 0})), 1u);
    const float m = kSampleCullMarginPx / 2;
    EXPECT_EQ(kept(one_triangle({2.5f + m, 2.5f + m, 0}, {2.9f, 2.5f + m, 0}, {2.7f, 2.9f, 0})),
              1u);
}

TEST(SampleCull, OffTheFrameIsLeftOut) {
    EXPECT_EQ(kept(one_triangle({-3, -3, 0}, {-1, -3, 0}, {-2, -1, 0})), 0u);
    EXPECT_EQ(kept(one_triangle({11, 2, 0}, {14, 2, 0}, {12, 5, 0})), 0u);
    // Covering the whole frame with no vertex inside it: kept.
    EXPECT_EQ(kept(one_triangle({-50, -50, 0}, {60, -50, 0}, {5, 60, 0})), 1u);
}

TEST(SampleCull, BehindTheEyeOrNotFiniteIsKept) {
    const glm::mat4 clip = glm::perspective(glm::radians(60.0f), 1.0f, 0.1f, 100.0f);
    // One vertex behind the eye (z > 0 in view space): the rasteriser clips it, so it stays.
    EXPECT_EQ(kept(one_triangle({0, 0, -1}, {0.001f, 0, -1}, {0, 0, 1}), 10, 10, clip), 1u);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(kept(one_triangle({nan, 2.6f, 0}, {3.4f, 2.6f, 0}, {3.0f, 3.4f, 0})), 1u);
}

TEST(SampleCull, KeptTrianglesKeepTheirVerticesAndNormalsOnly) {
    Mesh m;
    m.positions = {{2.2f, 2.2f, 0}, {2.8f, 2.2f, 0}, {2.5f, 2.8f, 0},
                   {2.6f, 2.6f, 0}, {3.4f, 2.6f, 0}, {3.0f, 3.4f, 0}};
    for (int i = 0; i < 6; ++i) m.normals.push_back(glm::vec3(float(i), 0, 1));
    m.indices = {3, 4, 5, 0, 1, 2, 2, 1, 0};  // left out, kept, kept (the same vertices)
    Mesh out;
    SampleCullScratch scratch;
    EXPECT_EQ(keep_sampled_triangles(m, window_clip(), 10, 10, out, scratch), 2u);
    ASSERT_EQ(out.positions.size(), 3u);
    EXPECT_EQ(out.normals[0].x, 0.0f);
    EXPECT_EQ(out.indices, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 0}));
    // The output is rebuilt on every call.
    EXPECT_EQ(
        keep_sampled_triangles(one_triangle({0.1f, 0.1f, 0}, {0.2f, 0.1f, 0}, {0.1f, 0.2f, 0}),
                               window_clip(), 10, 10, out, scratch),
        0u);
    EXPECT_TRUE(out.positions.empty());
}

}  // namespace
}  // namespace isowall
