#pragma once
// A binary range coder with adaptive bit probabilities, after LZMA's (Igor Pavlov's rc: a
// probability moved 1/32 of the way to each bit seen, a 32-bit range renormalised a byte at a
// time, carries propagated through a cached byte). Unlike LZMA's, a probability learns fast while
// it is young: its first bits move it by 1/2, then 1/4, 1/8 and 1/16 of the way, about as a count
// of the bits seen would (1/(n + 2)), and 1/32 from its 30th bit on. A cells group starts its
// models afresh and codes a few thousand values over a few thousand probabilities, most of which
// see few bits: on one frame's groups of each shared volume at its isovalues
// (isowall_bench_codec), this took 2.6-6.4% off the cells bytes against LZMA's fixed 1/32. The
// `cells` encoding codes its voxel values through it (remote/cell_values.h): against zstd on byte
// planes it lets each value's code depend on its context, which the planes cannot.
//
// The decoder reads exactly the bytes the encoder wrote: five at the start and one per
// renormalisation, the same on both sides. So a stream is whole when the decoder ends on its last
// byte, and a byte wanted past the end (read as 0, counted) means it was cut or forged.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace isowall::remote {

// An adaptive probability that the next bit is 0, in 1/65536ths, and how many bits it has seen
// (up to kSettled). It stays within [kLeast, kMost] = [31, 2017] / 2048, so a bit never costs less
// than log2(2048/2017) = 0.022 bits: a stream of n bytes holds a bounded number of decisions.
struct BitProbability {
    std::uint16_t p = 1u << 15;
    std::uint8_t seen = 0;
};

namespace range {
inline constexpr int kProbabilityBits = 16;
inline constexpr std::uint32_t kOne = 1u << kProbabilityBits;
inline constexpr int kMoveBits = 5;
// From this many bits seen on, a probability moves by 1/2^kMoveBits.
inline constexpr std::uint8_t kSettled = (1u << kMoveBits) - 2;
inline constexpr std::uint32_t kLeast = 31u << 5, kMost = kOne - kLeast;
inline constexpr std::uint32_t kTop = 1u << 24;
// Moves `prob` toward the bit seen: by 1/2^shift of its distance to 0 or 1, shift = the bit width
// of (seen + 2) less one, at most kMoveBits; then kept within [kLeast, kMost].
inline void update(BitProbability& prob, unsigned b) {
    const int shift = std::min(kMoveBits, static_cast<int>(std::bit_width(prob.seen + 2u)) - 1);
    if (prob.seen < kSettled) ++prob.seen;
    std::uint32_t p = prob.p;
    if (b == 0)
        p += (kOne - p) >> shift;
    else
        p -= p >> shift;
    prob.p = static_cast<std::uint16_t>(std::clamp(p, kLeast, kMost));
}
}  // namespace range

class RangeEncoder {
  public:
    void bit(BitProbability& prob, unsigned b) {
        const std::uint32_t bound = (range_ >> range::kProbabilityBits) * prob.p;
        if (b == 0) {
            range_ = bound;
        } else {
            low_ += bound;
            range_ -= bound;
        }
        range::update(prob, b);
        normalise();
    }
    // The low `n` bits of v (n <= 32), most significant first, at one bit each.
    void direct(std::uint32_t v, int n) {
        for (int i = n - 1; i >= 0; --i) {
            range_ >>= 1;
            if ((v >> i) & 1) low_ += range_;
            normalise();
        }
    }
    // The stream; the encoder is spent.
    std::vector<std::uint8_t> finish() {
        for (int i = 0; i < 5; ++i) shift_low();
        return std::move(out_);
    }

  private:
    void normalise() {
        while (range_ < range::kTop) {
            range_ <<= 8;
            shift_low();
        }
    }
    // Emits the byte above the low 24 bits once no carry can reach it: a run of 0xff bytes waits
    // in cache_size_ until a byte below 0xff (or a carry) settles it.
    void shift_low() {
        if (static_cast<std::uint32_t>(low_) < 0xff000000u || (low_ >> 32) != 0) {
            const auto carry = static_cast<std::uint8_t>(low_ >> 32);
            std::uint8_t b = cache_;
            do {
                out_.push_back(static_cast<std::uint8_t>(b + carry));
                b = 0xff;
            } while (--cache_size_ != 0);
            cache_ = static_cast<std::uint8_t>(static_cast<std::uint32_t>(low_) >> 24);
        }
        ++cache_size_;
        low_ = (low_ & 0x00ffffffu) << 8;
    }
    std::uint64_t low_ = 0;
    std::uint32_t range_ = 0xffffffffu;
    std::uint8_t cache_ = 0;
    std::uint64_t cache_size_ = 1;
    std::vector<std::uint8_t> out_;
};

class RangeDecoder {
  public:
    explicit RangeDecoder(std::span<const std::uint8_t> bytes) : bytes_(bytes) {
        for (int i = 0; i < 5; ++i) code_ = code_ << 8 | next();
    }
    unsigned bit(BitProbability& prob) {
        const std::uint32_t bound = (range_ >> range::kProbabilityBits) * prob.p;
        unsigned b;
        if (code_ < bound) {
            range_ = bound;
            b = 0;
        } else {
            code_ -= bound;
            range_ -= bound;
            b = 1;
        }
        range::update(prob, b);
        normalise();
        return b;
    }
    std::uint32_t direct(int n) {
        std::uint32_t v = 0;
        for (int i = 0; i < n; ++i) {
            range_ >>= 1;
            unsigned b = 0;
            if (code_ >= range_) {
                code_ -= range_;
                b = 1;
            }
            v = v << 1 | b;
            normalise();
        }
        return v;
    }
    // Bytes wanted past the end of the stream (read as 0).
    std::size_t overrun() const { return overrun_; }
    // The stream was read to its last byte and not past it: what the encoder wrote, whole.
    bool at_end() const { return overrun_ == 0 && pos_ == bytes_.size(); }

  private:
    void normalise() {
        while (range_ < range::kTop) {
            range_ <<= 8;
            code_ = code_ << 8 | next();
        }
    }
    std::uint32_t next() {
        if (pos_ < bytes_.size()) return bytes_[pos_++];
        ++overrun_;
        return 0;
    }
    std::span<const std::uint8_t> bytes_;
    std::size_t pos_ = 0, overrun_ = 0;
    std::uint32_t range_ = 0xffffffffu, code_ = 0;
};

}  // namespace isowall::remote
