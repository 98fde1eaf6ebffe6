#include "common/core/mesh.h"

#include <algorithm>
#include <cstddef>

namespace isowall {

void Mesh::append(const Mesh& other) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), other.positions.begin(), other.positions.end());
    normals.insert(normals.end(), other.normals.begin(), other.normals.end());
    // resize, not reserve: reserve allocates exactly what is asked, so a mesh built by many
    // appends would copy all its indices at every one (quadratic); resize grows geometrically.
    const std::size_t from = indices.size();
    indices.resize(from + other.indices.size());
    std::transform(other.indices.begin(), other.indices.end(),
                   indices.begin() + std::ptrdiff_t(from),
                   [base](std::uint32_t i) { return base + i; });
}

}  // namespace isowall
