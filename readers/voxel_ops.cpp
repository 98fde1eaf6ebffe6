#include "readers/voxel_ops.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include <glm/mat3x3.hpp>

#include "core/error.h"
#include "volume/load_checks.h"

namespace isowall::formats {
namespace {

bool is_integer_type(VoxelType t) {
    return t != VoxelType::f32 && t != VoxelType::f64;
}

// The smallest integer type holding [lo, hi], or nullopt.
std::optional<VoxelType> smallest_integer_type(double lo, double hi) {
    const auto fits = [&](auto v) {
        using T = decltype(v);
        return lo >= double(std::numeric_limits<T>::lowest()) &&
               hi <= double(std::numeric_limits<T>::max());
    };
    if (fits(std::uint8_t{})) return VoxelType::u8;
    if (fits(std::int8_t{})) return VoxelType::i8;
    if (fits(std::uint16_t{})) return VoxelType::u16;
    if (fits(std::int16_t{})) return VoxelType::i16;
    if (fits(std::uint32_t{})) return VoxelType::u32;
    if (fits(std::int32_t{})) return VoxelType::i32;
    return std::nullopt;
}

// Every stored value through the scaling into Out, at `out`.
template <class In, class Out>
void scale_to(std::span<const std::byte> bytes, Scaling s, std::byte* out) {
    const std::size_t n = bytes.size() / sizeof(In);
    for (std::size_t i = 0; i < n; ++i) {
        In v;
        std::memcpy(&v, bytes.data() + i * sizeof(In), sizeof(In));
        const Out o = static_cast<Out>(s.slope * double(v) + s.intercept);
        std::memcpy(out + i * sizeof(Out), &o, sizeof(Out));
    }
}

template <class In, class Out>
std::vector<std::byte> scaled(std::span<const std::byte> bytes, Scaling s) {
    std::vector<std::byte> out(bytes.size() / sizeof(In) * sizeof(Out));
    scale_to<In, Out>(bytes, s, out.data());
    return out;
}

std::string number_text(double v) {
    std::ostringstream s;
    s.precision(9);
    s << v;
    return s.str();
}

}  // namespace

std::string scaling_problem(Scaling s, double lo, double hi, VoxelType out) {
    if (!std::isfinite(s.slope) || !std::isfinite(s.intercept))
        return "the value scaling is not a finite number (slope " + number_text(s.slope) +
               ", intercept " + number_text(s.intercept) + ")";
    if (s.slope == 0) return "a scaling slope of 0 makes every voxel the same value";
    const double top = out == VoxelType::f32 ? double(std::numeric_limits<float>::max())
                                             : std::numeric_limits<double>::max();
    for (const double stored : {lo, hi}) {
        const double v = s.slope * stored + s.intercept;
        if (!(std::abs(v) <= top))
            return "value = " + number_text(s.slope) + " * stored + " + number_text(s.intercept) +
                   " overflows " + std::string(type_name(out)) + " for stored values in [" +
                   number_text(lo) + ", " + number_text(hi) + "] (" + number_text(stored) +
                   " gives " + number_text(v) + ")";
    }
    return {};
}

std::optional<std::pair<double, double>> finite_range(std::span<const std::byte> bytes,
                                                      VoxelType type) {
    return dispatch_voxel_type(type, [&](auto zero) -> std::optional<std::pair<double, double>> {
        using T = decltype(zero);
        const std::size_t n = bytes.size() / sizeof(T);
        std::optional<std::pair<double, double>> range;
        for (std::size_t i = 0; i < n; ++i) {
            T v;
            std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
            const double d = double(v);
            if (!std::isfinite(d)) continue;
            if (!range) range = {d, d};
            range->first = std::min(range->first, d);
            range->second = std::max(range->second, d);
        }
        return range;
    });
}

ScaledVoxels apply_scaling(std::vector<std::byte> bytes, VoxelType type, Scaling s,
                           const std::string& where, const std::string& field) {
    if (std::string p = scaling_problem(s, 0, 0, VoxelType::f64); !p.empty())
        throw InputError(where, field, p);
    if (s.identity()) return {std::move(bytes), type};
    // One pass for the values the file holds: an integer type's range chooses the type the
    // scaled values need, and every type's, scaled, must be numbers in that type.
    const auto range = finite_range(bytes, type);
    const auto [lo, hi] = range.value_or(std::pair<double, double>{0, 0});
    const VoxelType out = scaled_type(type, s, lo, hi);
    if (range)
        if (std::string p = scaling_problem(s, lo, hi, out); !p.empty())
            throw InputError(where, field, p);
    std::vector<std::byte> result = dispatch_voxel_type(type, [&](auto in) {
        return dispatch_voxel_type(
            out, [&](auto o) { return scaled<decltype(in), decltype(o)>(bytes, s); });
    });
    return {std::move(result), out};
}

VoxelType scaled_type(VoxelType type, Scaling s, double lo, double hi) {
    if (s.identity()) return type;
    const bool integral = std::trunc(s.slope) == s.slope && std::trunc(s.intercept) == s.intercept;
    if (integral && is_integer_type(type)) {
        const double a = s.slope * lo + s.intercept, b = s.slope * hi + s.intercept;
        if (const auto t = smallest_integer_type(std::min(a, b), std::max(a, b))) return *t;
    }
    return type == VoxelType::f64 ? VoxelType::f64 : VoxelType::f32;
}

void scale_into(std::span<const std::byte> in, VoxelType type, Scaling s, VoxelType out_type,
                std::byte* out) {
    dispatch_voxel_type(type, [&](auto i) {
        dispatch_voxel_type(out_type,
                            [&](auto o) { scale_to<decltype(i), decltype(o)>(in, s, out); });
    });
}

void mirror_rows(std::span<std::byte> bytes, int width, VoxelType type) {
    const std::size_t size = voxel_size(type);
    const std::size_t row = static_cast<std::size_t>(width) * size;
    const std::size_t rows = bytes.size() / std::max<std::size_t>(row, 1);
    for (std::size_t r = 0; r < rows; ++r) {
        std::byte* p = bytes.data() + r * row;
        for (int a = 0, b = width - 1; a < b; ++a, --b)
            std::swap_ranges(p + std::size_t(a) * size, p + std::size_t(a + 1) * size,
                             p + std::size_t(b) * size);
    }
}

std::vector<std::byte> to_float32(std::span<const std::byte> bytes, VoxelType type, Scaling s) {
    return dispatch_voxel_type(type,
                               [&](auto in) { return scaled<decltype(in), float>(bytes, s); });
}

void make_rotation(std::vector<std::byte>& bytes, glm::ivec3 dims, VoxelType type,
                   glm::vec3 spacing, Orientation& o) {
    if (glm::determinant(o.axes) >= 0) return;
    mirror_rows(bytes, dims.x, type);
    o.origin += o.axes[0] * (spacing.x * float(dims.x - 1));
    o.axes[0] = -o.axes[0];
}

std::string orientation_letters(const glm::mat3& axes) {
    std::string out;
    for (int c = 0; c < 3; ++c) {
        const glm::vec3 v = axes[c];
        int k = 0;
        for (int i = 1; i < 3; ++i)
            if (std::abs(v[i]) > std::abs(v[k])) k = i;
        static constexpr char kPlus[] = {'L', 'P', 'S'}, kMinus[] = {'R', 'A', 'I'};
        out += v[k] >= 0 ? kPlus[k] : kMinus[k];
    }
    return out;
}

Box3 patient_bounds(const Volume& v) {
    const Box3 b = v.bounds();
    const Orientation& o = v.orientation();
    Box3 out;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 c((i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y,
                          (i & 4) ? b.max.z : b.min.z);
        out.merge(o.origin + o.axes * c);
    }
    return out;
}

Volume finish_volume(Decoded d, const std::string& where, const std::string& scaling_field) {
    const VoxelType stored = d.type;
    ScaledVoxels sv = apply_scaling(std::move(d.bytes), d.type, d.scaling, where, scaling_field);
    for (int a = 0; a < 3; ++a)
        if (std::string p = spacing_problem(d.spacing[a], d.dims[a], a); !p.empty())
            throw InputError(where, "spacing", p);
    make_rotation(sv.bytes, d.dims, sv.type, d.spacing, d.orientation);
    Volume v(d.dims, sv.type, d.spacing, std::move(sv.bytes), where);
    v.set_files(std::move(d.files));
    v.set_orientation(d.orientation);
    v.add_fact("format", d.format);
    for (VolumeFact& f : d.facts) v.add_fact(std::move(f.name), std::move(f.value));
    if (!d.scaling.identity())
        v.add_fact("scaling", "value = " + number_text(d.scaling.slope) + " * stored " +
                                  (d.scaling.intercept < 0 ? "- " : "+ ") +
                                  number_text(std::abs(d.scaling.intercept)) +
                                  " (applied: " + std::string(type_name(stored)) + " -> " +
                                  std::string(type_name(sv.type)) + ")");
    return v;
}

}  // namespace isowall::formats
