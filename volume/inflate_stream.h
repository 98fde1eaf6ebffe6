#pragma once
// A gzip or zlib stream (gzip members back to back, as gzip allows) inflated a piece at a time
// from bytes in memory, usually a memory-mapped file: what a streamed import reads a compressed
// NRRD or MetaImage through, so that neither the compressed nor the inflated data is held whole.
// The checks are decode_gzip's (nrrd_decode.h): data that ends early, is corrupt, inflates past
// its length or is followed by other bytes is an InputError naming `where` and `field`.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace isowall {

class InflateStream {
  public:
    // `total`: the bytes the whole stream inflates to.
    InflateStream(std::span<const std::byte> in, std::uint64_t total, std::string where,
                  std::string field);
    ~InflateStream();
    InflateStream(const InflateStream&) = delete;
    InflateStream& operator=(const InflateStream&) = delete;
    // The next `n` inflated bytes into `to`; the call that reaches `total` also checks that the
    // stream ends there. Input already inflated is let go of (its pages of a mapped file).
    void read(std::byte* to, std::size_t n);

  private:
    struct State;
    std::unique_ptr<State> s_;
};

// Whether `b` starts with the gzip magic number (zlib's raw deflate and zlib streams do not).
inline bool starts_gzip(std::span<const std::byte> b) {
    return b.size() >= 2 && b[0] == std::byte{0x1f} && b[1] == std::byte{0x8b};
}

}  // namespace isowall
