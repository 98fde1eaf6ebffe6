// Footprint units against the full-resolution surface they stand for: the faces they cross, the
// first triangle a pixel centre's ray meets in them, and the sample triangle drawn for it.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include "core/ray.h"
#include "extract/footprint.h"
#include "extract/marching_cubes.h"

namespace isowall {
namespace {

// A noisy 20^3 volume: many small surface pieces, every marching-cubes case.
struct NoisyVolume {
    glm::ivec3 dims{20, 20, 20};
    std::vector<std::uint8_t> voxels;
    VolumeView<std::uint8_t> view;

    explicit NoisyVolume(unsigned seed, glm::vec3 spacing = glm::vec3(1.0f)) {
        std::mt19937 rng(seed);
        std::uniform_int_distribution<int> d(0, 255);
        voxels.resize(static_cast<std::size_t>(dims.x * dims.y * dims.z));
        for (auto& v : voxels) v = static_cast<std::uint8_t>(d(rng));
        view.data = voxels.data();
        view.dims = dims;
        view.spacing = spacing;
    }
};

constexpr double kIso = 127.5;

// Whether some fine cell face on face `f` of the unit has corners on both sides of kIso.
bool a_fine_face_straddles(const VolumeView<std::uint8_t>& v, glm::ivec3 base, int level, int f) {
    const InsideTest<std::uint8_t> inside(kIso);
    const int s = 1 << level, axis = f >> 1, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
            int in = 0;
            for (int k = 0; k < 4; ++k) {
                glm::ivec3 q = base;
                q[axis] += (f & 1) ? s : 0;
                q[a1] += i + (k & 1);
                q[a2] += j + (k >> 1);
                in += inside(v.at(q.x, q.y, q.z)) ? 1 : 0;
            }
            if (in != 0 && in != 4) return true;
        }
    return false;
}

TEST(UnitBlock, CrossesAFaceExactlyWhereAFineCellFaceOnItIsCrossed) {
    const NoisyVolume nv(1);
    // A smooth-ish threshold as well as noise: a high isovalue leaves most faces uncrossed.
    const InsideTest<std::uint8_t> inside(kIso);
    int crossed = 0, clear = 0;
    for (int level = 1; level <= 3; ++level)
        for (int z = 0; z + (1 << level) < nv.dims.z; z += 1 << level)
            for (int y = 0; y + (1 << level) < nv.dims.y; y += 1 << level)
                for (int x = 0; x + (1 << level) < nv.dims.x; x += 1 << level) {
                    const glm::ivec3 base(x, y, z);
                    const UnitBlock<std::uint8_t> block(nv.view, base, level, inside);
                    const int faces = block.crossed_faces();
                    for (int f = 0; f < 6; ++f) {
                        const bool want = a_fine_face_straddles(nv.view, base, level, f);
                        ASSERT_EQ(((faces >> f) & 1) != 0, want)
                            << "level " << level << " unit " << x << "," << y << "," << z
                            << " face " << f;
                        ASSERT_EQ(face_straddles(nv.view, base, level, f, inside), want);
                        (want ? crossed : clear) += 1;
                    }
                }
    EXPECT_GT(crossed, 0);
}

TEST(UnitBlock, AFlatFaceIsNotCrossed) {
    // Inside below z = 5.5, outside above: only faces cut by that plane are crossed.
    std::vector<std::uint8_t> voxels(16 * 16 * 16);
    for (int z = 0; z < 16; ++z)
        for (int i = 0; i < 256; ++i)
            voxels[static_cast<std::size_t>(z * 256 + i)] = z < 6 ? 200 : 10;
    VolumeView<std::uint8_t> v;
    v.data = voxels.data();
    v.dims = {16, 16, 16};
    const InsideTest<std::uint8_t> inside(kIso);
    // The unit of level 2 at z 4..8 holds the plane: its four side faces are crossed, its
    // bottom (z = 4, all inside) and top (z = 8, all outside) are not.
    const UnitBlock<std::uint8_t> cut(v, {4, 4, 4}, 2, inside);
    EXPECT_EQ(cut.crossed_faces(), 0b001111);
    EXPECT_TRUE(cut.straddles());
    const UnitBlock<std::uint8_t> above(v, {4, 4, 8}, 2, inside);
    EXPECT_EQ(above.crossed_faces(), 0);
    EXPECT_FALSE(above.straddles());
}

// The nearest hit of `ray` on every full-resolution triangle of the unit, by brute force, with its
// triangle's index in a mesh of the unit's cells (emit_meta_cell at level 0, no vertex sharing).
struct BruteHit {
    bool found = false;
    float t = std::numeric_limits<float>::max();
    glm::vec3 normal{0};
    bool front = true;
};

BruteHit brute_first_hit(const VolumeView<std::uint8_t>& v, glm::ivec3 base, int level,
                         const Ray& ray) {
    BruteHit best;
    const int s = 1 << level;
    for (int z = 0; z < s; ++z)
        for (int y = 0; y < s; ++y)
            for (int x = 0; x < s; ++x) {
                const glm::ivec3 c = base + glm::ivec3(x, y, z);
                double corner[8];
                meta_cell_corners(v, c, 0, corner);
                const int cs = cell_case(corner, kIso);
                Mesh mesh;
                struct NoCache {
                    std::pair<std::uint32_t*, bool> find_or_insert(glm::ivec3, int) {
                        return {&slot, true};
                    }
                    std::uint32_t slot = 0;
                } none;
                emit_meta_cell(v, c, 0, kIso, cs, corner, none, mesh);
                for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
                    // Mesh positions are object space; the volume's spacing here is 1.
                    const glm::vec3 a = mesh.positions[mesh.indices[i]];
                    const glm::vec3 b = mesh.positions[mesh.indices[i + 1]];
                    const glm::vec3 cc = mesh.positions[mesh.indices[i + 2]];
                    float t, u, w;
                    if (!intersect_barycentric(ray, a, b, cc, t, u, w) || t >= best.t) continue;
                    best.found = true;
                    best.t = t;
                    best.normal = glm::normalize((1 - u - w) * mesh.normals[mesh.indices[i]] +
                                                 u * mesh.normals[mesh.indices[i + 1]] +
                                                 w * mesh.normals[mesh.indices[i + 2]]);
                    best.front = glm::dot(glm::cross(b - a, cc - a), ray.d) < 0;
                }
            }
    return best;
}

TEST(FirstHitInUnit, IsTheNearestFullResolutionTriangleWithItsInterpolatedNormal) {
    const NoisyVolume nv(7);
    const InsideTest<std::uint8_t> inside(kIso);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    int hits = 0, misses = 0;
    for (int level = 1; level <= 3; ++level)
        for (int trial = 0; trial < 300; ++trial) {
            const int s = 1 << level;
            const glm::ivec3 base = s * glm::ivec3(static_cast<int>(u01(rng) * (19 / s)),
                                                   static_cast<int>(u01(rng) * (19 / s)),
                                                   static_cast<int>(u01(rng) * (19 / s)));
            if (glm::any(glm::greaterThan(base + s, nv.dims - 1))) continue;
            // From a point outside the unit towards a point inside it.
            const glm::vec3 target =
                glm::vec3(base) + float(s) * glm::vec3(u01(rng), u01(rng), u01(rng));
            const glm::vec3 dir =
                glm::normalize(glm::vec3(u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f));
            const Ray ray{target - 3.0f * float(s) * dir, dir};
            const UnitBlock<std::uint8_t> block(nv.view, base, level, inside);
            UnitCells cells;
            cells.reset(s);
            const FootprintHit got = first_hit_in_unit(nv.view, block, kIso, ray, cells);
            const BruteHit want = brute_first_hit(nv.view, base, level, ray);
            ASSERT_EQ(got.found, want.found) << "level " << level << " trial " << trial;
            if (!want.found) {
                ++misses;
                continue;
            }
            ++hits;
            EXPECT_NEAR(got.t, want.t, 1e-4f);
            EXPECT_GT(glm::dot(got.normal, want.normal), 0.9999f);
            EXPECT_EQ(got.front, want.front);
        }
    EXPECT_GT(hits, 100);
    EXPECT_GT(misses, 10);
}

TEST(SampleTriangle, HoldsItsPixelCentreAloneAndFacesAsTheHitTriangle) {
    // A perspective view of a 64^3 box from 200 units away, 400 x 300 pixels.
    const glm::mat4 view =
        glm::lookAt(glm::vec3(32, 32, 232), glm::vec3(32, 32, 32), glm::vec3(0, 1, 0));
    const glm::mat4 proj = glm::perspective(glm::radians(30.0f), 4.0f / 3.0f, 10.0f, 400.0f);
    const glm::vec3 spacing(1.0f, 1.0f, 2.0f);  // anisotropic: the grid is in voxel space
    FootprintGrid grid;
    grid.clip_from_voxel = proj * view * glm::scale(glm::mat4(1.0f), spacing);
    grid.voxel_from_clip = glm::inverse(grid.clip_from_voxel);
    grid.width = 400;
    grid.height = 300;
    const glm::mat4 clip_from_object = proj * view;
    for (const bool front : {true, false}) {
        const Ray ray = grid.centre_ray(210, 140);
        FootprintHit hit;
        hit.found = true;
        hit.position = ray.at(0.6f);  // somewhere along the centre's ray
        hit.normal = glm::vec3(0, 0, 1);
        hit.front = front;
        const SampleShape shape = SampleShape::at(grid, hit.position, ray.d);
        ASSERT_TRUE(shape.usable);
        Mesh mesh;
        append_sample_triangle(hit, shape, spacing, mesh);
        ASSERT_EQ(mesh.indices.size(), 3u);
        // In window space: the centre (210.5, 140.5) inside, every corner within the radius.
        glm::vec2 w[3];
        for (int k = 0; k < 3; ++k) {
            const glm::vec4 c = clip_from_object * glm::vec4(mesh.positions[mesh.indices[k]], 1.0f);
            w[k] = ndc_to_window(c.x / c.w, c.y / c.w, 400, 300);
            EXPECT_LT(glm::length(w[k] - glm::vec2(210.5f, 140.5f)), kSampleRadiusPx * 1.05f);
            EXPECT_EQ(mesh.normals[mesh.indices[k]], hit.normal);
        }
        // Window y grows downwards, so a triangle facing the eye (counter-clockwise in GL's
        // window space, y up) has a negative signed area here.
        const glm::vec2 e1 = w[1] - w[0], e2 = w[2] - w[0];
        const float area = e1.x * e2.y - e1.y * e2.x;
        EXPECT_EQ(area < 0, front);
        for (int k = 0; k < 3; ++k) {
            const glm::vec2 a = w[k], b = w[(k + 1) % 3];
            const glm::vec2 p = glm::vec2(210.5f, 140.5f);
            const float side = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
            EXPECT_EQ(side < 0, area < 0) << "the centre lies inside";
        }
    }
}

}  // namespace
}  // namespace isowall
