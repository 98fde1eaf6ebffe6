#include "core/number.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "core/error.h"

namespace isowall {
namespace {

// Integers in full (2147483647, not 2.14748e+09).
std::string format(double v, bool integer) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), integer ? "%.0f" : "%g", v);
    return buf;
}

}  // namespace

bool NumberRange::contains(double v) const {
    if (!std::isfinite(v) || v > hi || v < lo || (lo_open && v == lo)) return false;
    return !integer || v == std::floor(v);
}

std::string NumberRange::describe() const {
    const char* what = integer ? "an integer" : "a number";
    if (lo == limits::kAnyFinite.lo && hi == limits::kAnyFinite.hi)
        return std::string("a finite ") + (integer ? "integer" : "number");
    return std::string(what) + " in " + (lo_open ? "(" : "[") + format(lo, integer) + ", " +
           format(hi, integer) + "]";
}

std::optional<double> parse_number(std::string_view text) {
    // from_chars takes no '+' and no leading space, and reads hex only when asked to.
    if (!text.empty() && text.front() == '+') {
        text.remove_prefix(1);
        if (!text.empty() && text.front() == '-') return std::nullopt;  // "+-5"
    }
    double v = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
        return std::nullopt;
    return v;
}

// An integer range's ends judged on the text's own value: a double rounds 2^53 + 1 to 2^53, a
// long double (64 bits of mantissa here) holds it.
bool past_integer_range(std::string_view text, const NumberRange& range) {
    if (!range.integer) return false;
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    long double v = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (error != std::errc() || end != text.data() + text.size()) return false;
    return v > static_cast<long double>(range.hi) || v < static_cast<long double>(range.lo);
}

std::string number_problem(std::string_view text, const NumberRange& range) {
    const auto v = parse_number(text);
    if (v && range.contains(*v) && !past_integer_range(text, range)) return {};
    return "expected " + range.describe() + ", got " + quote(text);
}

double checked_isovalue(double iso, double lo, double hi, const std::string& where,
                        const std::string& field) {
    if (iso >= lo && iso <= hi) return iso;
    char msg[160];
    std::snprintf(msg, sizeof(msg), "isovalue %g is outside the value range [%g, %g]", iso, lo, hi);
    throw InputError(where, field, msg);
}

double checked_number(std::string_view text, const NumberRange& range, const std::string& where,
                      const std::string& field) {
    const std::string problem = number_problem(text, range);
    if (!problem.empty()) throw InputError(where, field, problem);
    return *parse_number(text);
}

std::optional<std::uint64_t> parse_byte_size(std::string_view text) {
    // Digits, an optional fraction, then the unit: no sign, space, exponent or hexadecimal.
    std::size_t digits = 0;
    while (digits < text.size() && std::isdigit(static_cast<unsigned char>(text[digits]))) ++digits;
    std::size_t used = digits;
    if (used < text.size() && text[used] == '.') {
        ++used;
        while (used < text.size() && std::isdigit(static_cast<unsigned char>(text[used]))) ++used;
        if (used == digits + 1) return std::nullopt;  // "5." or "5.G"
    }
    if (digits == 0) return std::nullopt;
    const std::optional<double> v = parse_number(text.substr(0, used));
    if (!v) return std::nullopt;
    std::string unit(text.substr(used));
    std::transform(unit.begin(), unit.end(), unit.begin(),
                   [](unsigned char c) { return char(std::toupper(c)); });
    double scale = 1;
    if (unit.empty() || unit == "B")
        scale = 1;
    else if (unit == "K" || unit == "KB" || unit == "KIB")
        scale = 1024.0;
    else if (unit == "M" || unit == "MB" || unit == "MIB")
        scale = 1024.0 * 1024;
    else if (unit == "G" || unit == "GB" || unit == "GIB")
        scale = 1024.0 * 1024 * 1024;
    else if (unit == "T" || unit == "TB" || unit == "TIB")
        scale = 1024.0 * 1024 * 1024 * 1024;
    else
        return std::nullopt;
    const double bytes = *v * scale;
    if (!std::isfinite(bytes) || bytes < 1 || bytes > 1.8e19) return std::nullopt;
    return static_cast<std::uint64_t>(bytes);
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

}  // namespace isowall
