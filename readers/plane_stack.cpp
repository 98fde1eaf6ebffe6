#include "readers/plane_stack.h"

#include <cstring>
#include <limits>
#include <vector>

#include <glm/mat3x3.hpp>

#include "core/error.h"
#include "volume/load_checks.h"

namespace isowall::formats {
namespace {

std::pair<double, double> type_range(VoxelType t) {
    return dispatch_voxel_type(t, [](auto v) {
        using T = decltype(v);
        return std::pair<double, double>{double(std::numeric_limits<T>::lowest()),
                                         double(std::numeric_limits<T>::max())};
    });
}

std::string whole(double v) {
    return std::to_string(static_cast<long long>(v));
}

// Every stored value of `bytes` (planes from z0 on) within the declared range.
void check_declared(std::span<const std::byte> bytes, VoxelType type,
                    std::pair<double, double> range, int z0, const std::string& where) {
    dispatch_voxel_type(type, [&](auto zero) {
        using T = decltype(zero);
        const std::size_t n = bytes.size() / sizeof(T);
        for (std::size_t i = 0; i < n; ++i) {
            T v;
            std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
            if (double(v) < range.first || double(v) > range.second)
                throw InputError(where, "BitsStored",
                                 "a stored value (" + whole(double(v)) + ", near slice " +
                                     std::to_string(z0) + ") lies outside the range " +
                                     whole(range.first) + " to " + whole(range.second) +
                                     " the file declares");
        }
    });
}

}  // namespace

Volume read_whole(PlaneStack stack, const std::string& where) {
    Decoded& d = stack.head;
    d.bytes = allocate_voxels(voxel_bytes(d.dims, d.type), where, stack.size_field);
    if (d.dims.z > 0) stack.read(0, d.dims.z, d.bytes.data());
    return finish_volume(std::move(d), where, stack.scaling_field);
}

std::unique_ptr<PlaneSource> stream_planes(PlaneStack stack, const std::string& where) {
    const Decoded& d = stack.head;
    // The checks finish_volume makes, made before the first voxel: a bad scaling or spacing is
    // refused before an import writes anything.
    (void)apply_scaling({}, d.type, d.scaling, where, stack.scaling_field);
    for (int a = 0; a < 3; ++a)
        if (std::string p = spacing_problem(d.spacing[a], d.dims[a], a); !p.empty())
            throw InputError(where, "spacing", p);
    const auto [lo, hi] = stack.declared_range.value_or(type_range(d.type));
    const VoxelType out = scaled_type(d.type, d.scaling, lo, hi);
    const bool mirror = glm::determinant(d.orientation.axes) < 0;
    const std::size_t plane = std::size_t(d.dims.x) * d.dims.y;
    // A declared range narrower than the stored type's must hold: a value past it would not fit
    // the integer type chosen from it.
    const bool check_range = !d.scaling.identity() && stack.declared_range &&
                             *stack.declared_range != type_range(d.type);
    const bool ahead = stack.read_ahead;
    const glm::ivec3 dims = d.dims;  // `d` is moved away with `stack` below
    const glm::vec3 spacing = d.spacing;
    auto decode = [stack = std::move(stack), out, mirror, plane, check_range, where,
                   stored = std::vector<std::byte>()](int z0, int z1, std::byte* to) mutable {
        const Decoded& h = stack.head;
        std::span<std::byte> planes(to, plane * std::size_t(z1 - z0) * voxel_size(out));
        if (h.scaling.identity()) {
            stack.read(z0, z1, to);
        } else {
            stored.resize(plane * std::size_t(z1 - z0) * voxel_size(h.type));
            stack.read(z0, z1, stored.data());
            if (check_range) check_declared(stored, h.type, *stack.declared_range, z0, where);
            scale_into(stored, h.type, h.scaling, out, to);
        }
        if (mirror) mirror_rows(planes, h.dims.x, out);
    };
    return std::make_unique<DecodedPlanes>(dims, out, spacing, where, std::move(decode), ahead);
}

}  // namespace isowall::formats
