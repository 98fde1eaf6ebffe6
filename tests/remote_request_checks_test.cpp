// What `isowall serve` checks of a request (remote/request_checks.h, class 7 of "Nothing lies,
// nothing hangs, round two"): each rule of a drawable frustum names its field, the isovalue must
// lie in the volume's range, and every frustum that passes has a finite projection matrix and
// finite pixel rays.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "core/ray.h"
#include "remote/request_checks.h"

namespace isowall::remote {
namespace {

Frustum perspective() {
    return {-0.04f, 0.04f, -0.03f, 0.03f, 0.1f, 100.0f, Projection::perspective};
}

bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

TEST(RequestChecks, DegenerateFrustumsNameTheirField) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const struct {
        const char* starts;
        Frustum f;
    } cases[] = {
        {"left: expected a number within 1e+09 of zero, got -1e+38",
         {-1e38f, 0.04f, -0.03f, 0.03f, 0.1f, 100.0f, Projection::perspective}},
        {"far_z: expected a number within 1e+09", {-1, 1, -1, 1, 0.1f, 1e38f}},
        {"top: expected a number within", {-1, 1, -1, nan, 0.1f, 100}},
        {"right: expected more than left (0.5), got 0.5", {0.5f, 0.5f, -1, 1, 0.1f, 100}},
        {"right: expected more than left (1), got -1", {1, -1, -1, 1, 0.1f, 100}},
        {"top: expected more than bottom", {-1, 1, 1, -1, 0.1f, 100}},
        {"near_z: expected at least 1e-09 for a perspective view, got 0", {-1, 1, -1, 1, 0, 100}},
        {"near_z: expected at least 1e-09", {-1, 1, -1, 1, -5, 100}},
        {"far_z: expected more than near_z (100), got 100", {-1, 1, -1, 1, 100, 100}},
        {"right: expected at least 1e-09 more than left",
         {0, 1e-10f, -1, 1, 0.1f, 100, Projection::orthographic}},
        {"far_z: expected at least 1e-09 more than near_z",
         {-1, 1, -1, 1, 0, 1e-10f, Projection::orthographic}},
    };
    for (const auto& c : cases) {
        const std::string p = frustum_problem(c.f);
        EXPECT_EQ(p.rfind(c.starts, 0), 0u) << c.f << ": " << p;
    }
}

TEST(RequestChecks, UsualFrustumsPass) {
    EXPECT_EQ(frustum_problem(perspective()), "");
    EXPECT_EQ(frustum_problem(Frustum{}), "");
    // Orthographic views may begin behind the eye; off-axis tiles lie to one side.
    EXPECT_EQ(frustum_problem({-2, 2, -1.5f, 1.5f, -10, 10, Projection::orthographic}), "");
    EXPECT_EQ(frustum_problem({0.02f, 0.04f, 0.01f, 0.03f, 0.1f, 100}), "");
    // Next to the limits (1e-9 as a float is just under 1e-9).
    EXPECT_EQ(frustum_problem({-1e9f, 1e9f, -1e9f, 1e9f, 2e-9f, 1e9f}), "");
}

// Seeded random frustums over many magnitudes: each one that passes projects and casts finitely.
TEST(RequestChecks, EveryFrustumThatPassesDrawsFinitely) {
    std::mt19937 rng(20240613);
    std::uniform_real_distribution<double> exponent(-12, 12), unit(-1, 1);
    const auto number = [&] { return float(unit(rng) * std::pow(10.0, exponent(rng))); };
    int passed = 0;
    for (int i = 0; i < 200000; ++i) {
        Frustum f{number(), number(), number(), number(), number(), number()};
        f.projection = i % 2 ? Projection::perspective : Projection::orthographic;
        if (!frustum_problem(f).empty()) continue;
        ++passed;
        ASSERT_TRUE(finite(f.matrix())) << f;
        for (const glm::ivec2 px : {glm::ivec2(0, 0), glm::ivec2(799, 599), glm::ivec2(400, 300)}) {
            const Ray r = pixel_ray(glm::mat4(1), f, 800, 600, px);
            ASSERT_TRUE(std::isfinite(r.o.x + r.o.y + r.o.z + r.d.x + r.d.y + r.d.z)) << f;
            ASSERT_GT(glm::length(r.d), 0.5f) << f;
        }
    }
    EXPECT_GT(passed, 1000);
}

TEST(RequestChecks, TheIsovalueLiesInTheVolumesRange) {
    EXPECT_EQ(iso_problem(50, 0, 255), "");
    EXPECT_EQ(iso_problem(0, 0, 255), "");    // the ends are in the range
    EXPECT_EQ(iso_problem(255, 0, 255), "");  // (a surface there is empty, not undrawable)
    EXPECT_EQ(iso_problem(256, 0, 255),
              "expected a value in [0, 255] (the dataset's range), got 256");
    EXPECT_NE(iso_problem(-1e-9, 0, 255), "");
    EXPECT_NE(iso_problem(std::nan(""), 0, 255), "");
    EXPECT_NE(iso_problem(1e300, -1024, 3071), "");
}

}  // namespace
}  // namespace isowall::remote
