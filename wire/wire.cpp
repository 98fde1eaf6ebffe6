#include "wire/wire.h"

namespace isowall {

MessageReader::MessageReader(std::span<const std::byte> bytes, std::uint8_t version,
                             std::string what)
    : bytes_(bytes), what_(std::move(what)) {
    const auto found = get<std::uint8_t>();
    if (found != version)
        fail("version " + std::to_string(found) + ", expected " + std::to_string(version));
}

bool MessageReader::get_bool() {
    const auto v = get<std::uint8_t>();
    if (v > 1) fail("bool byte " + std::to_string(v));
    return v == 1;
}

std::span<const std::byte> MessageReader::get_bytes() {
    const std::uint64_t n = get<std::uint64_t>();
    if (n > remaining()) fail("length " + std::to_string(n) + " is longer than the message");
    auto s = bytes_.subspan(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
}

std::string MessageReader::get_string() {
    const auto b = get_bytes();
    return {reinterpret_cast<const char*>(b.data()), b.size()};
}

std::size_t MessageReader::get_count(std::size_t min_bytes_each) {
    const std::uint64_t n = get<std::uint64_t>();
    if (min_bytes_each > 0 && n > remaining() / min_bytes_each)
        fail("count " + std::to_string(n) + " is larger than the message can hold");
    return static_cast<std::size_t>(n);
}

void MessageReader::finish() const {
    if (remaining() != 0) fail(std::to_string(remaining()) + " trailing bytes");
}

void MessageReader::fail(const std::string& why) const {
    throw WireError(what_ + ": " + why);
}

}  // namespace isowall
