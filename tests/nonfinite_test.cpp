// NaN and infinity in voxels: NaN is outside the surface for every isovalue, infinities are
// ordered values, the value range is over finite voxels, and no NaN or infinite position or
// normal ever reaches a mesh, in full extraction or in a progressive frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "app/whole_frame.h"
#include "core/error.h"
#include "engine/progressive_engine.h"
#include "tests/engine_util.h"
#include "tests/image_compare.h"
#include "tests/test_util.h"
#include "volume/volume.h"

namespace isowall {
namespace {

constexpr glm::ivec3 kDims{40, 36, 32};

std::size_t at(int x, int y, int z) {
    return (std::size_t(z) * kDims.y + y) * kDims.x + x;
}

// f = 12 - |p - c|: a ball of radius 12 in the middle, the values the isovalues cross.
std::vector<float> ball() {
    std::vector<float> v(std::size_t(kDims.x) * kDims.y * kDims.z);
    for (int z = 0; z < kDims.z; ++z)
        for (int y = 0; y < kDims.y; ++y)
            for (int x = 0; x < kDims.x; ++x)
                v[at(x, y, z)] = 12.0f - glm::length(glm::vec3(x, y, z) - glm::vec3(20, 18, 16));
    return v;
}

// Ways to spoil a ball with non-finite voxels, each crossing its surface.
struct Spoil {
    const char* name;
    void (*apply)(std::vector<float>& v);
};

void nan_block(std::vector<float>& v) {
    for (int z = 10; z < 22; ++z)
        for (int y = 0; y < 18; ++y)
            for (int x = 0; x < 20; ++x) v[at(x, y, z)] = std::nanf("");
}

void inf_voxels(std::vector<float>& v) {
    for (int x = 4; x < 36; ++x) v[at(x, 18, 16)] = x % 2 ? INFINITY : -INFINITY;
    for (int z = 0; z < kDims.z; ++z) v[at(20, 6, z)] = INFINITY;
}

void nan_and_inf_together(std::vector<float>& v) {
    nan_block(v);
    inf_voxels(v);
    for (std::size_t i = 0; i < v.size(); i += 97) v[i] = std::nanf("");
}

const Spoil kSpoils[] = {{"nan block", nan_block},
                         {"inf voxels", inf_voxels},
                         {"nan and inf together", nan_and_inf_together}};

Volume make_volume(const std::vector<float>& values, glm::vec3 spacing = glm::vec3(1)) {
    std::vector<std::byte> bytes(values.size() * sizeof(float));
    std::memcpy(bytes.data(), values.data(), bytes.size());
    return Volume(kDims, VoxelType::f32, spacing, std::move(bytes), "spoiled");
}

std::size_t non_finite_vertices(const Mesh& m) {
    std::size_t bad = 0;
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        const glm::vec3 p = m.positions[i], n = m.normals[i];
        for (int a = 0; a < 3; ++a) bad += !std::isfinite(p[a]) || !std::isfinite(n[a]);
    }
    return bad;
}

TEST(NonFinite, FullExtractionEmitsOnlyFiniteVerticesAndTheRangeIsFinite) {
    for (const Spoil& s : kSpoils) {
        SCOPED_TRACE(s.name);
        std::vector<float> values = ball();
        s.apply(values);
        const Volume volume = make_volume(values, glm::vec3(1, 0.5f, 2));
        const auto ex = make_surface_extractor(volume);
        float lo = INFINITY, hi = -INFINITY;
        for (float f : values)
            if (std::isfinite(f)) lo = std::min(lo, f), hi = std::max(hi, f);
        EXPECT_EQ(ex->value_min(), double(lo));
        EXPECT_EQ(ex->value_max(), double(hi));
        for (double iso : {-5.0, 0.0, 6.0, double(hi)}) {
            const Mesh m = ex->extract_full(iso);
            EXPECT_GT(m.triangle_count(), 0u) << "iso " << iso;
            EXPECT_EQ(non_finite_vertices(m), 0u) << "iso " << iso;
        }
    }
}

TEST(NonFinite, ProgressiveFrameMatchesTheFullSurfaceWithFiniteGroups) {
    for (const Spoil& s : kSpoils) {
        SCOPED_TRACE(s.name);
        std::vector<float> values = ball();
        s.apply(values);
        const Volume volume = make_volume(values);
        auto ex = make_surface_extractor(volume);
        auto renderer = make_renderer("osmesa");
        const FrameView fv = test::make_view(volume, 160, 120, 0.0, 30, 20);
        ProgressiveEngine engine(*ex);
        const FrameResult fr = draw_frame(engine, fv, *renderer);
        ASSERT_TRUE(fr.completed);
        std::size_t triangles = 0;
        for (const Group& g : fr.groups) {
            EXPECT_EQ(non_finite_vertices(g.mesh), 0u) << "group " << g.id;
            triangles += g.mesh.triangle_count();
        }
        EXPECT_GT(triangles, 0u);
        const Image full = test::full_surface_image(*ex, *renderer, fv);
        const test::ImageComparison m = test::compare_images(fr.final_image, full);
        EXPECT_GE(m.mask_iou, 0.999);
        EXPECT_GE(m.equal_share, 0.999);
    }
}

TEST(NonFinite, AVolumeWithoutAFiniteVoxelIsAnErrorNamingIt) {
    const float kinds[] = {std::nanf(""), INFINITY, -INFINITY};
    for (int mix = 1; mix < 8; ++mix) {  // every non-empty mix of NaN, +inf and -inf
        std::vector<float> values(std::size_t(kDims.x) * kDims.y * kDims.z);
        std::size_t k = 0;
        for (float& f : values) {
            do k = (k + 1) % 3;
            while (!(mix >> k & 1));
            f = kinds[k];
        }
        const Volume volume = make_volume(values);
        try {
            make_surface_extractor(volume);
            ADD_FAILURE() << "mix " << mix << ": expected an error";
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("spoiled: data: no finite voxel", 0), 0u)
                << e.what();
        }
    }
}

}  // namespace
}  // namespace isowall
