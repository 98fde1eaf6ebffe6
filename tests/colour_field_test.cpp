// Colour maps and surfaces coloured by a second field: matplotlib's tables at their ends, the
// field sampled trilinear at the vertices, a field on another grid refused, and the legend.
#include <gtest/gtest.h>

#include <cstring>

#include "core/colour_map.h"
#include "volume/colour_field.h"

namespace isowall {
namespace {

TEST(ColourMaps, MatplotlibsTablesAtTheirEndsAndBetween) {
    const auto viridis = colour_map_named("viridis");
    ASSERT_TRUE(viridis);
    // matplotlib's viridis(0.0) = (0.267004, 0.004874, 0.329415), viridis(1.0) = (0.993248,
    // 0.906157, 0.143936).
    EXPECT_EQ(viridis->at(0), glm::u8vec3(68, 1, 84));
    EXPECT_EQ(viridis->at(1), glm::u8vec3(253, 231, 37));
    EXPECT_EQ(viridis->at(-5), viridis->at(0));  // clamped
    EXPECT_EQ(viridis->at(std::nan("")), viridis->at(0));
    EXPECT_EQ(viridis->at(7), viridis->at(1));
    const glm::u8vec3 mid = viridis->at(0.5);  // teal
    EXPECT_GT(mid.y, mid.x);
    const auto gray = colour_map_named("gray");
    ASSERT_TRUE(gray);
    EXPECT_EQ(gray->at(0.5), glm::u8vec3(128, 128, 128));
    EXPECT_FALSE(colour_map_named("rainbow-ish"));
    EXPECT_NE(colour_map_names().find("viridis, magma"), std::string::npos);
    const ColourScale scale{*gray, 100, 300};
    EXPECT_EQ(scale.at(100), glm::u8vec3(0));
    EXPECT_EQ(scale.at(300), glm::u8vec3(255));
}

Volume ramp(glm::ivec3 d, glm::vec3 spacing) {
    std::vector<std::byte> bytes(std::size_t(d.x) * d.y * d.z * sizeof(float));
    std::vector<float> v;
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) v.push_back(float(10 * x + 100 * z));
    std::memcpy(bytes.data(), v.data(), bytes.size());
    return Volume(d, VoxelType::f32, spacing, std::move(bytes), "ramp");
}

TEST(ColourField, VerticesTakeTheFieldTrilinearThroughTheScale) {
    const Volume field = ramp({4, 3, 3}, {2, 1, 1});
    EXPECT_DOUBLE_EQ(sample_trilinear(field, {1, 1, 1}), 110.0);
    EXPECT_DOUBLE_EQ(sample_trilinear(field, {1.5f, 0, 0.25f}), 40.0);
    EXPECT_DOUBLE_EQ(sample_trilinear(field, {9, -3, 9}), 230.0);  // clamped to the grid
    const auto [lo, hi] = finite_range(field);
    EXPECT_DOUBLE_EQ(lo, 0.0);
    EXPECT_DOUBLE_EQ(hi, 230.0);
    Mesh m;
    // Object space: x is twice the voxel index (spacing 2).
    m.positions = {{0, 0, 0}, {6, 2, 2}, {3, 1, 1}};
    m.normals.assign(3, glm::vec3(0, 0, 1));
    m.indices = {0, 1, 2};
    const ColourField f{&field, {*colour_map_named("gray"), 0, 230}};
    colour_mesh(m, f, field.spacing());
    ASSERT_EQ(m.colours.size(), 3u);
    EXPECT_EQ(m.colours[0], glm::u8vec3(0));
    EXPECT_EQ(m.colours[1], glm::u8vec3(255));
    // voxel (1.5, 1, 1): 115 of 230, half way.
    EXPECT_NEAR(m.colours[2].x, 128, 1);
}

TEST(ColourField, AFieldOnAnotherGridIsRefused) {
    const Volume a = ramp({4, 3, 3}, {1, 1, 1}), b = ramp({4, 3, 2}, {1, 1, 1});
    EXPECT_EQ(colour_field_problem(a, a), "");
    EXPECT_EQ(colour_field_problem(b, a),
              "a field of 4x3x2 voxels cannot colour a volume of 4x3x3: it must lie on the same "
              "grid");
}

}  // namespace
}  // namespace isowall
