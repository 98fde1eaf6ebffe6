#pragma once
// What the group harnesses ask of a decoded mesh: that the renderer can draw it.
#include <cmath>
#include <cstdint>

#include "core/mesh.h"
#include "fuzz/fuzz_check.h"
#include "remote/group_codec.h"

namespace isowall::fuzz {

inline bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// One normal a position, three indices a triangle, at most kMaxGroupTriangles triangles, every
// index below the vertex count, every position and normal finite.
inline void check_drawable_mesh(const Mesh& m) {
    check(m.normals.size() == m.positions.size(), "one normal a position");
    check(m.indices.size() % 3 == 0, "three indices a triangle");
    check(m.triangle_count() <= remote::kMaxGroupTriangles, "at most kMaxGroupTriangles triangles");
    for (std::uint32_t i : m.indices) check(i < m.vertex_count(), "every index < vertex count");
    for (const glm::vec3& p : m.positions) check(finite(p), "every position is finite");
    for (const glm::vec3& n : m.normals) check(finite(n), "every normal is finite");
}

}  // namespace isowall::fuzz
