#include "readers/tiff_directories.h"

#include <array>
#include <set>

namespace isowall::formats {
namespace {

// Reads `n` (2, 4 or 8) bytes at `at` as an unsigned number in the file's byte order.
class Reader {
  public:
    Reader(std::istream& in, std::uint64_t size) : in_(in), size_(size) {}
    bool big_endian = false;
    bool fits(std::uint64_t at, std::uint64_t n) const { return at <= size_ && n <= size_ - at; }
    std::uint64_t number(std::uint64_t at, int n) {
        std::array<unsigned char, 8> b{};
        in_.clear();
        in_.seekg(std::streamoff(at));
        in_.read(reinterpret_cast<char*>(b.data()), n);
        std::uint64_t v = 0;
        for (int i = 0; i < n; ++i) {
            const int k = big_endian ? i : n - 1 - i;
            v = v << 8 | b[std::size_t(k)];
        }
        return in_ ? v : 0;
    }

  private:
    std::istream& in_;
    std::uint64_t size_;
};

std::string page_text(int page, std::uint64_t at) {
    return "the directory of page " + std::to_string(page) + " (at byte " + std::to_string(at) +
           ")";
}

}  // namespace

TiffDirectories tiff_directories(std::istream& in, std::uint64_t size) {
    TiffDirectories out;
    Reader r(in, size);
    if (!r.fits(0, 8)) return {0, "the file is shorter than a TIFF header (8 bytes)"};
    const std::uint64_t order = r.number(0, 2);
    if (order != 0x4949 && order != 0x4d4d) return {0, "no II or MM at byte 0 (not a TIFF)"};
    r.big_endian = order == 0x4d4d;
    const std::uint64_t version = r.number(2, 2);
    if (version != 42 && version != 43)
        return {0, "version " + std::to_string(version) + " at byte 2; TIFF is 42, BigTIFF 43"};
    const bool big = version == 43;
    // Classic: 2-byte count, 12-byte entries, 4-byte links. BigTIFF: 8, 20, 8.
    const int count_bytes = big ? 8 : 2, link_bytes = big ? 8 : 4;
    const std::uint64_t entry_bytes = big ? 20 : 12;
    if (big && !r.fits(0, 16)) return {0, "the file is shorter than a BigTIFF header (16 bytes)"};
    std::uint64_t at = r.number(big ? 8 : 4, link_bytes);
    std::set<std::uint64_t> seen;
    while (at != 0) {
        const int page = out.pages;
        if (page >= kMaxTiffPages)
            return {page, "more than " + std::to_string(kMaxTiffPages) + " pages"};
        if (!seen.insert(at).second)
            return {page, page_text(page, at) + " is one seen before: the chain of pages loops"};
        if (!r.fits(at, std::uint64_t(count_bytes)))
            return {page, page_text(page, at) + " starts past the end of the file (" +
                              std::to_string(size) + " bytes): a truncated file"};
        const std::uint64_t entries = r.number(at, count_bytes);
        const std::uint64_t body = at + std::uint64_t(count_bytes);
        if (entries > (size - body) / entry_bytes ||
            !r.fits(body + entries * entry_bytes, std::uint64_t(link_bytes)))
            return {page, page_text(page, at) + " of " + std::to_string(entries) +
                              " entries ends past the end of the file (" + std::to_string(size) +
                              " bytes): a truncated file"};
        ++out.pages;
        at = r.number(body + entries * entry_bytes, link_bytes);
    }
    return out;
}

}  // namespace isowall::formats
