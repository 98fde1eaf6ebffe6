// Degenerate views: an up parallel to the view, eye on target, angles far past a turn, zooms
// and pans that leave float precision. Every case either gives a finite view or says why not.
#include <gtest/gtest.h>

#include <cmath>

#include "core/camera.h"

namespace isowall {
namespace {

bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

Camera looking(glm::vec3 eye, glm::vec3 target, glm::vec3 up) {
    Camera c;
    c.eye = eye;
    c.target = target;
    c.up = up;
    return c;
}

TEST(CameraDegenerate, AnUpAlongTheViewIsReplacedAndEveryOperationStaysFinite) {
    const glm::vec3 t(10, 20, 30);
    const std::vector<Camera> cases = {
        looking(t + glm::vec3(0, 0, 50), t, {0, 0, 1}),   // straight down the up vector
        looking(t - glm::vec3(0, 0, 50), t, {0, 0, 1}),   // straight up it
        looking(t + glm::vec3(0, 0, 50), t, {0, 0, -7}),  // any length
        looking(t + glm::vec3(50, 0, 0), t, {1, 0, 0}),
        looking(t + glm::vec3(0, 50, 0), t, {0, 0, 0}),      // no up at all
        looking(t + glm::vec3(0, 0, 50), t, {1e-6f, 0, 1}),  // within rounding of parallel
    };
    for (const Camera& c : cases) {
        const glm::vec3 forward = c.target - c.eye;
        const glm::vec3 up = valid_up(forward, c.up);
        EXPECT_GT(glm::length(glm::cross(glm::normalize(forward), glm::normalize(up))), 0.5f) << c;
        EXPECT_TRUE(finite(c.view())) << c;
        EXPECT_TRUE(finite(pan(c, 0.3f, -0.2f, 1.5f).view())) << c;
        const Camera o = orbit(c, 30, 20);
        EXPECT_TRUE(finite(o.view())) << o;
        EXPECT_NEAR(o.distance(), c.distance(), 1e-3f) << o;
        EXPECT_EQ(camera_problem(c), "") << c;
    }
    // The documented choice: +z, or +y when the view runs along z.
    EXPECT_EQ(valid_up({0, 0, -1}, {0, 0, 1}), glm::vec3(0, 1, 0));
    EXPECT_EQ(valid_up({1, 0, 0}, {1, 0, 0}), glm::vec3(0, 0, 1));
    EXPECT_EQ(valid_up({1, 0, 0}, {0, 1, 0}), glm::vec3(0, 1, 0));  // a good up is kept
}

TEST(CameraDegenerate, EyeOnTargetAndPointsBeyondPrecisionAreNamed) {
    struct Case {
        glm::vec3 eye, target;
        const char* mentions;  // empty: fine
    };
    const float nan = std::nanf(""), inf = INFINITY;
    const std::vector<Case> cases = {
        {{0, 0, 0}, {0, 0, 0}, "the same point"},
        {{5, 5, 5}, {5, 5, 5}, "the same point"},
        {{1000, 0, 0}, {1000.01f, 0, 0}, "apart"},  // 1e-5 of the distance from the origin
        {{0, 0, 0}, {1e-5f, 0, 0}, "apart"},
        {{nan, 0, 0}, {0, 0, 0}, "not a finite point"},
        {{0, 0, 0}, {0, inf, 0}, "not a finite point"},
        {{0, 0, 0}, {0, 0, 1}, ""},
        {{1000, 0, 0}, {1001, 0, 0}, ""},
    };
    for (const Case& c : cases) {
        const std::string p = eye_target_problem(c.eye, c.target);
        const Camera shown = looking(c.eye, c.target, {0, 0, 1});
        if (*c.mentions == 0)
            EXPECT_EQ(p, "") << shown;
        else
            EXPECT_NE(p.find(c.mentions), std::string::npos) << shown << ": " << p;
    }
}

TEST(CameraDegenerate, OrbitReducesAnglesModulo360) {
    Camera c = looking({0, -10, 0}, {0, 0, 0}, {0, 0, 1});
    const std::vector<std::pair<double, double>> same = {
        {720.5, 0.5}, {-359, 1}, {1e6, 280}, {-1e6, 80}, {360.0 * 1000 + 45, 45}};
    for (const auto& [big, small] : same) {
        const Camera a = orbit(c, big, big), b = orbit(c, small, small);
        EXPECT_NEAR(glm::length(a.eye - b.eye), 0.0f, 1e-4f) << big << " vs " << small;
    }
}

TEST(CameraDegenerate, ZoomsAndPansThatLeavePrecisionAreNamed) {
    Box3 b;
    b.merge(glm::vec3(0));
    b.merge(glm::vec3(64, 64, 64));
    for (Projection proj : {Projection::perspective, Projection::orthographic}) {
        const Camera front = front_full_view(b, 4.0f / 3.0f, proj);
        EXPECT_EQ(camera_problem(front), "");
        EXPECT_EQ(camera_problem(zoom(front, 1e-6f)), "") << front;  // far away is fine
        EXPECT_EQ(camera_problem(zoom(front, 100)), "");
        EXPECT_NE(camera_problem(zoom(front, 1e6f)), "") << zoom(front, 1e6f);
        EXPECT_NE(camera_problem(zoom(zoom(front, 1e3f), 1e3f)), "");  // a run of zooms
        Camera far = front;
        for (int i = 0; i < 40; ++i) far = pan(far, 1e3f, 0, 1.0f);  // a run of pans
        EXPECT_NE(camera_problem(far), "") << far;
    }
}

}  // namespace
}  // namespace isowall
