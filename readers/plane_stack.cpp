#include "readers/plane_stack.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <new>
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

bool is_float(VoxelType t) {
    return t == VoxelType::f32 || t == VoxelType::f64;
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

// The scaling against the values the stored type may hold (the range the file declares, when it
// does), before a voxel is read: an integer type's range is known, so a scaling that overflows it
// is refused up front, alike for a whole read and a stream. Float values may be anything; they are
// checked as they are read.
void check_stack_scaling(const PlaneStack& stack, const std::string& where) {
    const Decoded& d = stack.head;
    const auto [lo, hi] = !is_float(d.type) ? stack.declared_range.value_or(type_range(d.type))
                                            : std::pair<double, double>{0, 0};
    const VoxelType out = scaled_type(d.type, d.scaling, lo, hi);
    if (std::string p = scaling_problem(d.scaling, lo, hi, out); !p.empty())
        throw InputError(where, stack.scaling_field, p);
}

// The voxels of a stack whose file cannot prove its size before it is read (a gzip stream: its
// length is known only once inflated, and gzip's trailer holds it modulo 2^32): the buffer grows
// as the bytes arrive, doubling from kStep up to the header's size, so a small file that claims
// gigabytes costs what it delivers, not what it claims. The price for a true file: its last
// growth holds the old buffer beside the new one (less than twice the volume, for a moment).
std::vector<std::byte> read_growing(const PlaneStack& stack, std::uint64_t need,
                                    const std::string& where) {
    check_fits_memory(need, where, stack.size_field);
    constexpr std::uint64_t kStep = std::uint64_t(64) << 20;  // a multiple of every voxel size
    std::vector<std::byte> bytes;
    try {
        while (bytes.size() < need) {
            const std::size_t n = std::size_t(std::min(need - bytes.size(), kStep));
            if (bytes.size() + n > bytes.capacity())
                bytes.reserve(std::size_t(std::min(
                    need, std::max<std::uint64_t>(2 * std::uint64_t(bytes.capacity()), kStep))));
            const std::size_t at = bytes.size();
            bytes.resize(at + n);
            stack.read_unproven(n, bytes.data() + at);
        }
    } catch (const std::bad_alloc&) {
        throw InputError(where, stack.size_field,
                         "cannot allocate " + std::to_string(need) + " bytes");
    }
    return bytes;
}

}  // namespace

Volume read_whole(PlaneStack stack, const std::string& where) {
    check_stack_scaling(stack, where);
    Decoded& d = stack.head;
    const std::uint64_t need = voxel_bytes(d.dims, d.type);
    if (stack.read_unproven) {
        d.bytes = read_growing(stack, need, where);
    } else {
        d.bytes = allocate_voxels(need, where, stack.size_field);
        if (d.dims.z > 0) stack.read(0, d.dims.z, d.bytes.data());
    }
    return finish_volume(std::move(d), where, stack.scaling_field);
}

std::unique_ptr<PlaneSource> stream_planes(PlaneStack stack, const std::string& where) {
    const Decoded& d = stack.head;
    // The checks finish_volume makes, made before the first voxel: a bad scaling or spacing is
    // refused before an import writes anything.
    check_stack_scaling(stack, where);
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
            // Float values were not checked before the first read (check_stack_scaling).
            if (const auto r = is_float(h.type) ? finite_range(stored, h.type) : std::nullopt)
                if (std::string p = scaling_problem(h.scaling, r->first, r->second, out);
                    !p.empty())
                    throw InputError(where, stack.scaling_field,
                                     p + ", near slice " + std::to_string(z0));
            scale_into(stored, h.type, h.scaling, out, to);
        }
        if (mirror) mirror_rows(planes, h.dims.x, out);
    };
    return std::make_unique<DecodedPlanes>(dims, out, spacing, where, std::move(decode), ahead);
}

}  // namespace isowall::formats
