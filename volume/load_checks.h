#pragma once
// Checks every loader makes before it trusts a header: the files are regular files (a device,
// FIFO or folder can be endless or block forever), the byte counts are computed in 64 bits with
// overflow detection (a size that wraps would load a different volume silently), and a buffer is
// only allocated once the machine can hold it. Each failure is an InputError naming the file and
// the field.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "volume/volume.h"

namespace isowall {

// Throws unless `path` names an existing regular file (symbolic links are followed).
void check_regular_file(const std::filesystem::path& path, const std::string& where,
                        const std::string& field);

// The product of `factors`, or nullopt when it does not fit in 64 bits.
std::optional<std::uint64_t> checked_product(std::initializer_list<std::uint64_t> factors);
// a + b, or nullopt when it does not fit in 64 bits.
std::optional<std::uint64_t> checked_sum(std::uint64_t a, std::uint64_t b);

// Three axis sizes from a header (as read, in 64 bits): each must be >= 2 and fit an int, and the
// voxel bytes must fit in 64 bits. Returns the dims.
glm::ivec3 checked_dims(const std::string& where, const std::string& field,
                        std::span<const std::uint64_t> sizes, VoxelType type);
// dims.x * dims.y * dims.z * voxel_size(type) of dims that passed checked_dims().
std::uint64_t voxel_bytes(glm::ivec3 dims, VoxelType type);

// Throws when `bytes` of decoded voxels cannot be held in this machine's memory; a header may
// claim any size, and a bare std::bad_alloc (or the OOM killer) is no message.
void check_fits_memory(std::uint64_t bytes, const std::string& where, const std::string& field);

// A zero-filled buffer of `bytes`, with allocation failure reported as an InputError.
std::vector<std::byte> allocate_voxels(std::uint64_t bytes, const std::string& where,
                                       const std::string& field);

// The exact-size rule: data shorter or longer than the header says is an error, since a wrong
// size almost always means wrong dims or type, and a silent crop would hide it.
void check_size(const std::string& file, std::uint64_t have, std::uint64_t offset,
                std::uint64_t need);

// `text` in quotes, non-printable bytes escaped (\xNN), cut to at most `limit` characters and
// "...": for quoting input in an error line.
std::string quote_bounded(std::string_view text, std::size_t limit = 60);

// The longest side of a volume, in object units: the view of the whole volume then stands well
// within the camera's reach (1e9 from the origin, core/camera.cpp), so a volume that loads
// can be looked at, and no view option is blamed for a spacing.
inline constexpr double kMaxVolumeSide = 1e7;

// Why `spacing` cannot be the spacing of an axis of `size` voxels (axis `axis`), or empty: it
// must be a positive float32 and keep that side within kMaxVolumeSide.
std::string spacing_problem(double spacing, int size, int axis);

}  // namespace isowall
