#pragma once
// The text of a NRRD header, split before Teem sees it. Teem opens the data file while it parses
// a header (even with skipData), skips its lines and bytes, and wraps sizes past 64 bits, so a
// header naming /dev/zero with a line skip, or a FIFO, hung it. We read the fields that locate the
// data ("data file", "line skip", "byte skip") and the sizes ourselves, with strict number
// parsing, and hand Teem the rest, which names no file.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace isowall {

struct NrrdHeaderText {
    std::string teem_text;                 // the header without the data-location fields
    std::optional<std::string> data_file;  // as written; nullopt: the data is attached
    std::uint64_t line_skip = 0;
    std::int64_t byte_skip = 0;        // -1: the data is the last bytes of the file
    std::vector<std::uint64_t> sizes;  // the "sizes" field, each checked against 64 bits
    bool spacings_given = false;       // a "spacings" field is there (Teem reads nan as absent)
    std::optional<std::size_t> data_offset;  // first byte after the blank line, if there is one
};

// Headers longer than this without a blank line are refused (real ones are a few KiB).
inline constexpr std::size_t kMaxNrrdHeaderBytes = std::size_t{16} << 20;

// Splits the header at the start of `file` (the bytes of the .nrrd or .nhdr); `where` names it.
NrrdHeaderText split_nrrd_header(std::span<const std::byte> file, const std::string& where);

}  // namespace isowall
