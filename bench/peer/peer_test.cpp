// The FE + Embree peer's ray side on meshes whose hit pixels are known: nothing, a square and a
// triangle facing the eye of the front full view, on screens whose sides are not multiples of
// the 8-pixel tile, with 1 and 3 threads; and the mesh file's checks.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

#include <glm/gtc/matrix_inverse.hpp>

#include "bench/peer/peer_mesh.h"
#include "bench/peer/peer_trace.h"
#include "core/error.h"
#include "core/ray.h"

namespace isowall::peer {
namespace {

constexpr float kPlaneY = 5.0f;  // the test shapes lie in this plane, facing the eye (-y side)

Box3 cube10() {
    Box3 b;
    b.merge(glm::vec3(0));
    b.merge(glm::vec3(10));
    return b;
}

PeerMesh flat_mesh(std::vector<glm::vec2> xz, std::vector<std::uint32_t> indices) {
    PeerMesh m;
    m.bounds = cube10();
    for (glm::vec2 p : xz) m.xyz.insert(m.xyz.end(), {p.x, kPlaneY, p.y});
    m.indices = std::move(indices);
    return m;
}

// Where pixel (x, y)'s ray meets the plane y = kPlaneY, as (x, z).
glm::vec2 on_plane(const TraceView& v, int x, int y) {
    const Ray r = pixel_ray(glm::inverse(v.camera.view()), v.frustum, v.width, v.height, {x, y});
    const glm::vec3 p = r.at((kPlaneY - r.o.y) / r.d.y);
    return {p.x, p.z};
}

// `inside` gives a signed distance in object units: > 0 inside, < 0 outside. Pixels whose
// centre lies within 1e-3 of an edge may go either way; every other pixel must agree.
void expect_hits(const TraceResult& r, const TraceView& v,
                 const std::function<float(glm::vec2)>& inside, std::size_t min_expected) {
    std::size_t sure_in = 0, mismatches = 0;
    for (int y = 0; y < v.height; ++y)
        for (int x = 0; x < v.width; ++x) {
            const float d = inside(on_plane(v, x, y));
            if (std::abs(d) < 1e-3f) continue;
            sure_in += d > 0;
            const bool hit = r.hits[std::size_t(y) * std::size_t(v.width) + std::size_t(x)];
            if (hit != (d > 0)) ++mismatches;
        }
    EXPECT_EQ(mismatches, 0u) << "screen " << v.width << "x" << v.height;
    EXPECT_GE(sure_in, min_expected);
    EXPECT_GE(r.hit_pixels, sure_in);
    EXPECT_LE(r.hit_pixels, sure_in + std::size_t(2 * (v.width + v.height)));
}

TEST(PeerTrace, EmptyMeshHitsNothing) {
    PeerMesh m;
    m.bounds = cube10();
    const TraceResult r = trace(m, front_view(m.bounds, 37, 29), 2);
    EXPECT_EQ(r.hit_pixels, 0u);
    EXPECT_EQ(r.hits.size(), 37u * 29u);
}

TEST(PeerTrace, SquareFacingTheEyeHitsItsProjection) {
    // x in [2, 8], z in [3, 7]: two triangles.
    const PeerMesh m = flat_mesh({{2, 3}, {8, 3}, {8, 7}, {2, 7}}, {0, 1, 2, 0, 2, 3});
    for (auto [w, h] : {std::pair{37, 29}, {160, 120}, {1, 1}}) {
        const TraceView v = front_view(m.bounds, w, h);
        for (int threads : {1, 3}) {
            const TraceResult r = trace(m, v, threads);
            const auto inside = [](glm::vec2 p) {
                return std::min({p.x - 2.0f, 8.0f - p.x, p.y - 3.0f, 7.0f - p.y});
            };
            expect_hits(r, v, inside, w * h > 1 ? 100u : 0u);
        }
    }
}

TEST(PeerTrace, TriangleFacingTheEyeHitsItsProjection) {
    // (1, 1), (9, 1), (5, 9): inside when on the inner side of all three edges.
    const PeerMesh m = flat_mesh({{1, 1}, {9, 1}, {5, 9}}, {0, 1, 2});
    const TraceView v = front_view(m.bounds, 203, 101);
    const auto edge = [](glm::vec2 a, glm::vec2 b, glm::vec2 p) {
        const glm::vec2 e = b - a;
        return (e.x * (p.y - a.y) - e.y * (p.x - a.x)) / glm::length(e);
    };
    const auto inside = [&](glm::vec2 p) {
        return std::min(
            {edge({1, 1}, {9, 1}, p), edge({9, 1}, {5, 9}, p), edge({5, 9}, {1, 1}, p)});
    };
    expect_hits(trace(m, v, 2), v, inside, 1000);
}

TEST(PeerMeshFile, RoundTripsAndRefusesAShortFile) {
    const auto path = std::filesystem::temp_directory_path() / "isowall_peer_test_mesh.bin";
    const PeerMesh m = flat_mesh({{2, 3}, {8, 3}, {8, 7}}, {0, 1, 2});
    write_peer_mesh(path, m);
    const PeerMesh back = read_peer_mesh(path);
    EXPECT_EQ(back.xyz, m.xyz);
    EXPECT_EQ(back.indices, m.indices);
    EXPECT_EQ(back.bounds.max, m.bounds.max);
    std::filesystem::resize_file(path, std::filesystem::file_size(path) - 1);
    try {
        read_peer_mesh(path);
        ADD_FAILURE() << "a short file was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(": size: expected"), std::string::npos) << e.what();
    }
    std::filesystem::remove(path);
}

TEST(PeerMeshFile, RefusesAnIndexPastTheVertices) {
    const auto path = std::filesystem::temp_directory_path() / "isowall_peer_test_bad_index.bin";
    write_peer_mesh(path, flat_mesh({{2, 3}, {8, 3}, {8, 7}}, {0, 1, 3}));
    EXPECT_THROW(read_peer_mesh(path), InputError);
    std::filesystem::remove(path);
}

}  // namespace
}  // namespace isowall::peer
