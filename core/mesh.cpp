#include "core/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include <glm/geometric.hpp>

namespace isowall {

void Mesh::append(const Mesh& other) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), other.positions.begin(), other.positions.end());
    normals.insert(normals.end(), other.normals.begin(), other.normals.end());
    // Colours stay one per position, or none: a mesh without them takes a neutral grey.
    if (!other.colours.empty() || !colours.empty()) {
        colours.resize(base, glm::u8vec3(160));
        if (other.colours.empty())
            colours.resize(positions.size(), glm::u8vec3(160));
        else
            colours.insert(colours.end(), other.colours.begin(), other.colours.end());
    }
    // resize, not reserve: reserve allocates exactly what is asked, so a mesh built by many
    // appends would copy all its indices at every one (quadratic); resize grows geometrically.
    const std::size_t from = indices.size();
    indices.resize(from + other.indices.size());
    std::transform(other.indices.begin(), other.indices.end(),
                   indices.begin() + std::ptrdiff_t(from),
                   [base](std::uint32_t i) { return base + i; });
}

void normals_from_faces(Mesh& mesh) {
    std::vector<glm::vec3> sum(mesh.vertex_count(), glm::vec3(0.0f));
    for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        const std::uint32_t a = mesh.indices[i], b = mesh.indices[i + 1], c = mesh.indices[i + 2];
        const glm::vec3 n = glm::cross(mesh.positions[b] - mesh.positions[a],
                                       mesh.positions[c] - mesh.positions[a]);
        sum[a] += n;
        sum[b] += n;
        sum[c] += n;
    }
    for (std::size_t v = 0; v < sum.size(); ++v) {
        const float len2 = glm::dot(sum[v], sum[v]);
        if (len2 > 0 && std::isfinite(len2)) mesh.normals[v] = sum[v] * (1.0f / std::sqrt(len2));
    }
}

}  // namespace isowall
