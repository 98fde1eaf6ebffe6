#pragma once
// Axis-aligned box. An empty box is inverted (min=+inf, max=-inf) so merge() needs no flag.
#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <ostream>

namespace isowall {

struct Box3 {
    glm::vec3 min{std::numeric_limits<float>::infinity()};
    glm::vec3 max{-std::numeric_limits<float>::infinity()};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void merge(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void merge(const Box3& b) {
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }
    glm::vec3 center() const { return 0.5f * (min + max); }
    glm::vec3 extent() const { return max - min; }
};

inline std::ostream& operator<<(std::ostream& os, const glm::vec3& v) {
    return os << "(" << v.x << ", " << v.y << ", " << v.z << ")";
}
inline std::ostream& operator<<(std::ostream& os, const Box3& b) {
    return os << "Box3[" << b.min << " - " << b.max << "]";
}

}  // namespace isowall
