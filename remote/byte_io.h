#pragma once
// Raw little-endian bytes for the group codecs. Unlike MessageWriter/MessageReader
// (wire/wire.h), arrays carry no count of their own and go in one copy: a group's counts
// sit once in its header, and a per-array u64 count would cost as much as the whole index stream
// of a small compact group. Reading keeps wire.h's rule: every length is checked against the
// bytes left before anything is sized from it, and every failure is a WireError.
#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "wire/wire.h"

namespace isowall::remote {

// The bulk copies below are the wire format only on a little-endian host, which is every host
// this project builds for; a big-endian one fails here rather than sending swapped bytes.
static_assert(std::endian::native == std::endian::little, "group codecs assume little-endian");

class ByteWriter {
  public:
    // Reserving the first bytes keeps GCC 12 from a false -Wstringop-overflow on small puts (as
    // MessageWriter does).
    ByteWriter() { bytes_.reserve(64); }

    template <WireScalar T>
    void put(T value) {
        put_raw(std::span<const T>(&value, 1));
    }
    template <class T>
    requires std::is_trivially_copyable_v<T>
    void put_raw(std::span<const T> values) {
        if (values.empty()) return;
        const std::size_t at = bytes_.size();
        bytes_.resize(at + values.size_bytes());
        std::memcpy(bytes_.data() + at, values.data(), values.size_bytes());
    }
    void reserve(std::size_t n) { bytes_.reserve(n); }
    std::vector<std::uint8_t> take() { return std::move(bytes_); }

  private:
    std::vector<std::uint8_t> bytes_;
};

class ByteReader {
  public:
    ByteReader(std::span<const std::uint8_t> bytes, const char* what)
        : bytes_(bytes), what_(what) {}

    template <WireScalar T>
    T get() {
        T v;
        get_raw(std::span(&v, 1));
        return v;
    }
    // Fills `out` from the next out.size_bytes() bytes.
    template <class T>
    requires std::is_trivially_copyable_v<T>
    void get_raw(std::span<T> out) {
        need(out.size_bytes());
        if (!out.empty()) std::memcpy(out.data(), bytes_.data() + pos_, out.size_bytes());
        pos_ += out.size_bytes();
    }
    // The next n bytes, not copied.
    std::span<const std::uint8_t> get_span(std::size_t n) {
        need(n);
        auto s = bytes_.subspan(pos_, n);
        pos_ += n;
        return s;
    }
    // `count` elements of `bytes_each` must fit in what is left: call before allocating them.
    void need_elements(std::uint64_t count, std::size_t bytes_each, const char* field) const {
        if (count > remaining() / bytes_each)
            fail(std::string(field) + ": " + std::to_string(count) +
                 " elements are longer than the bytes left (" + std::to_string(remaining()) + ")");
    }
    void finish() const {
        if (remaining() != 0) fail(std::to_string(remaining()) + " trailing bytes");
    }
    std::size_t remaining() const { return bytes_.size() - pos_; }
    [[noreturn]] void fail(const std::string& why) const {
        throw WireError(std::string(what_) + ": " + why);
    }

  private:
    void need(std::size_t n) const {
        if (n > remaining())
            fail("truncated: " + std::to_string(n) + " bytes wanted, " +
                 std::to_string(remaining()) + " left");
    }
    std::span<const std::uint8_t> bytes_;
    std::size_t pos_ = 0;
    const char* what_;
};

}  // namespace isowall::remote
