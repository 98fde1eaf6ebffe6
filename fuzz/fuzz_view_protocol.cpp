// Harness: the remote-viewing protocol (remote/view_protocol.h, remote/view_framing.h). The first
// byte picks what is fuzzed:
//   even: one payload. Bytes 1-2 are the type (u16 little-endian, any value, so unknown types are
//         fuzzed too), the rest the payload. A payload that decodes must encode back to exactly
//         its bytes (every field is read, nothing is normalised) and decode again alike.
//   odd:  a byte stream through a FrameParser (payload limit 1 MiB), cut into chunks whose sizes
//         come from byte 1. The messages it yields, framed again, must be exactly the bytes it
//         took; it never holds more than a header and the limit.
// fuzz.sh runs this with -malloc_limit_mb=64: no decoder sizes anything from a claimed length.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz/fuzz_check.h"
#include "remote/view_framing.h"

namespace {

using isowall::fuzz::check;
using namespace isowall::remote;

constexpr std::uint32_t kLimit = std::uint32_t{1} << 20;

// `a` is a prefix of `b`. memcmp is not called with no bytes: an empty vector's data() may be
// null, which memcmp may not be given even for a length of 0 (UBSan's first finding here).
bool is_prefix(const std::vector<std::byte>& a, std::span<const std::byte> b) {
    return a.size() <= b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size()) == 0);
}

void check_payload(std::span<const std::byte> data) {
    if (data.size() < 2) return;
    const auto type = static_cast<RemoteTag>(std::to_integer<unsigned>(data[0]) |
                                             std::to_integer<unsigned>(data[1]) << 8);
    const auto payload = data.subspan(2);
    const RemoteMessage m = decode_payload(type, payload);
    check(type_of(m) == type, "decode gives a message of its type");
    const std::vector<std::byte> again = encode_payload(m);
    check(again.size() == payload.size() && is_prefix(again, payload),
          "encode(decode(payload)) == payload");
    check(encode_payload(decode_payload(type, again)) == again, "a second round trip is the same");
}

void check_stream(std::span<const std::byte> data) {
    if (data.empty()) return;
    const unsigned chunk_seed = std::to_integer<unsigned>(data[0]);
    std::span<const std::byte> stream = data.subspan(1);
    FrameParser parser(kLimit);
    std::vector<std::byte> reframed;
    std::size_t taken = 0;
    for (unsigned i = 0; taken < stream.size(); ++i) {
        // Chunk sizes 1..16, varying with the seed and the chunk's index.
        const std::size_t size =
            std::min<std::size_t>(stream.size() - taken, 1 + (chunk_seed * 7 + i * 13) % 16);
        std::span<const std::byte> chunk = stream.subspan(taken, size);
        try {
            while (!chunk.empty()) {
                if (auto m = parser.next(chunk)) {
                    const auto frame = encode_frame(*m);
                    reframed.insert(reframed.end(), frame.begin(), frame.end());
                }
                check(parser.buffered_capacity() <= kHeaderBytes + kLimit,
                      "the parser holds at most a header and the limit");
            }
        } catch (const isowall::WireError&) {
            // The parser stays failed; what it yielded before the bad frame was the stream's.
            check(is_prefix(reframed, stream),
                  "the messages before an error, framed again, are the stream's bytes");
            return;
        }
        taken += size;
        check(reframed.size() + parser.pending_bytes() == taken,
              "every byte taken is in a message or pending");
        check(is_prefix(reframed, stream), "the messages framed again are the bytes taken");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const auto bytes = std::as_bytes(std::span(data + 1, size - 1));
    try {
        if (data[0] % 2 == 0)
            check_payload(bytes);
        else
            check_stream(bytes);
    } catch (const isowall::WireError&) {
    }
    return 0;
}
