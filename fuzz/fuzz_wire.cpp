// Harness: the wire messages (wall_protocol/protocol.h, wall_protocol/protocol_jobs.h). The first
// byte is the tag (any value, so unknown tags are fuzzed too), the rest the message. A message that
// decodes must encode back to exactly its bytes (every field is read, nothing is normalised) and
// decode again to a message of the same tag; a decoder never allocates much more than the message
// holds (fuzz.sh runs this harness with a small -malloc_limit_mb).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz/fuzz_check.h"
#include "wall_protocol/protocol.h"

namespace {

using isowall::fuzz::check;

void check_round_trip(isowall::Tag tag, std::span<const std::byte> bytes) {
    const isowall::Message m = isowall::decode_message(tag, bytes);
    check(isowall::tag_of(m) == tag, "decode gives a message of its tag");
    const std::vector<std::byte> again = isowall::encode(m);
    check(
        again.size() == bytes.size() && std::memcmp(again.data(), bytes.data(), bytes.size()) == 0,
        "encode(decode(bytes)) == bytes");
    const isowall::Message m2 = isowall::decode_message(tag, again);
    check(isowall::tag_of(m2) == tag, "a re-encoded message decodes");
    check(isowall::encode(m2) == again, "a second round trip gives the same bytes");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const auto tag = static_cast<isowall::Tag>(static_cast<std::int8_t>(data[0]));
    const auto bytes = std::as_bytes(std::span(data + 1, size - 1));
    try {
        check_round_trip(tag, bytes);
    } catch (const isowall::WireError&) {
    }
    // decode_as names both kinds when the tag is not the one asked for.
    try {
        (void)isowall::decode_as<isowall::ViewMsg>(tag, bytes);
    } catch (const isowall::WireError&) {
    }
    return 0;
}
