#include "master/control_text.h"

#include <algorithm>
#include <cctype>

namespace isowall {
namespace {

// One glyph: its character and its 5 rows of 3 cells from the top, '#' lit.
struct Glyph {
    char c;
    std::array<const char*, kGlyphHeight> rows;
};

// clang-format off
constexpr Glyph kGlyphs[] = {
    {' ', {"...", "...", "...", "...", "..."}},
    {'0', {"###", "#.#", "#.#", "#.#", "###"}},
    {'1', {".#.", "##.", ".#.", ".#.", "###"}},
    {'2', {"###", "..#", "###", "#..", "###"}},
    {'3', {"###", "..#", ".##", "..#", "###"}},
    {'4', {"#.#", "#.#", "###", "..#", "..#"}},
    {'5', {"###", "#..", "###", "..#", "###"}},
    {'6', {"###", "#..", "###", "#.#", "###"}},
    {'7', {"###", "..#", "..#", ".#.", ".#."}},
    {'8', {"###", "#.#", "###", "#.#", "###"}},
    {'9', {"###", "#.#", "###", "..#", "###"}},
    {'a', {".#.", "#.#", "###", "#.#", "#.#"}},
    {'b', {"##.", "#.#", "##.", "#.#", "##."}},
    {'c', {".##", "#..", "#..", "#..", ".##"}},
    {'d', {"##.", "#.#", "#.#", "#.#", "##."}},
    {'e', {"###", "#..", "##.", "#..", "###"}},
    {'f', {"###", "#..", "##.", "#..", "#.."}},
    {'g', {".##", "#..", "#.#", "#.#", ".##"}},
    {'h', {"#.#", "#.#", "###", "#.#", "#.#"}},
    {'i', {"###", ".#.", ".#.", ".#.", "###"}},
    {'j', {"..#", "..#", "..#", "#.#", ".#."}},
    {'k', {"#.#", "#.#", "##.", "#.#", "#.#"}},
    {'l', {"#..", "#..", "#..", "#..", "###"}},
    {'m', {"#.#", "###", "###", "#.#", "#.#"}},
    {'n', {"##.", "#.#", "#.#", "#.#", "#.#"}},
    {'o', {".#.", "#.#", "#.#", "#.#", ".#."}},
    {'p', {"##.", "#.#", "##.", "#..", "#.."}},
    {'q', {".#.", "#.#", "#.#", "##.", ".##"}},
    {'r', {"##.", "#.#", "##.", "#.#", "#.#"}},
    {'s', {".##", "#..", ".#.", "..#", "##."}},
    {'t', {"###", ".#.", ".#.", ".#.", ".#."}},
    {'u', {"#.#", "#.#", "#.#", "#.#", "###"}},
    {'v', {"#.#", "#.#", "#.#", "#.#", ".#."}},
    {'w', {"#.#", "#.#", "###", "###", "#.#"}},
    {'x', {"#.#", "#.#", ".#.", "#.#", "#.#"}},
    {'y', {"#.#", "#.#", ".#.", ".#.", ".#."}},
    {'z', {"###", "..#", ".#.", "#..", "###"}},
    {'.', {"...", "...", "...", "...", ".#."}},
    {',', {"...", "...", "...", ".#.", "#.."}},
    {':', {"...", ".#.", "...", ".#.", "..."}},
    {'-', {"...", "...", "###", "...", "..."}},
    {'+', {"...", ".#.", "###", ".#.", "..."}},
    {'=', {"...", "###", "...", "###", "..."}},
    {'/', {"..#", "..#", ".#.", "#..", "#.."}},
    {'%', {"#.#", "..#", ".#.", "#..", "#.#"}},
    {'(', {".#.", "#..", "#..", "#..", ".#."}},
    {')', {".#.", "..#", "..#", "..#", ".#."}},
    {'[', {"##.", "#..", "#..", "#..", "##."}},
    {']', {".##", "..#", "..#", "..#", ".##"}},
    {'<', {"..#", ".#.", "#..", ".#.", "..#"}},
    {'>', {"#..", ".#.", "..#", ".#.", "#.."}},
    {'_', {"...", "...", "...", "...", "###"}},
};
// clang-format on

constexpr Glyph kMissing{'?', {"###", "###", "###", "###", "###"}};

const Glyph& glyph_of(char c) {
    const char lower = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    for (const Glyph& g : kGlyphs)
        if (g.c == lower) return g;
    return kMissing;
}

}  // namespace

int text_width(std::string_view text, int scale) {
    if (text.empty()) return 0;
    return (static_cast<int>(text.size()) * (kGlyphWidth + 1) - 1) * scale;
}

void fill_rect(Image& img, const PixelRect& r, Rgb colour) {
    const int x0 = std::max(r.x, 0), x1 = std::min(r.x + r.width, img.width);
    const int y0 = std::max(r.y, 0), y1 = std::min(r.y + r.height, img.height);
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const std::size_t i = 4 * (static_cast<std::size_t>(y) * img.width + x);
            for (int k = 0; k < 3; ++k) img.rgba[i + k] = colour[static_cast<std::size_t>(k)];
            img.rgba[i + 3] = 255;
        }
}

void draw_text(Image& img, int x, int y, std::string_view text, int scale, Rgb colour) {
    int gx = x;
    for (char c : text) {
        const Glyph& g = glyph_of(c);
        for (int cy = 0; cy < kGlyphHeight; ++cy)
            for (int cx = 0; cx < kGlyphWidth; ++cx)
                if (g.rows[static_cast<std::size_t>(cy)][cx] == '#')
                    fill_rect(img, {gx + cx * scale, y + cy * scale, scale, scale}, colour);
        gx += (kGlyphWidth + 1) * scale;
    }
}

}  // namespace isowall
