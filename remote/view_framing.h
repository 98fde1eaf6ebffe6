#pragma once
// The remote-viewing protocol on a byte stream (a TCP connection): every message is a 12-byte
// header, then its payload (view_protocol.h).
//
//   offset  size  field
//   0       4     magic "IWVP" (0x49 0x57 0x56 0x50)
//   4       2     protocol version, u16 little-endian (kProtocolVersion)
//   6       2     message type, u16 little-endian (RemoteTag, 1..kLastRemoteTag)
//   8       4     payload length in bytes, u32 little-endian (at most the receiver's limit)
//
// A receiver checks the header as soon as it has its 12 bytes, before it holds any of the
// payload, so a bad magic, another version, an unknown type or a length over its limit is an
// error without a byte of payload buffered: a connection costs at most header + limit.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "remote/view_protocol.h"

namespace isowall::remote {

inline constexpr std::array<std::byte, 4> kMagic = {std::byte{'I'}, std::byte{'W'}, std::byte{'V'},
                                                    std::byte{'P'}};
inline constexpr std::uint16_t kProtocolVersion = 1;
inline constexpr std::size_t kHeaderBytes = 12;
// The default payload limit of a receiver: every valid message fits (a group's encoded bytes are
// at most kMaxGroupBytes, 32 MiB), and one connection holds at most this much plus a header.
inline constexpr std::uint32_t kDefaultMaxPayloadBytes = std::uint32_t{64} << 20;

struct FrameHeader {
    std::uint16_t version = kProtocolVersion;
    RemoteTag type = RemoteTag::bye;
    std::uint32_t payload_bytes = 0;
};

// The header's 12 bytes, checked: WireError naming the field ("view protocol header: magic: ...",
// "... length: 70000000 bytes is over the limit of 67108864 (group message)").
FrameHeader decode_header(std::span<const std::byte, kHeaderBytes> bytes,
                          std::uint32_t max_payload_bytes = kDefaultMaxPayloadBytes);
void put_header(std::span<std::byte, kHeaderBytes> out, const FrameHeader& h);

// Header and payload of one message, ready to send. Throws WireError when the payload is over
// 4 GiB - 1 (the header cannot say its length); the receiver's limit is the receiver's.
std::vector<std::byte> encode_frame(const RemoteMessage& m);
// Exactly one whole frame: a short buffer or bytes after the payload are errors.
RemoteMessage decode_frame(std::span<const std::byte> bytes,
                           std::uint32_t max_payload_bytes = kDefaultMaxPayloadBytes);

// Cuts a byte stream into messages, whatever the chunks it arrives in (as recv gives them):
//
//   std::span<const std::byte> chunk(buffer, received);
//   while (!chunk.empty())
//       if (auto m = parser.next(chunk)) handle(*m);
//
// next() takes bytes from the front of `input` until a message is complete (and returns it, the
// rest of `input` left for the next call) or `input` is used up (nullopt). It holds at most one
// header and one payload of at most `max_payload_bytes`, grown as the bytes arrive, never sized
// from the header alone. A WireError (bad header, a payload that does not decode) leaves the
// parser failed: every later call throws the same error, since the stream cannot be resynced.
class FrameParser {
  public:
    explicit FrameParser(std::uint32_t max_payload_bytes = kDefaultMaxPayloadBytes)
        : max_payload_bytes_(max_payload_bytes) {}

    std::optional<RemoteMessage> next(std::span<const std::byte>& input);
    // Bytes of a message begun but not complete: a stream that ends here was cut short.
    std::size_t pending_bytes() const { return header_filled_ + payload_.size(); }
    // The bytes held for the message being read (at most kHeaderBytes + the limit).
    std::size_t buffered_capacity() const { return kHeaderBytes + payload_.capacity(); }

  private:
    [[noreturn]] void fail(const std::string& why);

    std::uint32_t max_payload_bytes_;
    std::array<std::byte, kHeaderBytes> header_bytes_{};
    std::size_t header_filled_ = 0;
    std::optional<FrameHeader> header_;  // set once header_bytes_ is full and checked
    std::vector<std::byte> payload_;
    std::optional<std::string> failed_;
};

}  // namespace isowall::remote
