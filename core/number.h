#pragma once
// Every number that enters the program (an option, a script line, a wall file) is read here: the
// whole text must spell one finite number, and the number must lie in a documented range. NaN,
// infinity, "1e999" and values that would make the view degenerate stop at the door with one line
// naming the source and the field, instead of a black image and exit 0.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace isowall {

struct NumberRange {
    double lo = 0, hi = 0;
    bool lo_open = false;  // (lo, hi] rather than [lo, hi]
    bool integer = false;  // whole numbers only

    bool contains(double v) const;
    // "a number in [1e-06, 1e+06]", "an integer in [0, 9.0072e+15]", "a number in (0, 180]"
    std::string describe() const;
};

// The ranges of the program's numbers, in one place (README, "Numbers").
namespace limits {
inline constexpr double kMaxFinite = 1.7976931348623157e308;
inline constexpr NumberRange kAnyFinite{-kMaxFinite, kMaxFinite};
// Orbit angles are reduced modulo 360; past a million degrees a float has lost the fraction.
inline constexpr NumberRange kAngleDeg{-1e6, 1e6};
inline constexpr NumberRange kZoom{1e-6, 1e6};
inline constexpr NumberRange kPan{-1e3, 1e3};         // screen widths / heights
inline constexpr NumberRange kCoordinate{-1e6, 1e6};  // look-at eye and target, object units
inline constexpr NumberRange kHead{-1e7, 1e7};        // `head`: mm, or widths of the wall
inline constexpr NumberRange kPercent{0, 100, true};  // --snapshots
inline constexpr NumberRange kSeconds{0, 1e6, true};  // --timeout, --startup-timeout
inline constexpr NumberRange kWaitSeconds{0, 1e6};    // `wait time`
inline constexpr NumberRange kRayCount{0, 9007199254740992.0, false, true};  // 2^53
inline constexpr NumberRange kCutoffDeg{0, 180, true};
inline constexpr NumberRange kFoldbackDeg{0, 180};
inline constexpr NumberRange kCellCount{1, 2147483647.0, false, true};
// --adaptive-pixels: a meta-cell's projected size target; past 64 px a meta-cell of 8 cells
// would stand for a region the size of an icon.
inline constexpr NumberRange kMetaCellPixels{0, 64, true};
// --footprint-pixels: the same size target for footprint units; 0 turns them off.
inline constexpr NumberRange kFootprintPixels{0, 64};
}  // namespace limits

// The finite number `text` spells, all of it (decimal or exponent form, an optional sign), or
// nullopt: "nan", "inf", "1e999", "0x10", "5abc" and "" are not numbers.
std::optional<double> parse_number(std::string_view text);

// Why `text` is not a number in `range`, or empty: e.g.
// `expected a number in [1e-06, 1e+06], got "0"`.
std::string number_problem(std::string_view text, const NumberRange& range);

// The number, or InputError(where, field, number_problem(...)).
double checked_number(std::string_view text, const NumberRange& range, const std::string& where,
                      const std::string& field);

// The isovalue `iso`, or InputError(where, field, "isovalue 300 is outside the value range
// [0, 220]") when it lies outside [lo, hi]: no surface there, a blank picture. The one check of an
// isovalue, from --iso or a script's `iso` line, against a volume or a served dataset.
double checked_isovalue(double iso, double lo, double hi, const std::string& where,
                        const std::string& field);

// The value of a hexadecimal digit (0-9, a-f, A-F), or -1 for any other character.
int hex_digit(char c);

// A size in bytes as an option gives it (--memory-limit): "512M", "8G", "1.5GiB", "1048576";
// nullopt for anything else (or zero).
std::optional<std::uint64_t> parse_byte_size(std::string_view text);

}  // namespace isowall
