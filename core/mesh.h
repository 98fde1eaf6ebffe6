#pragma once
// Indexed face set: the unit every extractor produces and every renderer draws.
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/box.h"

namespace isowall {

struct Mesh {
    std::vector<glm::vec3> positions;    // object space (voxel index * spacing)
    std::vector<glm::vec3> normals;      // unit, one per position
    std::vector<std::uint32_t> indices;  // three per triangle, counter-clockwise seen from outside
    // Empty (the surface's one colour), or one sRGB colour per position: a surface coloured by a
    // second field (volume/colour_field.h).
    std::vector<glm::u8vec3> colours;

    std::size_t triangle_count() const { return indices.size() / 3; }
    std::size_t vertex_count() const { return positions.size(); }
    bool empty() const { return indices.empty(); }
    Box3 bounds() const {
        Box3 b;
        for (const auto& p : positions) b.merge(p);
        return b;
    }
    void append(const Mesh& other);
};

// Sets each vertex's normal to the area-weighted mean of its faces' (counter-clockwise: outward);
// a vertex of no face, or of faces that cancel, keeps its normal.
void normals_from_faces(Mesh& mesh);

}  // namespace isowall
