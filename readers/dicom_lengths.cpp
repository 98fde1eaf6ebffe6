#include "readers/dicom_lengths.h"

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string_view>
#include <vector>

namespace isowall::formats {
namespace {

constexpr std::uint32_t kUndefined = 0xffffffff;

struct Cursor {
    std::span<const std::byte> bytes;
    std::size_t pos = 0;
    bool big_endian = false;

    std::size_t left() const { return bytes.size() - pos; }
    // n bytes at `at` (within the bytes) as a number, the cursor left where it is.
    std::uint32_t get_at(std::size_t at, int n) const {
        Cursor peek = *this;
        peek.pos = at;
        return peek.get(n);
    }
    std::uint32_t get(int n) {
        std::uint32_t v = 0;
        for (int i = 0; i < n; ++i) {
            const auto b = std::uint32_t(bytes[pos + std::size_t(i)]);
            v |= big_endian ? b << (8 * (n - 1 - i)) : b << (8 * i);
        }
        pos += std::size_t(n);
        return v;
    }
};

// VRs whose explicit length is 4 bytes after 2 reserved ones (PS3.5 7.1.2).
bool long_vr(std::string_view vr) {
    return vr == "OB" || vr == "OD" || vr == "OF" || vr == "OL" || vr == "OV" || vr == "OW" ||
           vr == "SQ" || vr == "SV" || vr == "UC" || vr == "UN" || vr == "UR" || vr == "UT" ||
           vr == "UV";
}

std::string element_text(std::uint32_t group, std::uint32_t element) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "(%04X,%04X)", group, element);
    return buf;
}

enum class Syntax { implicit_le, explicit_le, explicit_be, deflated };

Syntax syntax_of(std::string_view uid) {
    while (!uid.empty() && (uid.back() == '\0' || uid.back() == ' ')) uid.remove_suffix(1);
    if (uid == "1.2.840.10008.1.2") return Syntax::implicit_le;
    if (uid == "1.2.840.10008.1.2.2") return Syntax::explicit_be;
    if (uid == "1.2.840.10008.1.2.1.99") return Syntax::deflated;
    return Syntax::explicit_le;
}

}  // namespace

bool has_part10_magic(std::span<const std::byte> file) {
    return file.size() >= 132 && file[128] == std::byte{'D'} && file[129] == std::byte{'I'} &&
           file[130] == std::byte{'C'} && file[131] == std::byte{'M'};
}

namespace {

// What the walk is inside: a sequence (only items and its delimiter may follow), an item (only
// data elements and its delimiter), or encapsulated pixel data (items of raw bytes).
enum class Kind { sequence, item, fragments };
struct Container {
    std::size_t end;  // SIZE_MAX: undefined length, ended by a delimiter
    Kind kind;
    // Inside a UN of undefined length the encoding is implicit VR, whatever the file's
    // (PS3.5 6.2.2): a private sequence an explicit-VR writer did not know.
    bool implicit_vr = false;
};

constexpr std::uint32_t kItem = 0xe000, kItemEnd = 0xe00d, kSequenceEnd = 0xe0dd;

// Why the tag (group, element) cannot come next inside `in` (nullptr: the top level), or empty.
std::string misplaced(std::uint32_t group, std::uint32_t element, const Container* in) {
    const bool item_tag = group == 0xfffe;
    const std::string what = "element " + element_text(group, element);
    if (!in) return item_tag ? what + " (an item tag) outside any sequence" : "";
    if (in->kind != Kind::item)
        return item_tag && (element == kItem || element == kSequenceEnd)
                   ? ""
                   : what + " inside a sequence, where only items may be";
    return item_tag && element != kItemEnd ? what + " (an item tag) directly inside an item" : "";
}

// An element's VR (explicit only) and length, after its tag; nullopt when the file ends first.
struct Head {
    std::string_view vr;
    std::uint32_t length;
};
std::optional<Head> read_head(Cursor& c, bool explicit_vr) {
    if (!explicit_vr) return Head{{}, c.get(4)};
    const std::string_view vr(reinterpret_cast<const char*>(c.bytes.data() + c.pos), 2);
    c.pos += 2;
    if (!long_vr(vr)) return Head{vr, c.get(2)};
    if (c.left() < 6) return std::nullopt;
    c.pos += 2;
    return Head{vr, c.get(4)};
}

}  // namespace

std::string dicom_length_problem(std::span<const std::byte> file) {
    if (!has_part10_magic(file)) return "no DICM at byte 128 (not a DICOM Part 10 file)";
    Cursor c{file, 132};
    Syntax syntax = Syntax::explicit_le;  // the file meta (group 0002) is always explicit LE
    bool in_meta = true;
    // The sequences and items the walk is inside; GDCM asserts on what breaks their structure.
    std::vector<Container> open;
    while (c.left() >= 8) {
        while (!open.empty() && c.pos >= open.back().end) {
            if (c.pos > open.back().end)
                return "an element runs past the end of its sequence or item";
            open.pop_back();
        }
        const std::size_t start = c.pos;
        const std::uint32_t group = c.get(2);
        if (in_meta && group != 0x0002) {
            // The data set begins: its transfer syntax applies from here.
            in_meta = false;
            if (syntax == Syntax::deflated) return {};
            c.pos = start;
            c.big_endian = syntax == Syntax::explicit_be;
            continue;
        }
        const std::uint32_t element = c.get(2);
        Container* in = open.empty() ? nullptr : &open.back();
        if (std::string p = misplaced(group, element, in); !p.empty()) return p;
        const bool implicit_here = in && in->implicit_vr;
        const bool explicit_vr =
            in_meta || (syntax != Syntax::implicit_le && group != 0xfffe && !implicit_here);
        const std::optional<Head> head = read_head(c, explicit_vr);
        if (!head) return "element " + element_text(group, element) + " is cut short";
        const std::uint32_t length = head->length;
        const std::string_view vr = head->vr;
        if (group == 0xfffe && element != kItem) {  // a delimiter ends what it closes
            if (!in || (element == kItemEnd) != (in->kind == Kind::item) || in->end != SIZE_MAX)
                return "element " + element_text(group, element) + " closes nothing open";
            open.pop_back();
            continue;
        }
        const bool pixel_data = group == 0x7fe0 && element == 0x0010;
        if (length == kUndefined) {
            const Kind kind = group == 0xfffe
                                  ? (in->kind == Kind::fragments ? Kind::fragments : Kind::item)
                              : pixel_data ? Kind::fragments
                                           : Kind::sequence;
            if (group == 0xfffe && in->kind == Kind::fragments)
                return "a fragment of pixel data of undefined length";
            open.push_back({SIZE_MAX, kind, implicit_here || vr == "UN"});
            continue;
        }
        const std::size_t room =
            open.empty() || open.back().end == SIZE_MAX ? c.left() : open.back().end - c.pos;
        if (length > room)
            return "element " + element_text(group, element) + " declares " +
                   std::to_string(length) + " bytes where " + std::to_string(room) + " remain";
        if (group == 0x0002 && element == 0x0010)
            syntax = syntax_of({reinterpret_cast<const char*>(file.data() + c.pos), length});
        // Items and sequences are walked into (a value of implicit VR that starts with an item
        // tag is a sequence: GDCM knows it from its dictionary); any other value, and a fragment
        // of pixel data, is skipped.
        const bool starts_with_item =
            length >= 4 && c.get_at(c.pos, 2) == 0xfffe && c.get_at(c.pos + 2, 2) == kItem;
        const bool fragment = group == 0xfffe && in && in->kind == Kind::fragments;
        if (!fragment && length > 0 &&
            (group == 0xfffe || vr == "SQ" || (!explicit_vr && starts_with_item))) {
            open.push_back(
                {c.pos + length, group == 0xfffe ? Kind::item : Kind::sequence, implicit_here});
            continue;
        }
        c.pos += length;
    }
    return {};
}

}  // namespace isowall::formats
