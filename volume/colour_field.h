#pragma once
// A surface coloured by a second field on the same grid (`--color-by`): each vertex takes the
// field's value where it lies, trilinear between the voxels, through a colour scale. A dose on a
// CT, a segmentation's labels, a simulation's second variable: the isosurface of one field shows
// where, the colour shows how much of the other.
#include <optional>
#include <string>

#include "core/colour_map.h"
#include "core/mesh.h"
#include "volume/volume.h"

namespace isowall {

struct ColourField {
    const Volume* values = nullptr;  // must outlive the field; same dims as the surface's volume
    ColourScale scale;
};

// The field's value at voxel-space point `p` (voxel indices, fractions between), trilinear and
// clamped to the grid.
double sample_trilinear(const Volume& v, glm::vec3 p);

// Sets mesh.colours: each vertex (object space, `spacing` the surface's volume's) coloured by the
// field's value there.
void colour_mesh(Mesh& mesh, const ColourField& field, glm::vec3 spacing);

// The range of the field's finite values (a default for the scale).
std::pair<double, double> finite_range(const Volume& v);

// Why `values` cannot colour `surface` (another grid), or empty.
std::string colour_field_problem(const Volume& values, const Volume& surface);

}  // namespace isowall
