#pragma once
// The exact values of a `cells` group sent to a step first (cell_codec.h: a full-resolution
// group's gradient voxels, on a slow link): each stepped value's offset in its bin (Bins::low),
// `shift` bits a value, packed from the lowest bit of the first byte up, in the order the values
// were coded. Nothing is predicted: the offsets below a bin's width are about as random as the
// noise of the scan they come from. Internal to the codec.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace isowall::remote::cells {

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
