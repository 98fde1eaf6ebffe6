// Full extraction: closed, accurate, consistently oriented surfaces; the octree skips nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "extract/extract.h"
#include "files/ply.h"
#include "tests/test_util.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

struct SphereField {
    std::vector<float> data;
    VolumeView<float> view;
    glm::vec3 centre;
};

// f = r - |p - c|: inside (f >= 0) is the ball. Spacing scales the grid, not the sphere.
SphereField sphere_field(glm::ivec3 d, glm::vec3 spacing, glm::vec3 centre, float r) {
    SphereField s;
    s.data.resize(std::size_t(d.x) * d.y * d.z);
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                s.data[(std::size_t(z) * d.y + y) * d.x + x] =
                    r - glm::length(glm::vec3(x, y, z) * spacing - centre);
    s.view = {s.data.data(), d, spacing};
    s.centre = centre;
    return s;
}

double mesh_area(const Mesh& m) {
    double a = 0;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const glm::vec3 p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]],
                        p2 = m.positions[m.indices[3 * t + 2]];
        a += 0.5 * double(glm::length(glm::cross(p1 - p0, p2 - p0)));
    }
    return a;
}

// Every undirected edge in exactly two triangles, and (orientation) every directed edge in one.
void expect_closed_and_oriented(const Mesh& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k) {
            const auto a = m.indices[3 * t + k], b = m.indices[3 * t + (k + 1) % 3];
            ++directed[{a, b}];
        }
    std::size_t bad = 0;
    for (const auto& [e, n] : directed) {
        const auto back = directed.find({e.second, e.first});
        if (n != 1 || back == directed.end() || back->second != 1) ++bad;
    }
    EXPECT_EQ(bad, 0u) << "of " << directed.size() << " directed edges";
}

TEST(Extract, SphereIsClosedWithTheRightArea) {
    for (glm::vec3 spacing : {glm::vec3(1), glm::vec3(0.5f, 0.75f, 1.25f)}) {
        const float r = 20.3f;
        const glm::ivec3 d = glm::ivec3(glm::ceil((2.0f * r + 6.0f) / spacing)) + 1;
        const glm::vec3 c = glm::vec3(d - 1) * spacing * 0.5f + glm::vec3(0.21f, -0.13f, 0.07f);
        auto s = sphere_field(d, spacing, c, r);
        auto o = MinMaxOctree<float>::build(s.view);
        const Mesh m = extract_full(s.view, o, 0.0, nullptr);
        SCOPED_TRACE(::testing::Message()
                     << "spacing " << spacing.x << " " << spacing.y << " " << spacing.z);
        ASSERT_GT(m.triangle_count(), 1000u);
        expect_closed_and_oriented(m);
        const double want = 4.0 * std::numbers::pi * r * r;
        const double area = mesh_area(m);
        EXPECT_NEAR(area / want, 1.0, 0.01) << "area " << area << " expected " << want;
        // Normals point outward, and winding agrees with them (counter-clockwise from outside).
        std::size_t inward = 0, misdrawn = 0;
        for (std::size_t t = 0; t < m.triangle_count(); ++t) {
            const auto i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
            const glm::vec3 p0 = m.positions[i0];
            const glm::vec3 geo = glm::cross(m.positions[i1] - p0, m.positions[i2] - p0);
            if (glm::dot(m.normals[i0], p0 - c) <= 0) ++inward;
            if (glm::dot(geo, p0 - c) < 0) ++misdrawn;
        }
        EXPECT_EQ(inward, 0u);
        EXPECT_EQ(misdrawn, 0u);
        // Vertices sit on the sphere (linear interpolation error is second order).
        double worst = 0;
        for (const auto& p : m.positions)
            worst = std::max(worst, std::abs(double(glm::length(p - c)) - r));
        EXPECT_LT(worst, 0.05 * double(glm::length(spacing)));
    }
}

TEST(Extract, IsovalueEqualToSamplesStillCloses) {
    // Integer field with many voxels exactly at the isovalue: the epsilon rule (>= iso is inside)
    // must still give a closed surface.
    const glm::ivec3 d(24, 24, 24);
    std::vector<std::uint8_t> data(std::size_t(d.x) * d.y * d.z);
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                data[(std::size_t(z) * d.y + y) * d.x + x] = static_cast<std::uint8_t>(std::max(
                    0.0f, 10.0f - 0.8f * glm::length(glm::vec3(x, y, z) - glm::vec3(11.5f))));
    VolumeView<std::uint8_t> v{data.data(), d, glm::vec3(1)};
    auto o = MinMaxOctree<std::uint8_t>::build(v);
    for (double iso : {3.0, 5.0, 7.0}) {
        const Mesh m = extract_full(v, o, iso, nullptr);
        SCOPED_TRACE(::testing::Message() << "iso " << iso);
        ASSERT_GT(m.triangle_count(), 0u);
        expect_closed_and_oriented(m);
    }
}

TEST(Extract, OctreeSkipsOnlyInactiveCells) {
    const Volume p = make_phantom();
    const auto v = p.view<std::uint8_t>();
    auto o = MinMaxOctree<std::uint8_t>::build(v);
    for (double iso : {kPhantomSkinIso, kPhantomBoneIso}) {
        ExtractStats st;
        const Mesh m = extract_full(v, o, iso, &st);
        // Brute force over every cell of the volume.
        std::size_t active = 0, triangles = 0;
        double corner[8];
        for (int z = 0; z + 1 < v.dims.z; ++z)
            for (int y = 0; y + 1 < v.dims.y; ++y)
                for (int x = 0; x + 1 < v.dims.x; ++x) {
                    cell_corners(v, {x, y, z}, corner);
                    const int c = cell_case(corner, iso);
                    active += c != 0 && c != 255;
                    triangles += mc::kTriangleCount[std::size_t(c)];
                }
        SCOPED_TRACE(::testing::Message() << "iso " << iso);
        EXPECT_EQ(st.cells_active, active);
        EXPECT_EQ(m.triangle_count(), triangles);
        EXPECT_GT(triangles, 50000u);
        EXPECT_LT(st.leaves_active * 64, v.voxel_count() / 4) << "the octree skipped too little";
    }
}

TEST(Extract, PlyRoundTrips) {
    auto s = sphere_field({16, 16, 16}, glm::vec3(1), glm::vec3(7.5f), 5.2f);
    auto o = MinMaxOctree<float>::build(s.view);
    const Mesh m = extract_full(s.view, o, 0.0, nullptr);
    const auto file = test::scratch_dir("ply") / "s.ply";
    write_ply(file, m);
    const Mesh r = read_ply(file);
    EXPECT_EQ(r.positions, m.positions);
    EXPECT_EQ(r.normals, m.normals);
    EXPECT_EQ(r.indices, m.indices);
}

}  // namespace
}  // namespace isowall
