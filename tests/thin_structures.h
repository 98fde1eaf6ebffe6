#pragma once
// A test volume of structures thinner than a cell: tubes of radius ~0.5 voxel along
// oblique lines and a sheet ~1 voxel thick, beside a ball many cells across, in n^3 uint8 voxels.
// At the isovalue kThinIso the tubes and the sheet are surfaces a meta-cell's eight corners miss,
// where the ball is a smooth surface any level draws.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "volume/volume.h"

namespace isowall::test {

inline constexpr double kThinIso = 100;

inline Volume make_thin_structures(int n = 96) {
    std::vector<std::byte> bytes(static_cast<std::size_t>(n) * n * n);
    const float c = 0.5f * static_cast<float>(n - 1);
    struct Line {
        glm::vec3 a, d;
    };
    const Line tubes[] = {
        {{0.2f * n, 0.5f * n, 0.1f * n}, glm::normalize(glm::vec3(0.7f, 0.2f, 1.0f))},
        {{0.8f * n, 0.5f * n, 0.1f * n}, glm::normalize(glm::vec3(-0.5f, 0.3f, 1.0f))},
        {{0.1f * n, 0.4f * n, 0.8f * n}, glm::normalize(glm::vec3(1.0f, 0.1f, -0.3f))},
    };
    const glm::vec3 sheet_normal = glm::normalize(glm::vec3(0.3f, 1.0f, 0.4f));
    const float sheet_at = glm::dot(sheet_normal, glm::vec3(c, 0.65f * n, c));
    auto bump = [](float dist, float sigma) { return std::exp(-(dist * dist) / (sigma * sigma)); };
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const glm::vec3 p(static_cast<float>(x), static_cast<float>(y),
                                  static_cast<float>(z));
                // The ball: a smooth ramp from 200 inside to 0 outside, its surface (100) at
                // radius n / 6, two voxels wide.
                float v = std::clamp(
                    100.0f + 50.0f * (n / 6.0f - glm::length(p - glm::vec3(c, 0.3f * n, c))), 0.0f,
                    200.0f);
                for (const Line& t : tubes) {
                    const glm::vec3 q = p - t.a;
                    const float r = glm::length(q - glm::dot(q, t.d) * t.d);
                    v = std::max(v, 200.0f * bump(r, 0.6f));  // 100 at r = 0.5
                }
                // The sheet, inside the middle of the volume only.
                if (glm::length(p - glm::vec3(c)) < 0.4f * n)
                    v = std::max(v, 200.0f * bump(glm::dot(sheet_normal, p) - sheet_at, 0.6f));
                bytes[(static_cast<std::size_t>(z) * n + y) * n + x] =
                    static_cast<std::byte>(static_cast<std::uint8_t>(std::lround(v)));
            }
    return Volume({n, n, n}, VoxelType::u8, glm::vec3(1.0f), std::move(bytes), "thin structures");
}

}  // namespace isowall::test
