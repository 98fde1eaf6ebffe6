#pragma once
// A binary range coder with adaptive bit probabilities, after LZMA's (Igor Pavlov's rc: 11-bit
// probabilities moved 1/32 of the way to each bit seen, a 32-bit range renormalised a byte at a
// time, carries propagated through a cached byte). The `cells` encoding codes its voxel values
// through it (remote/cell_values.h): against zstd on byte planes it lets each value's code depend
// on its context, which the planes cannot.
//
// The decoder reads exactly the bytes the encoder wrote: five at the start and one per
// renormalisation, the same on both sides. So a stream is whole when the decoder ends on its last
// byte, and a byte wanted past the end (read as 0, counted) means it was cut or forged.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace isowall::remote {

// An adaptive probability that the next bit is 0, in 1/2048ths. It stays within [31, 2017]
// (the update moves it by 1/32 of its distance to 0 or 2048, rounded down), so a bit never costs
// less than log2(2048/2017) = 0.022 bits: a stream of n bytes holds a bounded number of decisions.
struct BitProbability {
    std::uint16_t p = 1024;
};

namespace range {
inline constexpr int kProbabilityBits = 11;
inline constexpr std::uint32_t kOne = 1u << kProbabilityBits;
inline constexpr int kMoveBits = 5;
inline constexpr std::uint32_t kTop = 1u << 24;
}  // namespace range

class RangeEncoder {
  public:
    void bit(BitProbability& prob, unsigned b) {
        const std::uint32_t bound = (range_ >> range::kProbabilityBits) * prob.p;
        if (b == 0) {
            range_ = bound;
            prob.p =
                static_cast<std::uint16_t>(prob.p + ((range::kOne - prob.p) >> range::kMoveBits));
        } else {
            low_ += bound;
            range_ -= bound;
            prob.p = static_cast<std::uint16_t>(prob.p - (prob.p >> range::kMoveBits));
        }
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
            prob.p =
                static_cast<std::uint16_t>(prob.p + ((range::kOne - prob.p) >> range::kMoveBits));
            b = 0;
        } else {
            code_ -= bound;
            range_ -= bound;
            prob.p = static_cast<std::uint16_t>(prob.p - (prob.p >> range::kMoveBits));
            b = 1;
        }
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
