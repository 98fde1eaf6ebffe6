#pragma once
// The byte format of every message: explicit little-endian fields, a version byte first, never raw
// padded structs. Only trivially copyable scalars go in (a struct must be written field by field),
// and a reader never trusts a length: every count is checked against the bytes left before
// anything is allocated, so malformed or truncated input is an error, never a crash.
#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

namespace isowall {

// Every decoding failure: the message names what was being read and what was wrong.
class WireError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

template <class T>
concept WireScalar = std::is_trivially_copyable_v<T> &&
    (std::is_arithmetic_v<T> || std::is_enum_v<T>);

class MessageWriter {
  public:
    // The first bytes are reserved at once: besides saving regrowth, it keeps GCC 12 from a
    // false -Wstringop-overflow when many encoders are inlined into one std::visit.
    explicit MessageWriter(std::uint8_t version) {
        bytes_.reserve(64);
        put(version);
    }

    template <WireScalar T>
    void put(T value) {
        auto raw = std::bit_cast<std::array<std::byte, sizeof(T)>>(value);
        if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
        bytes_.insert(bytes_.end(), raw.begin(), raw.end());
    }
    void put(glm::vec3 v) {
        put(v.x);
        put(v.y);
        put(v.z);
    }
    // A length (u64) then the bytes.
    void put_bytes(std::span<const std::byte> b) {
        put(static_cast<std::uint64_t>(b.size()));
        bytes_.insert(bytes_.end(), b.begin(), b.end());
    }
    void put_string(std::string_view s) { put_bytes(std::as_bytes(std::span(s.data(), s.size()))); }
    // A count (u64) then each element as a scalar.
    // On a little-endian host the elements are the wire's bytes already: one copy (a region
    // result's depth is 4 bytes a pixel; element by element it cost a helper more than drawing).
    template <WireScalar T>
    void put_array(std::span<const T> values) {
        put(static_cast<std::uint64_t>(values.size()));
        if constexpr (std::endian::native == std::endian::little) {
            const auto raw = std::as_bytes(values);
            bytes_.insert(bytes_.end(), raw.begin(), raw.end());
        } else {
            for (const T& v : values) put(v);
        }
    }

    // Room for `n` bytes in all, so that large fields are written without regrowth.
    void reserve(std::size_t n) { bytes_.reserve(n); }
    const std::vector<std::byte>& bytes() const { return bytes_; }
    std::vector<std::byte> take() { return std::move(bytes_); }

  private:
    std::vector<std::byte> bytes_;
};

class MessageReader {
  public:
    // `what` names the message in errors, e.g. "view message".
    MessageReader(std::span<const std::byte> bytes, std::uint8_t version, std::string what);

    template <WireScalar T>
    T get() {
        need(sizeof(T));
        std::array<std::byte, sizeof(T)> raw;
        std::memcpy(raw.data(), bytes_.data() + pos_, sizeof(T));
        if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
        pos_ += sizeof(T);
        return std::bit_cast<T>(raw);
    }
    glm::vec3 get_vec3() {
        const float x = get<float>(), y = get<float>(), z = get<float>();
        return {x, y, z};
    }
    // A bool stored as one byte; anything but 0 or 1 is an error.
    bool get_bool();
    std::span<const std::byte> get_bytes();
    std::string get_string();
    template <WireScalar T>
    std::vector<T> get_array() {
        const std::uint64_t n = get<std::uint64_t>();
        if (n > remaining() / sizeof(T))
            fail("array of " + std::to_string(n) + " elements is longer than the message");
        std::vector<T> out(static_cast<std::size_t>(n));
        if constexpr (std::endian::native == std::endian::little && !std::is_enum_v<T> &&
                      !std::is_same_v<T, bool>) {
            if (!out.empty()) {  // memcpy of a null pointer is undefined even for 0 bytes
                std::memcpy(out.data(), bytes_.data() + pos_, out.size() * sizeof(T));
                pos_ += out.size() * sizeof(T);
            }
        } else {
            for (T& v : out) v = get<T>();
        }
        return out;
    }
    // A count of elements of at least `min_bytes_each`, checked against the bytes left.
    std::size_t get_count(std::size_t min_bytes_each);
    // Every byte must have been read: trailing bytes are an error too.
    void finish() const;
    std::size_t remaining() const { return bytes_.size() - pos_; }
    [[noreturn]] void fail(const std::string& why) const;

  private:
    void need(std::size_t n) const {
        if (n > remaining()) fail("truncated");
    }
    std::span<const std::byte> bytes_;
    std::size_t pos_ = 0;
    std::string what_;
};

}  // namespace isowall
