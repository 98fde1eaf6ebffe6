#include "remote/view_framing.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>

namespace isowall::remote {
namespace {

std::uint16_t get_u16(std::span<const std::byte> b) {
    return static_cast<std::uint16_t>(std::to_integer<unsigned>(b[0]) |
                                      std::to_integer<unsigned>(b[1]) << 8);
}

std::uint32_t get_u32(std::span<const std::byte> b) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = v << 8 | std::to_integer<std::uint32_t>(b[i]);
    return v;
}

void put_le(std::span<std::byte> out, std::uint32_t v) {
    for (std::byte& b : out) {
        b = static_cast<std::byte>(v & 0xff);
        v >>= 8;
    }
}

std::string hex(std::span<const std::byte> b) {
    std::string s;
    for (std::byte x : b) {
        char buf[4];
        std::snprintf(buf, sizeof buf, "%s%02x", s.empty() ? "" : " ",
                      std::to_integer<unsigned>(x));
        s += buf;
    }
    return s;
}

[[noreturn]] void header_error(const std::string& why) {
    throw WireError("view protocol header: " + why);
}

}  // namespace

FrameHeader decode_header(std::span<const std::byte, kHeaderBytes> bytes,
                          std::uint32_t max_payload_bytes) {
    const auto magic = bytes.first<4>();
    if (!std::equal(magic.begin(), magic.end(), kMagic.begin()))
        header_error("magic: expected 49 57 56 50 (\"IWVP\"), got " + hex(magic));
    FrameHeader h;
    h.version = get_u16(bytes.subspan<4, 2>());
    if (h.version != kProtocolVersion)
        header_error("version: expected " + std::to_string(kProtocolVersion) + ", got " +
                     std::to_string(h.version));
    const std::uint16_t type = get_u16(bytes.subspan<6, 2>());
    if (type < 1 || type > kLastRemoteTag)
        header_error("type: expected 1.." + std::to_string(kLastRemoteTag) + ", got " +
                     std::to_string(type));
    h.type = static_cast<RemoteTag>(type);
    h.payload_bytes = get_u32(bytes.subspan<8, 4>());
    if (h.payload_bytes > max_payload_bytes)
        header_error("length: " + std::to_string(h.payload_bytes) + " bytes is over the limit of " +
                     std::to_string(max_payload_bytes) + " (" + to_string(h.type) + " message)");
    return h;
}

void put_header(std::span<std::byte, kHeaderBytes> out, const FrameHeader& h) {
    std::copy(kMagic.begin(), kMagic.end(), out.begin());
    put_le(out.subspan<4, 2>(), h.version);
    put_le(out.subspan<6, 2>(), static_cast<std::uint16_t>(h.type));
    put_le(out.subspan<8, 4>(), h.payload_bytes);
}

std::vector<std::byte> encode_frame(const RemoteMessage& m) {
    const std::vector<std::byte> payload = encode_payload(m);
    if (payload.size() > std::numeric_limits<std::uint32_t>::max())
        throw WireError(std::string(to_string(type_of(m))) + " message: " +
                        std::to_string(payload.size()) + " bytes do not fit a frame");
    std::vector<std::byte> out(kHeaderBytes + payload.size());
    put_header(std::span(out).first<kHeaderBytes>(),
               {kProtocolVersion, type_of(m), static_cast<std::uint32_t>(payload.size())});
    std::copy(payload.begin(), payload.end(), out.begin() + kHeaderBytes);
    return out;
}

RemoteMessage decode_frame(std::span<const std::byte> bytes, std::uint32_t max_payload_bytes) {
    if (bytes.size() < kHeaderBytes)
        header_error("truncated: " + std::to_string(bytes.size()) + " of 12 bytes");
    const FrameHeader h = decode_header(bytes.first<kHeaderBytes>(), max_payload_bytes);
    const auto payload = bytes.subspan(kHeaderBytes);
    if (payload.size() != h.payload_bytes)
        throw WireError(std::string(to_string(h.type)) + " message: the header says " +
                        std::to_string(h.payload_bytes) + " payload bytes, the frame has " +
                        std::to_string(payload.size()) +
                        (payload.size() > h.payload_bytes ? " (trailing bytes)" : " (truncated)"));
    return decode_payload(h.type, payload);
}

void FrameParser::fail(const std::string& why) {
    failed_ = why;
    throw WireError(why);
}

std::optional<RemoteMessage> FrameParser::next(std::span<const std::byte>& input) {
    if (failed_) throw WireError(*failed_);
    if (!header_) {
        const std::size_t n = std::min(input.size(), kHeaderBytes - header_filled_);
        std::copy_n(input.begin(), n, header_bytes_.begin() + header_filled_);
        header_filled_ += n;
        input = input.subspan(n);
        if (header_filled_ < kHeaderBytes) return std::nullopt;
        try {
            header_ = decode_header(header_bytes_, max_payload_bytes_);
        } catch (const WireError& e) {
            fail(e.what());
        }
    }
    // Grow by what arrived (at most doubling), never to the header's length at once: a header
    // alone claiming 64 MiB costs nothing until the bytes come.
    const std::size_t n =
        std::min<std::size_t>(input.size(), header_->payload_bytes - payload_.size());
    if (payload_.size() + n > payload_.capacity())
        payload_.reserve(std::min<std::size_t>(
            header_->payload_bytes, std::max(payload_.size() + n, 2 * payload_.capacity())));
    payload_.insert(payload_.end(), input.begin(), input.begin() + static_cast<std::ptrdiff_t>(n));
    input = input.subspan(n);
    if (payload_.size() < header_->payload_bytes) return std::nullopt;

    const RemoteTag type = header_->type;
    header_.reset();
    header_filled_ = 0;
    std::vector<std::byte> payload;
    payload.swap(payload_);  // the next message starts small again
    try {
        return decode_payload(type, payload);
    } catch (const WireError& e) {
        fail(e.what());
    }
}

}  // namespace isowall::remote
