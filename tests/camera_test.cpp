// Camera and frustum math: full views fit, sub-frusta tile the screen exactly.
#include <gtest/gtest.h>

#include <cmath>

#include <random>

#include "core/camera.h"
#include "core/util.h"

namespace isowall {
namespace {

glm::vec3 to_ndc(const glm::mat4& proj, const glm::mat4& view, glm::vec3 p) {
    const glm::vec4 c = proj * view * glm::vec4(p, 1.0f);
    return glm::vec3(c) / c.w;
}

// Pixel coordinates (x right, y down) of p on a screen of w x h.
glm::vec2 to_pixel(const glm::mat4& proj, const glm::mat4& view, glm::vec3 p, int w, int h) {
    const glm::vec3 n = to_ndc(proj, view, p);
    return {(n.x * 0.5f + 0.5f) * float(w), (0.5f - n.y * 0.5f) * float(h)};
}

TEST(Camera, FrontFullViewContainsTheVolume) {
    Box3 b;
    b.merge(glm::vec3(0));
    b.merge(glm::vec3(511, 511, 233));
    for (Projection proj : {Projection::perspective, Projection::orthographic})
        for (float aspect : {4.0f / 3.0f, 0.5f, 1.0f}) {
            const Camera c = front_full_view(b, aspect, proj);
            const glm::mat4 P = c.frustum(aspect).matrix();
            for (int k = 0; k < 8; ++k) {
                const glm::vec3 corner((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y,
                                       (k & 4) ? b.max.z : b.min.z);
                const glm::vec3 n = to_ndc(P, c.view(), corner);
                EXPECT_LE(std::abs(n.x), 1.0f) << c << " aspect " << aspect;
                EXPECT_LE(std::abs(n.y), 1.0f) << c << " aspect " << aspect;
                EXPECT_GT(n.z, -1.0f);
                EXPECT_LT(n.z, 1.0f);
            }
        }
}

TEST(Camera, SubFrustaMapPointsToTheSamePixels) {
    // A 3x2 grid of 100x80 tiles with 10 px gaps between them: the virtual screen is 320x170.
    const int W = 320, H = 170;
    Camera c;
    c.eye = {3, -40, 5};
    c.target = {0, 0, 0};
    c.up = {0, 0, 1};
    c.near_z = 1;
    c.far_z = 100;
    std::mt19937 rng(3);
    for (Projection proj : {Projection::perspective, Projection::orthographic}) {
        c.projection = proj;
        const Frustum full = c.frustum(float(W) / float(H));
        for (int tile = 0; tile < 6; ++tile) {
            const PixelRect r{(tile % 3) * 110, (tile / 3) * 90, 100, 80};
            const Frustum f = sub_frustum(full, W, H, r);
            for (int i = 0; i < 20; ++i) {
                std::uniform_real_distribution<float> u(-8, 8);
                const glm::vec3 p(u(rng), u(rng), u(rng));
                const glm::vec2 whole = to_pixel(full.matrix(), c.view(), p, W, H);
                const glm::vec2 local = to_pixel(f.matrix(), c.view(), p, r.width, r.height);
                EXPECT_NEAR(local.x + float(r.x), whole.x, 1e-3f) << f;
                EXPECT_NEAR(local.y + float(r.y), whole.y, 1e-3f) << f;
            }
        }
    }
}

TEST(Camera, OrbitKeepsDistanceAndZoomMovesCloser) {
    Camera c;
    c.eye = {0, -10, 0};
    c.up = {0, 0, 1};
    const Camera o = orbit(c, 90, 0);
    EXPECT_NEAR(o.distance(), 10.0f, 1e-4f);
    EXPECT_NEAR(o.eye.x, 10.0f, 1e-4f);  // yaw 90 about +z takes -y to +x
    const Camera p = orbit(c, 0, 30);
    EXPECT_NEAR(p.distance(), 10.0f, 1e-4f);
    EXPECT_NEAR(glm::dot(glm::normalize(p.up), glm::normalize(p.target - p.eye)), 0.0f, 1e-5f);
    EXPECT_NEAR(zoom(c, 2).distance(), 5.0f, 1e-5f);
}

TEST(Camera, ClipToPixelIsTheCentresPixelAndNoneBehindTheEyeOrOffTheScreen) {
    // The screen's centre, a corner pixel, the edges (half-open), behind the eye, NaN.
    EXPECT_EQ(clip_to_pixel({0, 0, 0.5f, 1}, 100, 50), glm::ivec2(50, 25));
    EXPECT_EQ(clip_to_pixel({-0.99f, 0.99f, 0, 1}, 100, 50), glm::ivec2(0, 0));
    EXPECT_EQ(clip_to_pixel({-2, 2, 0, 2}, 100, 50), glm::ivec2(0, 0));  // divided by w first
    EXPECT_FALSE(clip_to_pixel({1, 0, 0, 1}, 100, 50).has_value());      // x = width
    EXPECT_FALSE(clip_to_pixel({0, 0, 0, 0}, 100, 50).has_value());
    EXPECT_FALSE(clip_to_pixel({0, 0, 0, -1}, 100, 50).has_value());
    EXPECT_FALSE(clip_to_pixel({NAN, 0, 0, 1}, 100, 50).has_value());
}

TEST(Util, ParseSize) {
    EXPECT_EQ(parse_size("1600x1200"), glm::ivec2(1600, 1200));
    EXPECT_FALSE(parse_size("1600").has_value());
    EXPECT_FALSE(parse_size("0x10").has_value());
    EXPECT_FALSE(parse_size("10x-1").has_value());
    EXPECT_FALSE(parse_size("10x10x").has_value());
    EXPECT_FALSE(parse_size("").has_value());
}

}  // namespace
}  // namespace isowall
