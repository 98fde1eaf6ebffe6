#include "remote/cell_units.h"

#include <algorithm>
#include <cstddef>
#include <string>
#include <tuple>
#include <utility>

#include <glm/common.hpp>

namespace isowall::remote::cells {
namespace {

// ---- units on the wire -----------------------------------------------------------------------

void put_leb128(ByteWriter& w, std::uint64_t v) {
    while (v >= 0x80) {
        w.put(static_cast<std::uint8_t>(v | 0x80));
        v >>= 7;
    }
    w.put(static_cast<std::uint8_t>(v));
}

std::uint64_t get_leb128(ByteReader& r) {
    std::uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
        const auto b = r.get<std::uint8_t>();
        v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
        if ((b & 0x80) == 0) return v;
    }
    r.fail("unit gap: a LEB128 number longer than 64 bits");
}

}  // namespace

void put_units(ByteWriter& w, const std::vector<Unit>& units, glm::ivec3 dims) {
    std::vector<int> levels;
    for (const Unit& u : units)
        if (levels.empty() || levels.back() != u.level) levels.push_back(u.level);
    w.put(static_cast<std::uint8_t>(levels.size()));
    std::size_t i = 0;
    for (const int level : levels) {
        std::size_t end = i;
        while (end < units.size() && units[end].level == level) ++end;
        w.put(static_cast<std::uint8_t>(level));
        w.put(static_cast<std::uint32_t>(end - i));
        const glm::ivec3 grid = unit_grid(dims, level);
        std::uint64_t next = 0;  // gaps from one past the previous unit
        for (; i < end; ++i) {
            const std::uint64_t at = linear(units[i].base >> level, grid);
            put_leb128(w, at - next);
            next = at + 1;
        }
    }
}

glm::ivec3 unit_grid(glm::ivec3 dims, int level) {
    const glm::ivec3 cells = glm::max(dims - 1, glm::ivec3(0));
    return (cells + ((1 << level) - 1)) >> level;
}

std::uint64_t linear(glm::ivec3 p, glm::ivec3 d) {
    return (static_cast<std::uint64_t>(p.z) * static_cast<std::uint64_t>(d.y) +
            static_cast<std::uint64_t>(p.y)) *
               static_cast<std::uint64_t>(d.x) +
           static_cast<std::uint64_t>(p.x);
}

glm::ivec3 unlinear(std::uint64_t i, glm::ivec3 d) {
    const auto dx = static_cast<std::uint64_t>(d.x), dy = static_cast<std::uint64_t>(d.y);
    return {static_cast<int>(i % dx), static_cast<int>((i / dx) % dy),
            static_cast<int>(i / (dx * dy))};
}

bool complete(const Unit& u, glm::ivec3 dims) {
    const int s = 1 << u.level;
    for (int a = 0; a < 3; ++a)
        if (u.base[a] < 0 || u.base[a] % s != 0 || u.base[a] + s > dims[a] - 1) return false;
    return true;
}

void sort_units(std::vector<Unit>& units, glm::ivec3 dims) {
    std::vector<std::tuple<int, std::uint64_t, std::size_t>> keys(units.size());
    for (std::size_t i = 0; i < units.size(); ++i) {
        const Unit& u = units[i];
        keys[i] = {u.level, linear(u.base >> u.level, unit_grid(dims, u.level)), i};
    }
    std::sort(keys.begin(), keys.end());
    std::vector<Unit> sorted(units.size());
    for (std::size_t i = 0; i < keys.size(); ++i) sorted[i] = units[std::get<2>(keys[i])];
    units = std::move(sorted);
}

VoxelBox box_of(const std::vector<Unit>& units, glm::ivec3 dims) {
    glm::ivec3 lo(dims), hi(0);
    for (const Unit& u : units) {
        lo = glm::min(lo, u.base);
        hi = glm::max(hi, u.base + (1 << u.level));
    }
    const glm::ivec3 origin = glm::max(lo - 1, glm::ivec3(0));
    return {origin, glm::min(hi + 1, dims - 1) - origin + 1};
}

std::vector<Unit> get_units(ByteReader& r, glm::ivec3 dims, std::uint32_t max_units) {
    std::vector<Unit> units;
    const auto buckets = r.get<std::uint8_t>();
    int last_level = -1;
    for (int b = 0; b < buckets; ++b) {
        const int level = r.get<std::uint8_t>();
        if (level <= last_level || level > kMaxUnitLevel)
            r.fail("unit level " + std::to_string(level) + ": expected " +
                   std::to_string(last_level + 1) + ".." + std::to_string(kMaxUnitLevel));
        last_level = level;
        const auto count = r.get<std::uint32_t>();
        if (count > max_units - units.size())
            r.fail("unit count " + std::to_string(count) + " over the limit " +
                   std::to_string(max_units));
        r.need_elements(count, 1, "units");  // at least one byte of gap each
        const glm::ivec3 grid = unit_grid(dims, level);
        const std::uint64_t cells = linear(grid - 1, grid) + 1;
        std::uint64_t next = 0;
        for (std::uint32_t k = 0; k < count; ++k) {
            const std::uint64_t gap = get_leb128(r);
            if (gap >= cells - next)
                r.fail("unit " + std::to_string(units.size()) + ": past the volume's " +
                       std::to_string(cells) + " units of level " + std::to_string(level));
            const std::uint64_t at = next + gap;
            next = at + 1;
            const Unit u{unlinear(at, grid) << level, level};
            if (!complete(u, dims))
                r.fail("unit " + std::to_string(units.size()) + ": a meta-cell of level " +
                       std::to_string(level) + " that reaches past the volume");
            units.push_back(u);
        }
    }
    if (units.empty()) r.fail("units: none");
    return units;
}

}  // namespace isowall::remote::cells
