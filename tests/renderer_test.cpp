// Renderer back ends (OSMesa, EGL) against each other and against analytic silhouettes.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <numbers>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/camera.h"
#include "core/image.h"
#include "core/mesh.h"
#include "files/image_io.h"
#include "render/headlight.h"
#include "render/renderer.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

constexpr std::array<const char*, 2> kBackends = {"osmesa", "egl"};

struct SurfacePoint {
    glm::vec3 position;
    glm::vec3 normal;
};

// A (rows+1) x (cols+1) vertex grid over (u, v) in [0,1]^2. Each triangle is wound
// counter-clockwise around the given outward normals, and zero-area triangles (at the poles of a
// sphere) are dropped.
Mesh grid_mesh(int rows, int cols, const std::function<SurfacePoint(float, float)>& surface) {
    Mesh mesh;
    for (int i = 0; i <= rows; ++i) {
        for (int j = 0; j <= cols; ++j) {
            const SurfacePoint p = surface(static_cast<float>(i) / static_cast<float>(rows),
                                           static_cast<float>(j) / static_cast<float>(cols));
            mesh.positions.push_back(p.position);
            mesh.normals.push_back(glm::normalize(p.normal));
        }
    }
    const auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        const glm::vec3& pa = mesh.positions[a];
        const glm::vec3 n = glm::cross(mesh.positions[b] - pa, mesh.positions[c] - pa);
        if (glm::length(n) < 1e-12f) return;
        const glm::vec3 outward = mesh.normals[a] + mesh.normals[b] + mesh.normals[c];
        if (glm::dot(n, outward) < 0.0f) std::swap(b, c);
        mesh.indices.insert(mesh.indices.end(), {a, b, c});
    };
    const auto at = [cols](int i, int j) { return static_cast<std::uint32_t>(i * (cols + 1) + j); };
    for (int i = 0; i < rows; ++i) {
        for (int j = 0; j < cols; ++j) {
            add(at(i, j), at(i + 1, j), at(i, j + 1));
            add(at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
        }
    }
    return mesh;
}

Mesh uv_sphere(glm::vec3 center, float radius, int stacks, int slices) {
    return grid_mesh(stacks, slices, [=](float u, float v) {
        const float theta = u * std::numbers::pi_v<float>;
        const float phi = v * 2.0f * std::numbers::pi_v<float>;
        const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                          std::sin(theta) * std::sin(phi));
        return SurfacePoint{center + radius * n, n};
    });
}

// Around the z axis, so that seen from +z the hole shows.
Mesh torus(glm::vec3 center, float major, float minor, int rings, int sides) {
    return grid_mesh(rings, sides, [=](float u, float v) {
        const float a = u * 2.0f * std::numbers::pi_v<float>;
        const float b = v * 2.0f * std::numbers::pi_v<float>;
        const glm::vec3 ring(std::cos(a), std::sin(a), 0.0f);
        const glm::vec3 n = std::cos(b) * ring + glm::vec3(0, 0, std::sin(b));
        return SurfacePoint{center + major * ring + minor * n, n};
    });
}

Camera looking_down_z(float distance, Projection projection, const Box3& bounds) {
    Camera camera;
    camera.eye = glm::vec3(0, 0, distance);
    camera.target = glm::vec3(0);
    camera.up = glm::vec3(0, 1, 0);
    camera.projection = projection;
    return fit_depth_range(camera, bounds);
}

void draw(Renderer& renderer, const Mesh& mesh, const Camera& camera, int width, int height) {
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    renderer.draw(mesh, camera.view(), camera.frustum(aspect).matrix());
}

Image render(Renderer& renderer, const Mesh& mesh, const Camera& camera, int width, int height) {
    renderer.resize(width, height);
    renderer.clear();
    draw(renderer, mesh, camera, width, height);
    Image image;
    renderer.read_back(image);
    return image;
}

std::size_t covered_count(const Image& image) {
    return static_cast<std::size_t>(
        std::count_if(image.depth.begin(), image.depth.end(), [](float d) { return d < 1.0f; }));
}

const std::uint8_t* pixel(const Image& image, int x, int y) {
    return &image.rgba[(static_cast<std::size_t>(y) * image.width + x) * 4];
}

TEST(Renderer, UnknownBackendNamesTheAllowedOnes) {
    try {
        make_renderer("vulkan");
        FAIL() << "make_renderer(\"vulkan\") did not throw";
    } catch (const RendererError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("vulkan"), std::string::npos) << message;
        EXPECT_NE(message.find("osmesa"), std::string::npos) << message;
        EXPECT_NE(message.find("egl"), std::string::npos) << message;
    }
}

TEST(Renderer, RejectsBadSizesAndDrawBeforeResize) {
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        EXPECT_EQ(std::string(renderer->name()), std::string(backend));
        EXPECT_THROW(renderer->clear(), RendererError);
        EXPECT_THROW(renderer->resize(0, 10), RendererError);
        try {
            renderer->resize(10, -1);
            FAIL() << "resize(10, -1) did not throw";
        } catch (const RendererError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(backend, 0), 0u) << e.what();
        }
    }
}

TEST(Renderer, EmptyMeshDrawsNothing) {
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        const Image image = render(*renderer, Mesh{}, Camera{}, 8, 6);
        ASSERT_EQ(image.width, 8);
        ASSERT_EQ(image.height, 6);
        EXPECT_EQ(covered_count(image), 0u);
        for (std::size_t i = 0; i < image.pixel_count(); ++i)
            ASSERT_EQ(image.rgba[i * 4], 0) << "pixel " << i;
    }
}

// Both back ends run llvmpipe here, so one scene should come out (almost) the same; the two
// renderers also live side by side and take turns, as their contexts must survive that.
TEST(Renderer, OsmesaAndEglAgree) {
    constexpr int kWidth = 320, kHeight = 240;
    const Mesh ring = torus(glm::vec3(0), 1.0f, 0.35f, 192, 96);
    // Passes through the torus tube, so each occludes the other somewhere.
    const Mesh ball = uv_sphere(glm::vec3(0.9f, 0.3f, 0.2f), 0.5f, 96, 192);
    Box3 bounds = ring.bounds();
    bounds.merge(ball.bounds());
    Camera camera = looking_down_z(6.0f, Projection::perspective, bounds);
    camera.eye = glm::vec3(1.5f, -2.5f, 5.0f);
    camera = fit_depth_range(camera, bounds);

    auto osmesa = make_renderer("osmesa");
    auto egl = make_renderer("egl");
    for (Renderer* r : {osmesa.get(), egl.get()}) r->resize(kWidth, kHeight);
    for (Renderer* r : {osmesa.get(), egl.get()}) r->clear();
    for (const Mesh* mesh : {&ring, &ball}) {
        for (Renderer* r : {osmesa.get(), egl.get()}) draw(*r, *mesh, camera, kWidth, kHeight);
    }
    Image a, b;
    osmesa->read_back(a);
    egl->read_back(b);
    ASSERT_EQ(a.pixel_count(), b.pixel_count());
    const auto dir = test::scratch_dir("renderer_backends");
    write_image(dir / "osmesa.png", a);
    write_image(dir / "egl.png", b);

    const test::ImageComparison m = test::compare_images(a, b);
    std::cout << "[ figures  ] mask IoU " << m.mask_iou << ", mean |colour diff| "
              << m.mean_channel_error << " /255 over " << m.pixels << " pixels, "
              << m.covered_either << " covered\n";
    // Checked first: an empty frame would make the IoU below meaningless (1 for two empty masks).
    EXPECT_GT(m.covered_either, a.pixel_count() / 10) << "scene barely covers the frame";
    EXPECT_GE(m.mask_iou, 0.999);
    EXPECT_LT(m.mean_channel_error, 1.0);
}

// Silhouette of a sphere of radius r seen from distance d: a cone of half-angle asin(r/d), so its
// image radius is (H/2) tan(asin(r/d)) / tan(fovy/2) pixels.
TEST(Renderer, SphereSilhouetteMatchesPerspectiveFormula) {
    constexpr int kSize = 400;
    constexpr float kRadius = 1.0f, kDistance = 5.0f;
    const Mesh sphere = uv_sphere(glm::vec3(0), kRadius, 256, 512);
    const Camera camera = looking_down_z(kDistance, Projection::perspective, sphere.bounds());
    const double half_fovy = glm::radians(static_cast<double>(camera.fovy_deg)) / 2.0;
    const double expected =
        (kSize / 2.0) * std::tan(std::asin(kRadius / kDistance)) / std::tan(half_fovy);
    const auto dir = test::scratch_dir("renderer_sphere_perspective");
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        const Image image = render(*renderer, sphere, camera, kSize, kSize);
        write_image(dir / (std::string(backend) + ".png"), image);
        const double measured =
            std::sqrt(static_cast<double>(covered_count(image)) / std::numbers::pi);
        std::cout << "[ figures  ] " << backend << " perspective radius " << measured
                  << " px, expected " << expected << ", error " << measured - expected << "\n";
        EXPECT_NEAR(measured, expected, 1.0) << camera;

        // Headlight: the centre faces the light and is brightest; the rim is dark but drawn.
        const std::uint8_t* centre = pixel(image, kSize / 2, kSize / 2);
        const std::uint8_t* rim =
            pixel(image, kSize / 2 + static_cast<int>(expected) - 2, kSize / 2);
        EXPECT_GT(centre[0], 220);
        EXPECT_GT(centre[0], centre[2]) << "front colour is warm";
        EXPECT_LT(rim[0], centre[0] / 2);
        EXPECT_TRUE(image.covered(kSize / 2 + static_cast<int>(expected) - 2, kSize / 2));
    }
}

TEST(Renderer, SphereSilhouetteMatchesOrthographicScale) {
    constexpr int kSize = 400;
    constexpr float kRadius = 1.0f;
    const Mesh sphere = uv_sphere(glm::vec3(0), kRadius, 256, 512);
    Camera camera = looking_down_z(5.0f, Projection::orthographic, sphere.bounds());
    camera.ortho_height = 3.0f;
    const double expected = kRadius * kSize / camera.ortho_height;
    const auto dir = test::scratch_dir("renderer_sphere_orthographic");
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        const Image image = render(*renderer, sphere, camera, kSize, kSize);
        write_image(dir / (std::string(backend) + ".png"), image);
        const double measured =
            std::sqrt(static_cast<double>(covered_count(image)) / std::numbers::pi);
        std::cout << "[ figures  ] " << backend << " orthographic radius " << measured
                  << " px, expected " << expected << ", error " << measured - expected << "\n";
        EXPECT_NEAR(measured, expected, 1.0) << camera;
    }
}

// A sphere up and to the right in the view must land in the top rows (row 0 = top) and the
// right columns of the Image.
TEST(Renderer, ReadBackPutsTheTopRowFirst) {
    constexpr int kWidth = 64, kHeight = 48;
    const Mesh sphere = uv_sphere(glm::vec3(0.6f, 0.5f, 0.0f), 0.3f, 32, 64);
    Box3 bounds = sphere.bounds();
    bounds.merge(glm::vec3(0));
    const Camera camera = looking_down_z(5.0f, Projection::perspective, bounds);
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        const Image image = render(*renderer, sphere, camera, kWidth, kHeight);
        ASSERT_GT(covered_count(image), 20u);
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                if (!image.covered(x, y)) continue;
                EXPECT_LT(y, kHeight / 2) << "covered pixel (" << x << ", " << y << ")";
                EXPECT_GE(x, kWidth / 2) << "covered pixel (" << x << ", " << y << ")";
            }
        }
    }
}

// The coverage a ray order reads (the depth alone) is the read-back's depth below 1, row for
// row, for the whole frame, for rects in it (one across the torus's hole) and for an empty rect.
TEST(Renderer, CoverageIsTheDepthBelowOne) {
    constexpr int kW = 80, kH = 60;
    const Mesh ring = torus(glm::vec3(0), 1.0f, 0.3f, 48, 24);
    const Camera eye = looking_down_z(4.0f, Projection::perspective, ring.bounds());
    for (const char* name : kBackends) {
        SCOPED_TRACE(name);
        const auto r = make_renderer(name);
        const Image frame = render(*r, ring, eye, kW, kH);
        ASSERT_GT(covered_count(frame), 100u);
        ASSERT_FALSE(frame.covered(kW / 2, kH / 2)) << "the hole";
        for (const PixelRect rect : {PixelRect{0, 0, kW, kH}, PixelRect{30, 20, 21, 17},
                                     PixelRect{3, 50, 10, 8}, PixelRect{5, 5, 0, 0}}) {
            std::vector<std::uint8_t> covered(7, 9);
            r->read_coverage(covered, rect);
            ASSERT_EQ(covered.size(), std::size_t(rect.width) * std::size_t(rect.height));
            std::size_t differ = 0, count = 0;
            for (int y = 0; y < rect.height; ++y)
                for (int x = 0; x < rect.width; ++x) {
                    const std::uint8_t c = covered[std::size_t(y * rect.width + x)];
                    differ += c != (frame.covered(rect.x + x, rect.y + y) ? 1 : 0);
                    count += c;
                }
            EXPECT_EQ(differ, 0u) << rect.x << "," << rect.y << " " << rect.width << "x"
                                  << rect.height;
            if (rect.width == kW) {
                EXPECT_EQ(count, covered_count(frame));
            }
        }
        std::vector<std::uint8_t> covered;
        EXPECT_THROW(r->read_coverage(covered, PixelRect{75, 0, 10, 10}), RendererError);
    }
}

TEST(Renderer, DrawAddsToTheFrameAndClearEmptiesIt) {
    constexpr int kSize = 64;
    const Mesh left = uv_sphere(glm::vec3(-0.6f, 0, 0), 0.3f, 32, 64);
    const Mesh right = uv_sphere(glm::vec3(0.6f, 0, 0), 0.3f, 32, 64);
    Box3 bounds = left.bounds();
    bounds.merge(right.bounds());
    const Camera camera = looking_down_z(5.0f, Projection::perspective, bounds);
    const auto covered_on = [](const Image& image, bool left_half) {
        std::size_t n = 0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                n += image.covered(x, y) && (x < image.width / 2) == left_half;
        return n;
    };
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        renderer->resize(kSize, kSize);
        renderer->clear();
        draw(*renderer, left, camera, kSize, kSize);
        draw(*renderer, right, camera, kSize, kSize);
        Image image;
        renderer->read_back(image);
        EXPECT_GT(covered_on(image, true), 50u) << "first draw was lost";
        EXPECT_GT(covered_on(image, false), 50u);

        renderer->clear();
        renderer->read_back(image);
        EXPECT_EQ(covered_count(image), 0u);
        EXPECT_TRUE(
            std::all_of(image.rgba.begin(), image.rgba.end(),
                        [&, i = 0](std::uint8_t v) mutable { return (i++ % 4 == 3) || v == 0; }))
            << "background is not black";
    }
}

TEST(Renderer, DepthTestMakesDrawOrderIrrelevant) {
    constexpr int kSize = 96;
    const Mesh near_ball = uv_sphere(glm::vec3(0.2f, 0.1f, 0.8f), 0.4f, 48, 96);
    const Mesh far_ball = uv_sphere(glm::vec3(0, 0, -0.5f), 0.8f, 48, 96);
    Box3 bounds = near_ball.bounds();
    bounds.merge(far_ball.bounds());
    const Camera camera = looking_down_z(5.0f, Projection::perspective, bounds);
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        renderer->resize(kSize, kSize);
        Image near_first, far_first;
        renderer->clear();
        draw(*renderer, near_ball, camera, kSize, kSize);
        draw(*renderer, far_ball, camera, kSize, kSize);
        renderer->read_back(near_first);
        renderer->clear();
        draw(*renderer, far_ball, camera, kSize, kSize);
        draw(*renderer, near_ball, camera, kSize, kSize);
        renderer->read_back(far_first);
        EXPECT_EQ(near_first.rgba, far_first.rgba);
        EXPECT_EQ(near_first.depth, far_first.depth);
    }
}

// Two-sided lighting: a face turned away from the eye is lit as brightly as one facing it, in
// the (bluish) back colour instead of the (warm) front colour.
TEST(Renderer, BackFacesAreLitInTheirOwnColour) {
    constexpr int kWidth = 64, kHeight = 32;
    Mesh quads;
    // Left quad faces +z (counter-clockwise seen from the eye); right quad faces -z.
    quads.positions = {{-0.9f, -0.4f, 0}, {-0.1f, -0.4f, 0}, {-0.1f, 0.4f, 0}, {-0.9f, 0.4f, 0},
                       {0.1f, -0.4f, 0},  {0.9f, -0.4f, 0},  {0.9f, 0.4f, 0},  {0.1f, 0.4f, 0}};
    quads.normals = {{0, 0, 1},  {0, 0, 1},  {0, 0, 1},  {0, 0, 1},
                     {0, 0, -1}, {0, 0, -1}, {0, 0, -1}, {0, 0, -1}};
    quads.indices = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6};
    Camera camera = looking_down_z(3.0f, Projection::orthographic, quads.bounds());
    camera.ortho_height = 1.0f;
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        const Image image = render(*renderer, quads, camera, kWidth, kHeight);
        const std::uint8_t* front = pixel(image, kWidth / 4, kHeight / 2);
        const std::uint8_t* back = pixel(image, 3 * kWidth / 4, kHeight / 2);
        ASSERT_TRUE(image.covered(kWidth / 4, kHeight / 2));
        ASSERT_TRUE(image.covered(3 * kWidth / 4, kHeight / 2));
        EXPECT_GT(front[0], front[2]);
        EXPECT_GT(back[2], back[0]);
        EXPECT_GT(back[2], 180) << "back face is not lit";
    }
}

// render/headlight.h is the C++ twin of the fragment shader (render/shaders/headlight.frag), for
// a server that predicts a picture's colours without drawing it: what GL draws for a face whose
// shading normal meets the eye at a given angle, front or back, is headlight::colour's, to the
// 8-bit rounding. Orthographic, so the light's direction is the view's everywhere.
TEST(Renderer, HeadlightColoursAreTheShadersOwn) {
    constexpr int kSide = 16;
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto renderer = make_renderer(backend);
        for (const float deg : {0.0f, 25.0f, 50.0f, 75.0f, 88.0f}) {
            for (const bool front : {true, false}) {
                SCOPED_TRACE(testing::Message()
                             << deg << " degrees, " << (front ? "front" : "back"));
                const float a = glm::radians(deg);
                const float z = front ? 1.0f : -1.0f;
                Mesh quad;
                quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
                // The shading normal leans from the face's own normal (+z front, -z back).
                quad.normals.assign(4, glm::vec3(std::sin(a), 0, z * std::cos(a)));
                quad.indices = front ? std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}
                                     : std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2};
                Camera camera = looking_down_z(3.0f, Projection::orthographic, quad.bounds());
                camera.ortho_height = 1.0f;
                const Image image = render(*renderer, quad, camera, kSide, kSide);
                ASSERT_TRUE(image.covered(kSide / 2, kSide / 2));
                const std::uint8_t* got = pixel(image, kSide / 2, kSide / 2);
                const glm::vec3 want = glm::clamp(headlight::colour(z * std::cos(a)), 0.0f, 1.0f);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(double(got[c]), double(want[c]) * 255.0, 1.0) << "channel " << c;
            }
        }
    }
}

}  // namespace
}  // namespace isowall
