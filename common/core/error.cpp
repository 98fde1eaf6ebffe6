#include "common/core/error.h"

#include <cstdio>

namespace isowall {
namespace {

bool is_continuation(unsigned char c) {
    return (c & 0xC0) == 0x80;
}

// Appends `text` to `out`, each control byte (and DEL) as \xNN.
void append_printable(std::string& out, std::string_view text) {
    for (const char ch : text) {
        const auto c = static_cast<unsigned char>(ch);
        if (c < 0x20 || c == 0x7F) {
            char buf[8];
            std::snprintf(buf, sizeof(buf), "\\x%02X", c);
            out += buf;
        } else {
            out += ch;
        }
    }
}

// The byte length of the first `chars` characters of UTF-8 `text` (bytes that are not valid
// UTF-8 count one each).
std::size_t prefix_bytes(std::string_view text, std::size_t chars) {
    std::size_t i = 0;
    for (std::size_t n = 0; i < text.size() && n < chars; ++n) {
        ++i;
        while (i < text.size() && is_continuation(static_cast<unsigned char>(text[i]))) ++i;
    }
    return i;
}

// The byte offset where the last `chars` characters of `text` start.
std::size_t suffix_start(std::string_view text, std::size_t chars) {
    std::size_t i = text.size();
    for (std::size_t n = 0; i > 0 && n < chars; ++n) {
        --i;
        while (i > 0 && is_continuation(static_cast<unsigned char>(text[i]))) --i;
    }
    return i;
}

}  // namespace

std::string clip(std::string_view text, std::size_t max_chars) {
    const std::size_t keep = prefix_bytes(text, max_chars);
    std::string out;
    append_printable(out, text.substr(0, keep));
    if (keep < text.size()) out += "...";
    return out;
}

std::string quote(std::string_view text) {
    return '"' + clip(text) + '"';
}

std::string clip_source(std::string_view where) {
    constexpr std::size_t kHead = 40, kTail = 77;
    const std::size_t head = prefix_bytes(where, kHead);
    const std::size_t tail = suffix_start(where, kTail);
    std::string out;
    if (tail <= head + 3) {  // short enough to show whole
        append_printable(out, where);
        return out;
    }
    append_printable(out, where.substr(0, head));
    out += "...";
    append_printable(out, where.substr(tail));
    return out;
}

}  // namespace isowall
