#include "core/error.h"

#include <cstdio>

namespace isowall {
namespace {

bool is_continuation(unsigned char c) {
    return (c & 0xC0) == 0x80;
}

// The bytes of the valid UTF-8 sequence at text[i] when it encodes a printable character beyond
// ASCII (not a C1 control, U+0080 to U+009F, which a terminal may obey: 0x9B starts a control
// sequence like ESC [), else 0: overlong forms, surrogates and stray bytes are not characters.
std::size_t printable_utf8_bytes(std::string_view text, std::size_t i) {
    const auto c = static_cast<unsigned char>(text[i]);
    const std::size_t n = c >= 0xC2 && c <= 0xDF   ? 2
                          : c >= 0xE0 && c <= 0xEF ? 3
                          : c >= 0xF0 && c <= 0xF4 ? 4
                                                   : 0;
    if (n == 0 || i + n > text.size()) return 0;
    char32_t cp = c & (0x7F >> n);
    for (std::size_t k = 1; k < n; ++k) {
        const auto d = static_cast<unsigned char>(text[i + k]);
        if (!is_continuation(d)) return 0;
        cp = cp << 6 | (d & 0x3F);
    }
    constexpr char32_t kLeast[] = {0, 0, 0x80, 0x800, 0x10000};
    const bool bad = cp < kLeast[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF) ||
                     (cp >= 0x80 && cp <= 0x9F);
    return bad ? 0 : n;
}

// Appends `text` to `out`, each control byte (and DEL), C1 control and byte that is not part of
// valid UTF-8 as \xNN: an error line never carries a byte a terminal would act on.
void append_printable(std::string& out, std::string_view text) {
    for (std::size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        const std::size_t n =
            c < 0x80 ? (c < 0x20 || c == 0x7F ? 0 : 1) : printable_utf8_bytes(text, i);
        if (n > 0) {
            out.append(text.substr(i, n));
            i += n;
            continue;
        }
        char buf[8];
        std::snprintf(buf, sizeof(buf), "\\x%02X", c);
        out += buf;
        ++i;
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
