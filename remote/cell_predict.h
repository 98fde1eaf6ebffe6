#pragma once
// The prediction of a `cells` group's integer voxel values (remote/cell_values.h) from the voxels
// both sides already know, and the residual that goes in its place. Internal to the codec.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>

#include <glm/vec3.hpp>

#include "remote/cell_voxels.h"

namespace isowall::remote::cells {

// Classes of how far what is known at 1 voxel disagrees (axis_estimate; capped at 7), one
// neighbour, none (a farther ring or the previous value).
inline constexpr int kSpreadClasses = 10;

template <class T>
struct Prediction {
    T value{};
    int spread = kSpreadClasses - 1;
};

// Rounds sum / n (n > 0) to the nearest integer, halves away from zero, as a T.
template <class T>
T rounded_mean(std::int64_t sum, std::int64_t n) {
    return static_cast<T>(sum >= 0 ? (sum + n / 2) / n : -((-sum + n / 2) / n));
}

// The known face neighbours of p at `step` voxels: their values by axis and side.
struct Ring {
    std::int64_t value[3][2] = {};
    bool known[3][2] = {};
    std::int64_t sum = 0, n = 0, lo = 0, hi = 0;
};

template <class T>
Ring ring_at(const BoxVoxels<T>& held, glm::ivec3 p, int step) {
    Ring r;
    for (int a = 0; a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
            glm::ivec3 q = p;
            q[a] += side == 0 ? -step : step;
            T value;
            if (!held.known(q, value)) continue;
            const auto v = static_cast<std::int64_t>(value);
            r.value[a][side] = v;
            r.known[a][side] = true;
            r.lo = r.n == 0 ? v : std::min(r.lo, v);
            r.hi = r.n == 0 ? v : std::max(r.hi, v);
            r.sum += v;
            ++r.n;
        }
    return r;
}

// What the ring at 1 voxel says of p, axis by axis: where both sides are known, their mean; where
// one is, its value carried on by half the slope to the voxel beyond it (when that one is known
// too), which a surface's ramp continues. The prediction is the estimates' mean, rounded. Against
// the mean of the face neighbours alone, on one frame's groups of each shared volume at its
// isovalues (isowall_bench_codec): 0.6-9.1% fewer cells bytes on 11 of the 12, 1.1% more on the MR
// head at 112.
//
// How far the axes' estimates disagree is the prediction's context (its spread class) where two
// or more axes give one: the bit width of max - min in units of kSpreadUnit values (capped), so
// that disagreements within a scanner's noise share a class. Against the face neighbours'
// max - min, it took another 0.7-3.0% off every one of the 12 rows; in units of 1 value, 0.5-2.9%.
inline constexpr std::int64_t kSpreadUnit = 4;

template <class T>
Prediction<T> axis_estimate(const BoxVoxels<T>& held, glm::ivec3 p, const Ring& r) {
    // Twice each axis's estimate: integers throughout.
    std::int64_t twice = 0, axes = 0, lo_twice = 0, hi_twice = 0;
    for (int a = 0; a < 3; ++a) {
        const bool lo = r.known[a][0], hi = r.known[a][1];
        if (!lo && !hi) continue;
        const std::int64_t near = r.value[a][lo ? 0 : 1];
        glm::ivec3 beyond = p;
        beyond[a] += lo ? -2 : 2;
        T far;
        const std::int64_t e = lo && hi                  ? r.value[a][0] + r.value[a][1]
                               : held.known(beyond, far) ? 3 * near - far
                                                         : 2 * near;
        lo_twice = axes == 0 ? e : std::min(lo_twice, e);
        hi_twice = axes == 0 ? e : std::max(hi_twice, e);
        twice += e;
        ++axes;
    }
    const std::int64_t guess = rounded_mean<std::int64_t>(twice, 2 * axes);
    Prediction<T> out{static_cast<T>(std::clamp<std::int64_t>(
        guess, std::numeric_limits<T>::lowest(), std::numeric_limits<T>::max()))};
    const auto apart = static_cast<std::uint64_t>(
        axes >= 2 ? (hi_twice - lo_twice) / (2 * kSpreadUnit) : r.hi - r.lo);
    const int width = static_cast<int>(std::bit_width(apart));
    out.spread = r.n == 1 ? kSpreadClasses - 2 : std::min(width, kSpreadClasses - 3);
    return out;
}

template <class T>
Prediction<T> predict(const BoxVoxels<T>& held, glm::ivec3 p, T previous) {
    if constexpr (!std::is_integral_v<T>) {
        return {};
    } else {
        // The nearest ring that holds a known voxel: 1 voxel away, else 2, else 4 (a coarse
        // level's corners lie 2^level apart, and their neighbours there are its other corners).
        for (int step = 1; step <= 4; step *= 2) {
            const Ring r = ring_at(held, p, step);
            if (r.n == 0) continue;
            if (step > 1) return {rounded_mean<T>(r.sum, r.n), kSpreadClasses - 1};
            return axis_estimate(held, p, r);
        }
        return {previous, kSpreadClasses - 1};
    }
}

template <class T>
auto residual(T value, T predicted) {
    if constexpr (!std::is_integral_v<T>) {
        return value;
    } else {
        using U = std::make_unsigned_t<T>;
        using S = std::make_signed_t<T>;
        const auto d =
            static_cast<S>(static_cast<U>(static_cast<U>(value) - static_cast<U>(predicted)));
        return static_cast<U>(static_cast<U>(static_cast<U>(d) << 1) ^
                              static_cast<U>(d >> (8 * sizeof(T) - 1)));
    }
}

template <class T, class R>
T from_residual(R r, T predicted) {
    if constexpr (!std::is_integral_v<T>) {
        return r;
    } else {
        using U = std::make_unsigned_t<T>;
        const auto d =
            static_cast<U>(static_cast<U>(r >> 1) ^ static_cast<U>(-static_cast<U>(r & 1)));
        return static_cast<T>(static_cast<U>(static_cast<U>(predicted) + d));
    }
}

template <class T>
using Residual = decltype(residual(T{}, T{}));

}  // namespace isowall::remote::cells
