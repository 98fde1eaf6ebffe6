#include "volume/nrrd_decode.h"

#include <bzlib.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string_view>
#include <type_traits>

#include "core/error.h"
#include "volume/inflate_stream.h"
#include "volume/load_checks.h"

namespace isowall {
namespace {

std::string count_words(std::uint64_t n, const char* unit) {
    return std::to_string(n) + " " + unit;
}

// Decoded bytes, grown by doubling up to need + 1: one byte more than the header says is enough
// to know the data is longer, and memory follows the data that really arrives.
class GrowingOutput {
  public:
    GrowingOutput(std::uint64_t need, std::string where, const char* what)
        : need_(need), where_(std::move(where)), what_(what) {
        check_fits_memory(need, where_, "sizes");
    }
    // Free space at the end (never empty); grows the buffer when it is full.
    std::span<std::byte> room() {
        if (size_ == bytes_.size()) {
            const std::uint64_t want = std::min<std::uint64_t>(
                need_ + 1, std::max<std::uint64_t>(std::uint64_t{1} << 16, 2 * bytes_.size()));
            bytes_.resize(static_cast<std::size_t>(want));
        }
        return std::span<std::byte>(bytes_).subspan(size_);
    }
    void produced(std::size_t n) {
        size_ += n;
        if (size_ > need_)
            throw InputError(where_, "data",
                             std::string(what_) +
                                 " data is longer than the header says: more than " +
                                 count_words(need_, "bytes"));
    }
    std::vector<std::byte> finish() {
        if (size_ < need_)
            throw InputError(where_, "data",
                             std::string(what_) + " data is shorter than the header says: " +
                                 count_words(size_, "bytes") + ", expected " +
                                 std::to_string(need_));
        bytes_.resize(size_);
        return std::move(bytes_);
    }

  private:
    std::uint64_t need_;
    std::string where_;
    const char* what_;
    std::vector<std::byte> bytes_;
    std::size_t size_ = 0;
};

unsigned clamp_uint(std::size_t n) {
    return static_cast<unsigned>(std::min<std::size_t>(n, UINT_MAX));
}

bool starts_bzip2(std::span<const std::byte> rest) {
    return rest.size() >= 3 && rest[0] == std::byte{'B'} && rest[1] == std::byte{'Z'} &&
           rest[2] == std::byte{'h'};
}

struct InflateEnd {
    void operator()(z_stream* z) const { inflateEnd(z); }
};
struct Bzip2End {
    void operator()(bz_stream* s) const { BZ2_bzDecompressEnd(s); }
};

bool is_separator(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' || c == ',';
}

// One number of type T from the whole of `token`; nullopt when it is not one or out of range.
template <class T>
std::optional<T> parse_number(std::string_view token) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    const char* end = token.data() + token.size();
    if constexpr (std::is_floating_point_v<T>) {
        T v{};
        const auto r = std::from_chars(token.data(), end, v);
        if (r.ec != std::errc() || r.ptr != end) return std::nullopt;
        return v;
    } else {
        using Wide = std::conditional_t<std::is_signed_v<T>, std::int64_t, std::uint64_t>;
        Wide v{};
        const auto r = std::from_chars(token.data(), end, v);
        if (r.ec != std::errc() || r.ptr != end) return std::nullopt;
        if (v < static_cast<Wide>(std::numeric_limits<T>::lowest()) ||
            v > static_cast<Wide>(std::numeric_limits<T>::max()))
            return std::nullopt;
        return static_cast<T>(v);
    }
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

constexpr std::size_t kMaxToken = 64;

}  // namespace

std::size_t skip_lines(std::span<const std::byte> bytes, std::size_t offset, std::uint64_t lines,
                       const std::string& where) {
    for (std::uint64_t i = 0; i < lines; ++i) {
        const auto* begin = bytes.data() + std::min(offset, bytes.size());
        const auto* end = bytes.data() + bytes.size();
        const auto* nl = std::find(begin, end, std::byte{'\n'});
        if (nl == end)
            throw InputError(where, "line skip",
                             "the file ends after " + count_words(i, "lines") + " of the " +
                                 std::to_string(lines) + " to skip");
        offset = static_cast<std::size_t>(nl - bytes.data()) + 1;
    }
    return offset;
}

std::vector<std::byte> decode_gzip(std::span<const std::byte> in, std::uint64_t need,
                                   const std::string& where) {
    GrowingOutput out(need, where, "gzip");
    z_stream z{};
    if (inflateInit2(&z, 15 + 32) != Z_OK)  // 15 + 32: gzip or zlib header, detected
        throw InputError(where, "data", "cannot start zlib");
    std::unique_ptr<z_stream, InflateEnd> guard(&z);
    std::size_t pos = 0;
    for (;;) {
        const std::span<std::byte> room = out.room();
        const unsigned in_n = clamp_uint(in.size() - pos), out_n = clamp_uint(room.size());
        z.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in.data() + pos));
        z.avail_in = in_n;
        z.next_out = reinterpret_cast<Bytef*>(room.data());
        z.avail_out = out_n;
        const int rc = inflate(&z, Z_NO_FLUSH);
        pos += in_n - z.avail_in;
        out.produced(out_n - z.avail_out);
        if (rc == Z_STREAM_END) {
            if (pos == in.size()) break;
            if (!starts_gzip(in.subspan(pos)))
                throw InputError(where, "data",
                                 count_words(in.size() - pos, "bytes") +
                                     " follow the gzip data (the file is longer than it)");
            inflateReset(&z);  // another gzip member: gzip allows them back to back
            continue;
        }
        const bool stalled = z.avail_in == in_n && z.avail_out == out_n;
        if (rc == Z_OK || (rc == Z_BUF_ERROR && !stalled)) continue;
        if (rc == Z_BUF_ERROR)
            throw InputError(where, "data",
                             "gzip data ends early: the file is shorter than the header says");
        throw InputError(
            where, "data",
            std::string("gzip data is corrupt: ") + (z.msg ? z.msg : "inflate failed"));
    }
    return out.finish();
}

std::vector<std::byte> decode_bzip2(std::span<const std::byte> in, std::uint64_t need,
                                    const std::string& where) {
    GrowingOutput out(need, where, "bzip2");
    bz_stream s{};
    if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK)
        throw InputError(where, "data", "cannot start bzip2");
    std::unique_ptr<bz_stream, Bzip2End> guard(&s);
    std::size_t pos = 0;
    for (;;) {
        const std::span<std::byte> room = out.room();
        const unsigned in_n = clamp_uint(in.size() - pos), out_n = clamp_uint(room.size());
        s.next_in = reinterpret_cast<char*>(const_cast<std::byte*>(in.data() + pos));
        s.avail_in = in_n;
        s.next_out = reinterpret_cast<char*>(room.data());
        s.avail_out = out_n;
        const int rc = BZ2_bzDecompress(&s);
        pos += in_n - s.avail_in;
        out.produced(out_n - s.avail_out);
        if (rc == BZ_STREAM_END) {
            if (pos == in.size()) break;
            if (!starts_bzip2(in.subspan(pos)))
                throw InputError(where, "data",
                                 count_words(in.size() - pos, "bytes") +
                                     " follow the bzip2 data (the file is longer than it)");
            BZ2_bzDecompressEnd(&s);  // another stream, as bzip2 writes for concatenated files
            s = bz_stream{};
            if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK)
                throw InputError(where, "data", "cannot start bzip2");
            continue;
        }
        if (rc != BZ_OK)
            throw InputError(where, "data",
                             "bzip2 data is corrupt (error " + std::to_string(rc) + ")");
        if (s.avail_in == in_n && s.avail_out == out_n)
            throw InputError(where, "data",
                             "bzip2 data ends early: the file is shorter than the header says");
    }
    return out.finish();
}

std::vector<std::byte> decode_ascii(std::span<const std::byte> in, VoxelType type,
                                    std::uint64_t count, const std::string& where) {
    const std::uint64_t size = voxel_size(type);
    GrowingOutput out(count * size, where, "ascii");
    const std::string_view text(reinterpret_cast<const char*>(in.data()), in.size());
    std::uint64_t index = 0;
    std::size_t pos = 0;
    dispatch_voxel_type(type, [&](auto tag) {
        using T = decltype(tag);
        for (;;) {
            while (pos < text.size() && is_separator(text[pos])) ++pos;
            if (pos == text.size()) break;
            std::size_t end = pos;
            while (end < text.size() && !is_separator(text[end]) && end - pos <= kMaxToken) ++end;
            const std::string_view token = text.substr(pos, end - pos);
            const std::string which = "value " + std::to_string(index + 1);
            if (token.size() > kMaxToken)
                throw InputError(where, "data",
                                 which + " is longer than " + std::to_string(kMaxToken) +
                                     " characters: " + quote_bounded(text.substr(pos)));
            const auto v = parse_number<T>(token);
            if (!v)
                throw InputError(where, "data",
                                 which + ": expected " + std::string(type_name(type)) + ", got " +
                                     quote_bounded(token));
            const std::span<std::byte> room = out.room();
            const std::size_t n = std::min<std::size_t>(room.size(), sizeof(T));
            std::memcpy(room.data(), &*v, n);  // n < sizeof(T) only past the header's count
            out.produced(sizeof(T));
            ++index;
            pos = end;
        }
    });
    return out.finish();
}

std::vector<std::byte> decode_hex(std::span<const std::byte> in, std::uint64_t need,
                                  const std::string& where) {
    GrowingOutput out(need, where, "hex");
    const std::string_view text(reinterpret_cast<const char*>(in.data()), in.size());
    int high = -1;  // the first digit of a pair, once read
    for (std::size_t pos = 0; pos < text.size(); ++pos) {
        const char c = text[pos];
        if (high < 0 && is_separator(c) && c != ',') continue;
        const int d = hex_digit(c);
        if (d < 0)
            throw InputError(where, "data",
                             "byte " + std::to_string(pos) + ": expected a hex digit, got " +
                                 quote_bounded(text.substr(pos, 1)));
        if (high < 0) {
            high = d;
            continue;
        }
        out.room()[0] = static_cast<std::byte>(high * 16 + d);
        out.produced(1);
        high = -1;
    }
    if (high >= 0) throw InputError(where, "data", "hex data ends in half a byte");
    return out.finish();
}

}  // namespace isowall
