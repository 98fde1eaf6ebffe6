#include "volume/phantom.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace isowall {
namespace {

constexpr float kSoftTissue = 100.0f;
constexpr float kBone = 120.0f;  // added on top of soft tissue: bone voxels read 220
constexpr float kRampVoxels = 3.0f;

// 1 inside (sd < 0), 0 outside, a linear ramp kRampVoxels wide across the surface, so the field
// is smooth enough for central-difference normals after rounding to 8 bits.
float occupancy(float sd) {
    return std::clamp(0.5f - sd / kRampVoxels, 0.0f, 1.0f);
}

// Approximate signed distance (in voxels) to an ellipsoid with semi-axes `a`.
float sd_ellipsoid(glm::vec3 p, glm::vec3 a) {
    const float k = glm::length(p / a);
    return (k - 1.0f) * std::min({a.x, a.y, a.z});
}

float sd_cylinder(glm::vec2 p, glm::vec2 centre, float radius) {
    return glm::length(p - centre) - radius;
}

float sd_torus(glm::vec3 p, float major, float minor) {
    const glm::vec2 q(glm::length(glm::vec2(p.x, p.y)) - major, p.z);
    return glm::length(q) - minor;
}

float phantom_value(glm::vec3 p, glm::vec3 half) {
    const float r = std::min({half.x, half.y, half.z});
    const float bump = 0.035f * r * std::sin(0.23f * p.x + 0.5f) * std::sin(0.19f * p.y) *
                       std::sin(0.21f * p.z + 1.0f);
    const float skin = sd_ellipsoid(p, 0.9f * half) + bump;

    const float shell_sd = std::abs(sd_ellipsoid(p, 0.62f * half)) - 0.045f * r;
    // Two "eye" holes through the front (-y) and one through the top.
    const float holes = std::min(
        {sd_cylinder({p.x, p.z}, {-0.2f * r, 0.1f * r}, 0.16f * r) + (p.y > 0 ? 1e6f : 0.0f),
         sd_cylinder({p.x, p.z}, {0.2f * r, 0.1f * r}, 0.16f * r) + (p.y > 0 ? 1e6f : 0.0f),
         sd_cylinder({p.x, p.y}, {0.1f * r, 0.0f}, 0.2f * r) + (p.z < 0 ? 1e6f : 0.0f)});
    const float shell = std::max(shell_sd, -holes);
    const float torus = sd_torus(p - glm::vec3(0, 0.05f * r, -0.05f * r), 0.26f * r, 0.09f * r);

    return kSoftTissue * occupancy(skin) + kBone * std::max(occupancy(shell), occupancy(torus));
}

}  // namespace

Volume make_phantom(const PhantomSpec& spec) {
    const glm::ivec3 d = spec.dims;
    const glm::vec3 half = 0.5f * glm::vec3(d - 1);
    std::vector<std::byte> bytes(static_cast<std::size_t>(d.x) * d.y * d.z);
    auto fill_slabs = [&](int z0, int z1) {
        for (int z = z0; z < z1; ++z)
            for (int y = 0; y < d.y; ++y)
                for (int x = 0; x < d.x; ++x) {
                    const glm::vec3 p = glm::vec3(x, y, z) - half;
                    const float v = std::round(phantom_value(p, half));
                    bytes[(static_cast<std::size_t>(z) * d.y + y) * d.x + x] =
                        static_cast<std::byte>(
                            static_cast<std::uint8_t>(std::clamp(v, 0.0f, 255.0f)));
                }
    };
    // Two halves on two threads: the result does not depend on the split.
    std::thread other(fill_slabs, d.z / 2, d.z);
    fill_slabs(0, d.z / 2);
    other.join();
    return Volume(d, VoxelType::u8, spec.spacing, std::move(bytes), "phantom");
}

}  // namespace isowall
