#include "volume/nrrd_header.h"

#include <algorithm>
#include <charconv>
#include <string_view>

#include "core/error.h"
#include "volume/load_checks.h"

namespace isowall {
namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

std::vector<std::string_view> words(std::string_view s) {
    std::vector<std::string_view> out;
    while (!(s = trim(s)).empty()) {
        const std::size_t end = std::min(s.find_first_of(" \t"), s.size());
        out.push_back(s.substr(0, end));
        s.remove_prefix(end);
    }
    return out;
}

template <class Int>
std::optional<Int> parse_int(std::string_view s) {
    Int v{};
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
    return v;
}

// The end of the header: the first byte after its blank line, if any.
std::optional<std::size_t> blank_line_end(std::span<const std::byte> bytes) {
    for (std::size_t i = 0; i + 1 < bytes.size(); ++i) {
        if (bytes[i] != std::byte{'\n'}) continue;
        if (bytes[i + 1] == std::byte{'\n'}) return i + 2;
        if (bytes[i + 1] == std::byte{'\r'} && i + 2 < bytes.size() &&
            bytes[i + 2] == std::byte{'\n'})
            return i + 3;
    }
    return std::nullopt;
}

// Teem spells the data-location fields with or without their space.
std::string field_key(std::string_view line) {
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos || line.substr(colon, 2) == ":=" || line[0] == '#')
        return {};
    std::string key;
    for (char c : line.substr(0, colon))
        if (c != ' ') key += c;
    return key;
}

void set_data_file(NrrdHeaderText& h, std::string_view value, const std::string& where) {
    const auto w = words(value);
    if (w.empty()) throw InputError(where, "data file", "no file name");
    const bool list = w[0] == "LIST" || w[0] == "SKIPLIST";
    const bool pattern = w.size() >= 4 && parse_int<long long>(w[1]) &&
                         parse_int<long long>(w[2]) && parse_int<long long>(w[3]);
    if (list || pattern)
        throw InputError(where, "data file",
                         "several data files (" + quote_bounded(trim(value)) +
                             ") are not supported; join them into one file");
    h.data_file = std::string(trim(value));
}

void set_sizes(NrrdHeaderText& h, std::string_view value, const std::string& where) {
    for (std::string_view w : words(value)) {
        const auto v = parse_int<std::uint64_t>(w);
        if (!v)
            throw InputError(where, "sizes",
                             "expected whole numbers that fit 64 bits, got " + quote_bounded(w));
        h.sizes.push_back(*v);
    }
}

// Reads one of our fields from `line`; false when the line is not one of them.
bool take_field(NrrdHeaderText& h, std::string_view line, const std::string& where,
                std::vector<std::string>& seen) {
    const std::string key = field_key(line);
    const std::string_view value = trim(line.substr(std::min(line.find(':') + 1, line.size())));
    const bool ours = key == "datafile" || key == "lineskip" || key == "byteskip";
    if (key == "sizes") set_sizes(h, value, where);
    if (key == "spacings") h.spacings_given = true;
    if (!ours) return false;
    const std::string name = key == "datafile"   ? "data file"
                             : key == "lineskip" ? "line skip"
                                                 : "byte skip";
    if (std::find(seen.begin(), seen.end(), key) != seen.end())
        throw InputError(where, name, "given twice");
    seen.push_back(key);
    if (key == "datafile") {
        set_data_file(h, value, where);
    } else if (key == "lineskip") {
        const auto v = parse_int<std::uint64_t>(value);
        if (!v)
            throw InputError(where, name,
                             "expected a whole number >= 0, got " + quote_bounded(value));
        h.line_skip = *v;
    } else {
        const auto v = parse_int<std::int64_t>(value);
        if (!v || *v < -1)
            throw InputError(where, name,
                             "expected a whole number >= -1, got " + quote_bounded(value));
        h.byte_skip = *v;
    }
    return true;
}

// Teem formats its parse errors, which quote the field's value, into a fixed buffer of about
// 1 KiB (biff), and overflows it for a long value (found by fuzz/fuzz_nrrd.cpp: a "type:" of 1.7
// KB ended in a fortify abort). A field line Teem parses is at most kMaxTeemLine bytes; comments
// and key/value pairs, which Teem keeps without parsing, may be longer.
constexpr std::size_t kMaxTeemLine = 512;

// Teem reads a line as a key/value pair only when its ":=" comes before any ": "; a line such as
// "type: <long value> :=" is a field to Teem, and so is bounded (found by fuzz/fuzz_nrrd.cpp).
bool is_key_value(std::string_view line) {
    const std::size_t equals = line.find(":=");
    return equals != std::string_view::npos && equals < line.find(": ");
}

void check_teem_line(std::string_view line, const std::string& where) {
    if (line.size() <= kMaxTeemLine || line.substr(0, 1) == "#" || is_key_value(line)) return;
    const std::size_t colon = line.find(':');
    const std::string field =
        colon == std::string_view::npos ? "header" : std::string(trim(line.substr(0, colon)));
    throw InputError(where, field,
                     "a line of " + std::to_string(line.size()) + " bytes; expected at most " +
                         std::to_string(kMaxTeemLine));
}

}  // namespace

NrrdHeaderText split_nrrd_header(std::span<const std::byte> file, const std::string& where) {
    const std::string_view all(reinterpret_cast<const char*>(file.data()), file.size());
    if (all.substr(0, 7) != "NRRD000")
        throw InputError(
            where, "header",
            "not a NRRD file: expected \"NRRD000N\" first, got " +
                quote_bounded(all.substr(0, std::min(all.find('\n'), all.size())), 20));
    NrrdHeaderText h;
    h.data_offset = blank_line_end(file.first(std::min(file.size(), kMaxNrrdHeaderBytes)));
    if (!h.data_offset && file.size() > kMaxNrrdHeaderBytes)
        throw InputError(where, "header",
                         "no blank line ends the header in its first " +
                             std::to_string(kMaxNrrdHeaderBytes >> 20) + " MiB");
    const std::string_view text = all.substr(0, h.data_offset.value_or(all.size()));
    if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos)
        throw InputError(where, "header", "a NUL byte at byte " + std::to_string(nul));
    std::vector<std::string> seen;
    for (std::size_t pos = 0; pos < text.size();) {
        const std::size_t end = std::min(text.find('\n', pos), text.size());
        const std::string_view line = text.substr(pos, end - pos);
        if (!take_field(h, line, where, seen)) {
            check_teem_line(line, where);
            h.teem_text += line;
            h.teem_text += '\n';
        }
        pos = end + 1;
    }
    return h;
}

}  // namespace isowall
