// A renderer's frame resized from region to region, as a wall rank's help frame is: larger, far
// smaller (its buffers then shrink to it, render/gl_core.cpp), a little larger again. Every size
// draws what a fresh renderer of that size draws, and nothing of an earlier frame shows.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/camera.h"
#include "core/image.h"
#include "core/mesh.h"
#include "render/renderer.h"

namespace isowall {
namespace {

// A tilted quad filling most of the view, seen down -z.
Mesh tilted_quad() {
    Mesh m;
    m.positions = {
        {-0.6f, -0.5f, -0.2f}, {0.6f, -0.5f, 0.2f}, {0.6f, 0.5f, 0.2f}, {-0.6f, 0.5f, -0.2f}};
    m.normals.assign(4, glm::vec3(-0.31f, 0.0f, 0.95f));
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

Image drawn(Renderer& r, const Mesh& mesh, int width, int height) {
    Camera camera;
    camera.eye = glm::vec3(0, 0, 3);
    camera.target = glm::vec3(0);
    camera.up = glm::vec3(0, 1, 0);
    camera = fit_depth_range(camera, mesh.bounds());
    r.resize(width, height);
    r.clear();
    const float aspect = float(width) / float(height);
    r.draw(mesh, camera.view(), camera.frustum(aspect).matrix());
    Image image;
    r.read_back(image);
    return image;
}

TEST(RendererFrames, FramesOfChangingSizesDrawAsFreshOnes) {
    const Mesh quad = tilted_quad();
    const int sizes[][2] = {{512, 384}, {40, 30}, {48, 36}, {512, 384}, {400, 300}, {32, 24}};
    for (const char* backend : {"osmesa", "egl"}) {
        SCOPED_TRACE(backend);
        auto reused = make_renderer(backend);
        for (const auto& wh : sizes) {
            SCOPED_TRACE(std::to_string(wh[0]) + "x" + std::to_string(wh[1]));
            const Image got = drawn(*reused, quad, wh[0], wh[1]);
            auto fresh = make_renderer(backend);
            const Image want = drawn(*fresh, quad, wh[0], wh[1]);
            ASSERT_EQ(got.width, wh[0]);
            ASSERT_EQ(got.height, wh[1]);
            const auto covered =
                std::count_if(got.depth.begin(), got.depth.end(), [](float d) { return d < 1.0f; });
            EXPECT_GT(covered, wh[0] * wh[1] / 4);
            EXPECT_LT(covered, wh[0] * wh[1]) << "nothing left as background";
            EXPECT_EQ(got.rgba, want.rgba);
            EXPECT_EQ(got.depth, want.depth);
        }
    }
}

}  // namespace
}  // namespace isowall
