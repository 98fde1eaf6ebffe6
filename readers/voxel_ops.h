#pragma once
// What every reader of another format does once it has the stored voxels: the value scaling the
// file asks for (DICOM RescaleSlope/Intercept, NIfTI scl_slope/scl_inter), and an orientation
// that is a rotation (a mirrored file has its x reversed). Pure functions over bytes, so each is
// tested without a file.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "volume/volume.h"

namespace isowall::formats {

struct Scaling {
    double slope = 1, intercept = 0;
    bool identity() const { return slope == 1 && intercept == 0; }
};

// Stored voxels of `type` after value = slope * stored + intercept. The type is kept when the
// scaling is the identity; otherwise widened only as far as needed: the smallest integer type
// that holds every scaled value when slope and intercept are integers and the type is an integer
// one (a CT's uint16 with intercept -1024 becomes int16), else float32 (float64 stays float64).
// InputError naming `where` and `field` when slope or intercept is not finite, slope is 0, or a
// stored value's scaled value is not finite in the type it gives (scaling_problem).
struct ScaledVoxels {
    std::vector<std::byte> bytes;
    VoxelType type;
};
ScaledVoxels apply_scaling(std::vector<std::byte> bytes, VoxelType type, Scaling s,
                           const std::string& where, const std::string& field);

// Why `s` cannot scale stored values in [lo, hi] into `out`, or empty: the slope or intercept is
// not finite, the slope is 0, or a scaled end of the range is not finite in `out` (1e38 * 255 is
// past float32's 3.4e38: every such voxel would be inf).
std::string scaling_problem(Scaling s, double lo, double hi, VoxelType out);

// The least and greatest finite value among stored voxels of `type` (NaN and infinities passed
// over: scaling cannot make those worse), or nullopt when there is none.
std::optional<std::pair<double, double>> finite_range(std::span<const std::byte> bytes,
                                                      VoxelType type);

// The type apply_scaling gives stored voxels of `type` whose values lie in [lo, hi] (a streamed
// read decides it before any voxel is read, from the range the file declares or the type's).
VoxelType scaled_type(VoxelType type, Scaling s, double lo, double hi);
// Stored voxels of `type` through the scaling into `out_type` at `out`.
void scale_into(std::span<const std::byte> in, VoxelType type, Scaling s, VoxelType out_type,
                std::byte* out);
// Reverses x in each row of `width` voxels of `type` (make_rotation's mirror, a plane at a time).
void mirror_rows(std::span<std::byte> bytes, int width, VoxelType type);

// Every voxel of `type` in `bytes` as slope * stored + intercept in float32, whatever the scaling.
std::vector<std::byte> to_float32(std::span<const std::byte> bytes, VoxelType type, Scaling s);

// The voxels and orientation of a volume whose axes (columns, patient LPS) may be mirrored: when
// det(axes) < 0, x is reversed in the voxels and in the orientation (the first column negated,
// the origin moved to the old last column), so the same points keep the same values. Axes are
// otherwise kept as given.
void make_rotation(std::vector<std::byte>& bytes, glm::ivec3 dims, VoxelType type,
                   glm::vec3 spacing, Orientation& o);

// The patient directions the volume's x, y and z point to most nearly, as three of L R A P S I
// ("LPS" for the identity, "RAS" for diag(-1, -1, 1)).
std::string orientation_letters(const glm::mat3& axes);

// The box the volume fills in patient space (mm, LPS): its eight corners through the orientation.
Box3 patient_bounds(const Volume& v);

// Builds the volume of a reader: the bytes it decoded, scaled and made a rotation, with `files`
// and the facts "format" and, when scaling applied, "scaling". A helper so every reader ends
// alike.
struct Decoded {
    std::vector<std::byte> bytes;
    glm::ivec3 dims{0};
    VoxelType type = VoxelType::u8;
    glm::vec3 spacing{1.0f};
    Orientation orientation;
    Scaling scaling;
    std::string format;  // "NIfTI-1", "DICOM", "HDF5", ...
    std::vector<std::filesystem::path> files;
    std::vector<VolumeFact> facts;  // what else the format carried, in the order to print
};
Volume finish_volume(Decoded d, const std::string& where, const std::string& scaling_field);

}  // namespace isowall::formats
