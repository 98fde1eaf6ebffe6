#pragma once
// Values to a step (Bins), and the exact values of a `cells` group sent to a step first
// (cell_codec.h: a full-resolution group's gradient voxels, on a slow link): each stepped value's
// offset in its bin (Bins::low), `shift` bits a value, packed from the lowest bit of the first byte
// up, in the order the values were coded. Nothing is predicted: the offsets below a bin's width are
// about as random as the noise of the scan they come from. Internal to the codec.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace isowall::remote::cells {

// Values to a step of 2^shift (cell_codec.h: a coarse pass's, a full-resolution group's
// gradients'): bins aligned on the isovalue, so every value keeps its side of it, and every unit
// its case and crossed edges; only where the surface cuts an edge moves, by at most half a step
// over the edge's difference. A value goes as its bin's difference to the predicted value's bin;
// both sides then hold the bin's middle.
template <class T>
struct Bins {
    double iso = 0;
    int shift = 0;  // 0: the values exact; else at least 2 (a difference of bins then fits T)

    std::int64_t of(T v) const {
        const double k = std::floor((static_cast<double>(v) - iso) / step());
        constexpr double kFar = 0x1p62;  // past any bin of a 32-bit voxel's values
        return static_cast<std::int64_t>(k < -kFar ? -kFar : k > kFar ? kFar : k);
    }
    // The bin's middle, rounded half up: on the isovalue's side of the bin (the step is 2 or
    // more), and clamped into T, which keeps it in any bin a value of T was in.
    T middle(std::int64_t k) const {
        const double x = std::floor(iso + (static_cast<double>(k) + 0.5) * step() + 0.5);
        const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
        const double hi = static_cast<double>(std::numeric_limits<T>::max());
        return static_cast<T>(x < lo ? lo : x > hi ? hi : x);
    }
    double step() const { return std::ldexp(1.0, shift); }
    // The least integer in bin k: a value's exact offset in its bin counts from it.
    std::int64_t low(std::int64_t k) const {
        return static_cast<std::int64_t>(std::ceil(iso + static_cast<double>(k) * step()));
    }
};

class ExactBitsWriter {
  public:
    // The low `bits` (1..32) bits of `offset`.
    void put(std::uint64_t offset, int bits) {
        for (int b = 0; b < bits; ++b, ++used_) {
            if (used_ % 8 == 0) bytes_.push_back(0);
            bytes_.back() =
                static_cast<std::uint8_t>(bytes_.back() | ((offset >> b) & 1u) << (used_ % 8));
        }
    }
    std::vector<std::uint8_t> take() { return std::move(bytes_); }

  private:
    std::vector<std::uint8_t> bytes_;
    std::uint64_t used_ = 0;
};

// What is wrong with `bytes` as `count` values of `bits` each, or empty: they must be exactly as
// many bytes as the values take, and the last byte's unused bits zero.
inline std::string exact_bits_problem(std::span<const std::uint8_t> bytes, std::uint64_t count,
                                      int bits) {
    const std::uint64_t need = (count * static_cast<std::uint64_t>(bits) + 7) / 8;
    if (bytes.size() != need)
        return std::to_string(bytes.size()) + " bytes of exact values, expected " +
               std::to_string(need) + " for " + std::to_string(count) + " values of " +
               std::to_string(bits) + " bits";
    const std::uint64_t tail = count * static_cast<std::uint64_t>(bits) % 8;
    if (tail != 0 && (bytes.back() >> tail) != 0)
        return "the exact values' unused bits are not zero";
    return {};
}

class ExactBitsReader {
  public:
    // Over bytes exact_bits_problem finds nothing wrong with.
    explicit ExactBitsReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
    std::uint64_t get(int bits) {
        std::uint64_t v = 0;
        for (int b = 0; b < bits; ++b, ++used_)
            v |= static_cast<std::uint64_t>(bytes_[used_ / 8] >> (used_ % 8) & 1u) << b;
        return v;
    }

  private:
    std::span<const std::uint8_t> bytes_;
    std::uint64_t used_ = 0;
};

}  // namespace isowall::remote::cells
