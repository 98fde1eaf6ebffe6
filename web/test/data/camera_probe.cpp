// Prints the camera numbers web/test/camera.test.mjs checks (JSON), from core/camera.cpp.
#include <cstdio>
#include <glm/gtx/io.hpp>
#include "core/camera.h"
using namespace isowall;
static void vec(const char* k, glm::vec3 v) {
    std::printf("\"%s\":[%.9g,%.9g,%.9g],", k, v.x, v.y, v.z);
}
static void mat(const char* k, const glm::mat4& m) {
    std::printf("\"%s\":[", k);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) std::printf("%.9g%s", m[c][r], c == 3 && r == 3 ? "" : ",");
    std::printf("],");
}
int main() {
    struct Case {
        Box3 b;
        int w, h;
        double yaw, pitch;
        float zoom;
        int proj;
    };
    Case cases[] = {
        {{{0, 0, 0}, {199, 183, 167}}, 800, 600, 0, 0, 1, 0},
        {{{0, 0, 0}, {199, 183, 167}}, 800, 600, -32.00000000000034, -12, 1, 0},
        {{{0, 0, 0}, {199, 183, 167}}, 640, 480, 137.5, 63.25, 1.7f, 0},
        {{{-1, -2, -3}, {4, 5, 6}}, 300, 700, 720.5, -89, 0.5f, 0},
        {{{0, 0, 0}, {255, 255, 112}}, 1024, 768, -170, 45, 3.0f, 1},
    };
    std::printf("[");
    for (std::size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        const Case& k = cases[i];
        const float aspect = float(k.w) / float(k.h);
        Camera c = front_full_view(k.b, aspect,
                                   k.proj ? Projection::orthographic : Projection::perspective);
        std::printf(
            "{\"min\":[%g,%g,%g],\"max\":[%g,%g,%g],\"w\":%d,\"h\":%d,\"yaw\":%.17g,\"pitch\":%."
            "17g,\"zoom\":%.9g,\"proj\":%d,",
            k.b.min.x, k.b.min.y, k.b.min.z, k.b.max.x, k.b.max.y, k.b.max.z, k.w, k.h, k.yaw,
            k.pitch, k.zoom, k.proj);
        vec("front_eye", c.eye);
        std::printf("\"front_near\":%.9g,\"front_far\":%.9g,\"front_ortho\":%.9g,", c.near_z,
                    c.far_z, c.ortho_height);
        c = orbit(c, k.yaw, k.pitch);
        vec("orbit_eye", c.eye);
        vec("orbit_up", c.up);
        c = zoom(c, k.zoom);
        c = fit_depth_range(c, k.b);
        vec("eye", c.eye);
        vec("target", c.target);
        vec("up", c.up);
        std::printf("\"near\":%.9g,\"far\":%.9g,\"ortho\":%.9g,", c.near_z, c.far_z,
                    c.ortho_height);
        const Frustum f = c.frustum(aspect);
        std::printf("\"frustum\":[%.9g,%.9g,%.9g,%.9g,%.9g,%.9g],", f.left, f.right, f.bottom,
                    f.top, f.near_z, f.far_z);
        mat("view", c.view());
        mat("projection", f.matrix());
        std::printf("\"problem\":\"%s\"}%s\n", camera_problem(c).c_str(),
                    i + 1 < sizeof cases / sizeof cases[0] ? "," : "");
    }
    std::printf("]\n");
}
