// Wall files: the TOML format (walls/6x4.toml documents every key), read with toml++ into a
// WallSpec. Every error names the file and the dotted field. Tile geometry is in wall_geometry.cpp.
#include "wall_spec/wall.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

#include "core/error.h"
#include "core/number.h"
#include "files/input_file.h"

namespace isowall {
namespace {

// The ranges of a wall file's numbers (README, "Numbers"). Sides in pixels stay well inside int
// arithmetic whatever the tile count, and a virtual screen of 131072 px a side is past any wall
// built so far.
constexpr long long kMaxTilePx = 32768;
constexpr long long kMaxScreenPx = 131072;
constexpr long long kMaxBezelPx = 1'000'000;
constexpr NumberRange kTileMm{1e-3, 1e6};
constexpr NumberRange kBezelMm{-1e6, 1e6};
constexpr NumberRange kViewerMm{-1e7, 1e7};
constexpr NumberRange kEyeSeparationMm{0, 1e4};
constexpr NumberRange kEyeSeparation{0, 1};
constexpr NumberRange kConvergence{1e-3, 1e3};

// A TOML value as the user wrote it, for "got ..." in error messages (toml++'s own printer
// pads arrays as "[ 6, 0 ]" and can span lines).
// Bounded like every quoted input (core/error.h): a long array or string shows its start.
std::string describe(const toml::node& node) {
    std::ostringstream os;
    if (const auto* a = node.as_array()) {
        os << '[';
        for (size_t i = 0; i < a->size() && os.tellp() <= std::streamoff(kQuoteChars); ++i)
            os << (i ? ", " : "") << describe(*a->get(i));
        os << ']';
    } else if (node.is_table()) {
        os << "a table";
    } else if (const auto* s = node.as_string()) {
        os << quote(s->get());
    } else if (const auto* b = node.as_boolean()) {
        os << (b->get() ? "true" : "false");
    } else if (const auto* i = node.as_integer()) {
        os << i->get();
    } else if (const auto* f = node.as_floating_point()) {
        // Keep 2.0 looking like a float, or "expected integers, got [2, 2]" reads as nonsense.
        os << f->get() << (std::isfinite(f->get()) && f->get() == std::floor(f->get()) ? ".0" : "");
    } else {
        os << "a date or time";
    }
    return clip(os.str());
}

// Reads one table, naming fields with their dotted path, so every error says where it is.
class Reader {
  public:
    Reader(const std::string& where, const toml::table& table, std::string prefix)
        : where_(where), table_(table), prefix_(std::move(prefix)) {}

    [[noreturn]] void fail(std::string_view key, const std::string& message) const {
        throw InputError(where_, field(key), message);
    }

    std::string field(std::string_view key) const { return prefix_ + std::string(key); }

    // Unknown keys are errors: a misspelt optional key would otherwise be silently ignored.
    void check_keys(std::initializer_list<std::string_view> allowed) const {
        for (auto&& [key, node] : table_) {
            if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
            std::string list;
            for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
            fail(key.str(), "unknown key; expected one of " + list);
        }
    }

    const toml::node* find(std::string_view key) const { return table_.get(key); }

    const toml::node& require(std::string_view key, const std::string& expected) const {
        const toml::node* n = find(key);
        if (!n) fail(key, "missing; expected " + expected);
        return *n;
    }

    // `count` integers, each in [min, max].
    std::vector<int> ints(std::string_view key, size_t count, long long min, long long max,
                          const std::string& expected) const {
        const toml::node& n = require(key, expected);
        const auto* a = n.as_array();
        std::vector<int> out;
        if (a && a->size() == count)
            for (const toml::node& e : *a) {
                const auto* i = e.as_integer();
                if (!i || i->get() < min || i->get() > max) break;
                out.push_back(static_cast<int>(i->get()));
            }
        if (out.size() != count) fail(key, "expected " + expected + ", got " + describe(n));
        return out;
    }

    // A TOML integer or float in `range` (the shared rule for numbers: finite and in range).
    static std::optional<double> number(const toml::node& n, const NumberRange& range) {
        std::optional<double> v;
        if (const auto* i = n.as_integer()) v = static_cast<double>(i->get());
        if (const auto* f = n.as_floating_point()) v = f->get();
        if (v && range.contains(*v)) return v;
        return std::nullopt;
    }

    std::vector<double> numbers(std::string_view key, size_t count, const NumberRange& range,
                                const std::string& expected) const {
        const toml::node& n = require(key, expected);
        const auto* a = n.as_array();
        std::vector<double> out;
        if (a && a->size() == count)
            for (const toml::node& e : *a) {
                const auto v = number(e, range);
                if (!v) break;
                out.push_back(*v);
            }
        if (out.size() != count) fail(key, "expected " + expected + ", got " + describe(n));
        return out;
    }

    const std::string& where() const { return where_; }

  private:
    const std::string& where_;
    const toml::table& table_;
    std::string prefix_;
};

// bezel_px / bezel_mm: one number for all four sides, or a table {left, right, top, bottom}
// with missing sides 0.
template <typename T>
void read_bezels(const Reader& r, std::string_view key, T& left, T& right, T& top, T& bottom) {
    const toml::node* n = r.find(key);
    if (!n) return;
    const bool integer = std::is_integral_v<T>;
    const std::string expected =
        integer
            ? "an integer or a table {left, right, top, bottom} of integers, each in [-1e6, 1e6]"
            : "a number or a table {left, right, top, bottom} of numbers, each in [-1e6, 1e6]";
    auto value = [&](const toml::node& v) -> std::optional<T> {
        if (integer) {
            const auto* i = v.as_integer();
            // Not std::abs: it overflows on the most negative int64.
            if (!i || i->get() < -kMaxBezelPx || i->get() > kMaxBezelPx) return std::nullopt;
            return static_cast<T>(i->get());
        }
        const auto d = Reader::number(v, kBezelMm);
        return d ? std::optional<T>(static_cast<T>(*d)) : std::nullopt;
    };
    if (const auto* t = n->as_table()) {
        const Reader sides(r.where(), *t, r.field(key) + ".");
        sides.check_keys({"left", "right", "top", "bottom"});
        for (auto [name, out] : {std::pair<std::string_view, T*>{"left", &left},
                                 {"right", &right},
                                 {"top", &top},
                                 {"bottom", &bottom}})
            if (const toml::node* s = sides.find(name)) {
                const auto v = value(*s);
                if (!v)
                    sides.fail(name, "expected " +
                                         std::string(integer ? "an integer" : "a number") +
                                         " in [-1e6, 1e6], got " + describe(*s));
                *out = *v;
            }
        return;
    }
    const auto v = value(*n);
    if (!v) r.fail(key, "expected " + expected + ", got " + describe(*n));
    left = right = top = bottom = *v;
}

RankOrder read_rank_order(const Reader& r) {
    const toml::node* n = r.find("rank_order");
    if (!n) return RankOrder::row_major;
    const auto* s = n->as_string();
    for (RankOrder o : {RankOrder::row_major, RankOrder::column_major, RankOrder::serpentine})
        if (s && s->get() == to_string(o)) return o;
    r.fail("rank_order",
           "expected \"row-major\", \"column-major\" or \"serpentine\", got " + describe(*n));
}

PhysicalSize read_physical(const Reader& top, WallSpec& spec) {
    const toml::node* n = top.find("physical");
    const auto* t = n->as_table();
    if (!t) top.fail("physical", "expected a table, got " + describe(*n));
    const Reader r(top.where(), *t, "physical.");
    r.check_keys({"tile_size_mm", "bezel_mm", "viewer_mm"});
    PhysicalSize p;
    const auto size =
        r.numbers("tile_size_mm", 2, kTileMm, "two numbers in [1e-3, 1e6] (width, height)");
    p.tile_width_mm = size[0];
    p.tile_height_mm = size[1];
    if (r.find("bezel_mm")) {
        if (top.find("bezel_px"))
            r.fail("bezel_mm", "conflicts with bezel_px; give the bezels once, in mm or in pixels");
        BezelsMm& b = p.bezel_mm;
        read_bezels(r, "bezel_mm", b.left, b.right, b.top, b.bottom);
        // The pixel pitch of the tile carries the bezels into pixels, so the virtual screen keeps
        // the wall's true proportions and lines stay straight across the mullions.
        const double pitch_x = p.tile_width_mm / spec.tile_width_px;
        const double pitch_y = p.tile_height_mm / spec.tile_height_px;
        const auto px = [&](double mm, double pitch) {
            const double v = std::round(mm / pitch);
            if (!(std::abs(v) <= double(kMaxBezelPx)))
                r.fail("bezel_mm", "a bezel of " + describe(*r.find("bezel_mm")) +
                                       " mm is more than 1e6 px at this tile's pixel pitch");
            return static_cast<int>(v);
        };
        spec.bezel_px = {px(b.left, pitch_x), px(b.right, pitch_x), px(b.top, pitch_y),
                         px(b.bottom, pitch_y)};
    }
    if (r.find("viewer_mm")) {
        const std::string expected = "three numbers (x, y, z) in [-1e7, 1e7] with z > 0";
        const auto v = r.numbers("viewer_mm", 3, kViewerMm, expected);
        if (v[2] <= 0)
            r.fail("viewer_mm", "expected " + expected + ", got " + describe(*r.find("viewer_mm")));
        p.viewer_mm = glm::dvec3(v[0], v[1], v[2]);
    }
    return p;
}

// An X display name: "[host]:D[.S]" (host letters, digits, '.', '-', '_' or a unix: prefix).
bool valid_display(const std::string& d) {
    const auto colon = d.rfind(':');
    if (colon == std::string::npos || d.size() > 255) return false;
    for (std::size_t i = 0; i < colon; ++i)
        if (!std::isalnum(static_cast<unsigned char>(d[i])) && !std::strchr(".-_", d[i]))
            return false;
    const std::string rest = d.substr(colon + 1);
    const auto dot = rest.find('.');
    const auto digits = [](const std::string& t) {
        return !t.empty() && t.size() <= 6 &&
               std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    return digits(rest.substr(0, dot)) &&
           (dot == std::string::npos || digits(rest.substr(dot + 1)));
}

std::string read_display(const Reader& r, std::string_view key = "display") {
    const toml::node* n = r.find(key);
    if (!n) return {};
    const auto* s = n->as_string();
    if (!s || !valid_display(s->get()))
        r.fail(key, "expected an X display such as \":0\" or \"node7:0.1\", got " + describe(*n));
    return s->get();
}

// [stereo]: after [physical], which decides the unit of the eye separation.
Stereo read_stereo(const Reader& top, const WallSpec& spec) {
    const toml::node* n = top.find("stereo");
    const auto* t = n->as_table();
    if (!t) top.fail("stereo", "expected a table, got " + describe(*n));
    const Reader r(top.where(), *t, "stereo.");
    r.check_keys({"mode", "eye_separation_mm", "eye_separation", "convergence", "right_display"});
    Stereo st;
    const toml::node& mode = r.require("mode", "\"side-by-side\", \"top-bottom\" or \"full\"");
    const auto* m = mode.as_string();
    bool known = false;
    for (StereoMode o : {StereoMode::side_by_side, StereoMode::top_bottom, StereoMode::full})
        if (m && m->get() == to_string(o)) st.mode = o, known = true;
    if (!known)
        r.fail("mode",
               "expected \"side-by-side\", \"top-bottom\" or \"full\", got " + describe(mode));
    const auto number = [&](std::string_view key, const NumberRange& range,
                            const std::string& expected, double otherwise) {
        const toml::node* v = r.find(key);
        if (!v) return otherwise;
        const auto x = Reader::number(*v, range);
        if (!x) r.fail(key, "expected " + expected + ", got " + describe(*v));
        return *x;
    };
    // The separation's unit follows the wall: millimetres where its size is known.
    const char* other = spec.physical ? "eye_separation" : "eye_separation_mm";
    if (r.find(other))
        r.fail(other, spec.physical ? "a wall with [physical] gives eye_separation_mm"
                                    : "needs [physical] (the wall's size in mm); give "
                                      "eye_separation, a fraction of the wall's width");
    st.separation = spec.physical
                        ? number("eye_separation_mm", kEyeSeparationMm, "mm in [0, 1e4]",
                                 kDefaultEyeSeparationMm)
                        : number("eye_separation", kEyeSeparation,
                                 "a fraction of the wall's width in [0, 1]", kDefaultEyeSeparation);
    st.convergence = number("convergence", kConvergence,
                            "a fraction of the distance to the target in [1e-3, 1e3]", 1.0);
    if (r.find("right_display")) {
        st.right_display = read_display(r, "right_display");
        if (st.mode != StereoMode::full)
            r.fail("right_display", "only the full mode shows an eye on a screen of its own");
    }
    if (st.mode == StereoMode::side_by_side && spec.tile_width_px < 2)
        r.fail("mode", "side-by-side halves the tile's width: expected tiles at least 2 px wide");
    if (st.mode == StereoMode::top_bottom && spec.tile_height_px < 2)
        r.fail("mode", "top-bottom halves the tile's height: expected tiles at least 2 px high");
    return st;
}

void read_overrides(const Reader& top, WallSpec& spec) {
    const toml::node* n = top.find("tile");
    const auto* a = n->as_array();
    if (!a || !a->is_array_of_tables())
        top.fail("tile", "expected [[tile]] tables, got " + describe(*n));
    for (size_t i = 0; i < a->size(); ++i) {
        const Reader r(top.where(), *a->get(i)->as_table(), "tile[" + std::to_string(i) + "].");
        r.check_keys({"column", "row", "disabled", "offset_px", "display"});
        TileOverride o;
        auto index = [&](std::string_view key, int count) {
            const std::string expected = "an integer in [0, " + std::to_string(count - 1) + "]";
            const toml::node& v = r.require(key, expected);
            const auto* iv = v.as_integer();
            if (!iv || iv->get() < 0 || iv->get() >= count)
                r.fail(key, "expected " + expected + ", got " + describe(v));
            return static_cast<int>(iv->get());
        };
        o.column = index("column", spec.columns);
        o.row = index("row", spec.rows);
        if (const toml::node* d = r.find("disabled")) {
            const auto* b = d->as_boolean();
            if (!b) r.fail("disabled", "expected true or false, got " + describe(*d));
            o.disabled = b->get();
        }
        if (r.find("offset_px")) {
            // A nudge of at most the tile's own size: further, the tile would show a part of
            // the virtual screen that is not its own, or none of it (a grey tile, exit 0).
            const long long w = spec.tile_width_px, h = spec.tile_height_px;
            const auto off = r.ints("offset_px", 2, -std::max(w, h), std::max(w, h),
                                    "two integers (x right, y down) within the tile's size, [-" +
                                        std::to_string(w) + ", " + std::to_string(w) + "] and [-" +
                                        std::to_string(h) + ", " + std::to_string(h) + "]");
            if (std::abs(off[0]) > w || std::abs(off[1]) > h)
                r.fail("offset_px", "(" + std::to_string(off[0]) + ", " + std::to_string(off[1]) +
                                        ") moves the tile past its own size " + std::to_string(w) +
                                        "x" + std::to_string(h));
            o.offset_x_px = off[0];
            o.offset_y_px = off[1];
        }
        o.display = read_display(r);
        for (const TileOverride& prev : spec.overrides)
            if (prev.column == o.column && prev.row == o.row)
                r.fail("column", "tile (" + std::to_string(o.column) + ", " +
                                     std::to_string(o.row) + ") is given twice");
        spec.overrides.push_back(o);
    }
    if (rank_count(spec) == 1) top.fail("tile", "every tile is disabled; expected at least one");
}

// In 64-bit arithmetic, before anything computes it in int. Named for the tiles when they alone
// are too wide, else for the bezels that make them so.
void check_screen_size(const std::string& where, const std::string& bezel_field,
                       const WallSpec& spec) {
    const Bezels& b = spec.bezel_px;
    const long long tiles_w = 1LL * spec.columns * spec.tile_width_px;
    const long long tiles_h = 1LL * spec.rows * spec.tile_height_px;
    const long long w = tiles_w + (spec.columns - 1LL) * (b.left + b.right);
    const long long h = tiles_h + (spec.rows - 1LL) * (b.top + b.bottom);
    if (w <= kMaxScreenPx && h <= kMaxScreenPx) return;
    const bool tiles = tiles_w > kMaxScreenPx || tiles_h > kMaxScreenPx;
    throw InputError(where, tiles ? "tiles" : bezel_field,
                     "the virtual screen would be " + std::to_string(w) + "x" + std::to_string(h) +
                         " px; expected at most " + std::to_string(kMaxScreenPx) + " a side");
}

}  // namespace

std::string to_string(RankOrder order) {
    switch (order) {
        case RankOrder::row_major:
            return "row-major";
        case RankOrder::column_major:
            return "column-major";
        case RankOrder::serpentine:
            return "serpentine";
    }
    return "?";
}

WallSpec parse_wall(std::string_view toml_text, const std::string& where) {
    toml::table doc;
    try {
        doc = toml::parse(toml_text, where);
    } catch (const toml::parse_error& e) {
        std::string msg(e.description());
        std::replace(msg.begin(), msg.end(), '\n', ' ');
        const auto& pos = e.source().begin;
        throw InputError(
            where, "line " + std::to_string(pos.line) + ", column " + std::to_string(pos.column),
            "TOML syntax: " + msg);
    }
    const Reader r(where, doc, "");
    r.check_keys({"tiles", "tile_size_px", "bezel_px", "rank_order", "physical", "tile", "display",
                  "stereo"});

    WallSpec spec;
    const auto tiles = r.ints("tiles", 2, 1, std::numeric_limits<int>::max(),
                              "two positive integers (columns, rows)");
    spec.columns = tiles[0];
    spec.rows = tiles[1];
    if (static_cast<long long>(spec.columns) * spec.rows > 1'000'000)
        r.fail("tiles", "expected at most a million tiles, got " + describe(*r.find("tiles")));
    const auto size =
        r.ints("tile_size_px", 2, 1, kMaxTilePx, "two integers in [1, 32768] (width, height)");
    spec.tile_width_px = size[0];
    spec.tile_height_px = size[1];
    Bezels& b = spec.bezel_px;
    read_bezels(r, "bezel_px", b.left, b.right, b.top, b.bottom);
    spec.rank_order = read_rank_order(r);
    spec.display = read_display(r);
    if (r.find("physical")) spec.physical = read_physical(r, spec);

    // Overlap of a whole tile or more would reorder the tiles on the virtual screen.
    const std::string bezel_field = r.find("bezel_px") ? "bezel_px" : "physical.bezel_mm";
    if (b.left + b.right <= -spec.tile_width_px)
        throw InputError(where, bezel_field,
                         "expected horizontal overlap (-(left + right) = " +
                             std::to_string(-(b.left + b.right)) +
                             " px) less than the tile width " + std::to_string(spec.tile_width_px));
    if (b.top + b.bottom <= -spec.tile_height_px)
        throw InputError(
            where, bezel_field,
            "expected vertical overlap (-(top + bottom) = " + std::to_string(-(b.top + b.bottom)) +
                " px) less than the tile height " + std::to_string(spec.tile_height_px));

    check_screen_size(where, bezel_field, spec);
    if (r.find("tile")) read_overrides(r, spec);
    if (r.find("stereo")) spec.stereo = read_stereo(r, spec);
    return spec;
}

WallSpec load_wall(const std::filesystem::path& path) {
    return parse_wall(read_input_file(path, "file", kMaxWallFileBytes), path.string());
}

}  // namespace isowall
