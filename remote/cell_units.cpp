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

// Each bucket's units as the occupancy of its box in that level's grid of units, z, then y, then
// x, one bit a place through the range coder, its probability chosen by ten places before it: the
// two along x, the three of the row below, the five nearest of the slice below. A surface's units
// lie in sheets a unit or two thick, so a place beside, below or behind an occupied one tells a
// lot: on one frame's groups of cthead at 600 and the 256 head at 40 the units took 40% fewer
// bytes than as LEB128 gaps through zstd. The places coded are the boxes' volumes, several times
// the units.
//
// A bucket's box of places with a border of empty ones (two before x, one after; one before and
// after y; one before z), so the ten places a context reads need no bounds checks.
class Occupancy {
  public:
    explicit Occupancy(glm::ivec3 size)
        : n_(size),
          sy_(static_cast<std::ptrdiff_t>(size.x) + 3),
          sz_(sy_ * (static_cast<std::ptrdiff_t>(size.y) + 2)),
          places_(static_cast<std::size_t>(sz_ * (static_cast<std::ptrdiff_t>(size.z) + 1)), 0) {}
    // What a box of `size` holds, its border included: what the limits count.
    static std::uint64_t held(glm::ivec3 size) {
        return (static_cast<std::uint64_t>(size.x) + 3) * (static_cast<std::uint64_t>(size.y) + 2) *
               (static_cast<std::uint64_t>(size.z) + 1);
    }
    std::uint8_t& at(glm::ivec3 p) { return places_[index(p.x, p.y, p.z)]; }

    template <class Bit>
    void code(std::vector<BitProbability>& context, Bit&& bit) {
        for (int z = 0; z < n_.z; ++z)
            for (int y = 0; y < n_.y; ++y) {
                std::uint8_t* p = &places_[index(0, y, z)];
                for (int x = 0; x < n_.x; ++x, ++p) {
                    const unsigned c = p[-1] | p[-2] << 1 | p[-sy_ - 1] << 2 | p[-sy_] << 3 |
                                       p[-sy_ + 1] << 4 | p[-sz_ - sy_] << 5 | p[-sz_ - 1] << 6 |
                                       p[-sz_] << 7 | p[-sz_ + 1] << 8 | p[-sz_ + sy_] << 9;
                    *p = static_cast<std::uint8_t>(bit(context[c], *p));
                }
            }
    }

  private:
    std::size_t index(int x, int y, int z) const {
        return static_cast<std::size_t>((z + 1) * sz_ + (y + 1) * sy_ + (x + 2));
    }
    glm::ivec3 n_;
    std::ptrdiff_t sy_, sz_;
    std::vector<std::uint8_t> places_;
};

constexpr std::size_t kOccupancyContexts = 1024;

}  // namespace

std::uint64_t UnitBucket::places() const {
    return static_cast<std::uint64_t>(size.x) * static_cast<std::uint64_t>(size.y) *
           static_cast<std::uint64_t>(size.z);
}

bool put_units(ByteWriter& w, RangeEncoder& bits, const std::vector<Unit>& units) {
    std::vector<std::pair<UnitBucket, std::size_t>> buckets;  // and each one's first unit
    for (std::size_t i = 0; i < units.size(); ++i) {
        const glm::ivec3 p = units[i].base >> units[i].level;
        if (buckets.empty() || buckets.back().first.level != units[i].level) {
            buckets.push_back({{units[i].level, 0, p, p}, i});
        }
        UnitBucket& b = buckets.back().first;
        ++b.count;
        b.origin = glm::min(b.origin, p);
        b.size = glm::max(b.size, p);  // the far corner, for now
    }
    std::uint64_t held = 0;
    for (auto& [b, first] : buckets) {
        b.size = b.size - b.origin + 1;
        held += Occupancy::held(b.size);
    }
    if (held > kMaxUnitBoxPlaces) return false;  // get_units would refuse it
    w.put(static_cast<std::uint8_t>(buckets.size()));
    for (const auto& [b, first] : buckets) {
        w.put(static_cast<std::uint8_t>(b.level));
        w.put(b.count);
        for (int a = 0; a < 3; ++a) put_leb128(w, static_cast<std::uint64_t>(b.origin[a]));
        for (int a = 0; a < 3; ++a) put_leb128(w, static_cast<std::uint64_t>(b.size[a]));
    }
    std::vector<BitProbability> context(kOccupancyContexts);
    for (const auto& [b, first] : buckets) {
        Occupancy occupied(b.size);
        for (std::size_t i = first; i < first + b.count; ++i)
            occupied.at((units[i].base >> b.level) - b.origin) = 1;
        occupied.code(context, [&](BitProbability& p, unsigned v) {
            bits.bit(p, v);
            return v;
        });
    }
    return true;
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

std::vector<UnitBucket> get_unit_buckets(ByteReader& r, glm::ivec3 dims, std::uint32_t max_units) {
    std::vector<UnitBucket> buckets;
    std::uint64_t units = 0;
    const auto n = r.get<std::uint8_t>();
    int last_level = -1;
    for (int k = 0; k < n; ++k) {
        UnitBucket b;
        b.level = r.get<std::uint8_t>();
        if (b.level <= last_level || b.level > kMaxUnitLevel)
            r.fail("unit level " + std::to_string(b.level) + ": expected " +
                   std::to_string(last_level + 1) + ".." + std::to_string(kMaxUnitLevel));
        last_level = b.level;
        b.count = r.get<std::uint32_t>();
        if (b.count == 0 || b.count > max_units - units)
            r.fail("unit count " + std::to_string(b.count) + ": expected 1.." +
                   std::to_string(max_units - units) + " (over the limit " +
                   std::to_string(max_units) + " in all)");
        units += b.count;
        const glm::ivec3 grid = unit_grid(dims, b.level);
        for (int a = 0; a < 3; ++a) {
            const std::uint64_t o = get_leb128(r);
            if (o >= static_cast<std::uint64_t>(grid[a]))
                r.fail("units of level " + std::to_string(b.level) + ": a box past the volume's " +
                       std::to_string(grid[a]) + " units along axis " + std::to_string(a));
            b.origin[a] = static_cast<int>(o);
        }
        for (int a = 0; a < 3; ++a) {
            const std::uint64_t s = get_leb128(r);
            if (s == 0 || s > static_cast<std::uint64_t>(grid[a] - b.origin[a]))
                r.fail("units of level " + std::to_string(b.level) + ": a box past the volume's " +
                       std::to_string(grid[a]) + " units along axis " + std::to_string(a));
            b.size[a] = static_cast<int>(s);
        }
        if (b.places() > kMaxUnitBoxPlaces)
            r.fail("units: spread over " + std::to_string(b.places()) + " places of level " +
                   std::to_string(b.level) + ", over the limit " +
                   std::to_string(kMaxUnitBoxPlaces));
        if (b.count > b.places())
            r.fail("unit count " + std::to_string(b.count) + ": more than the " +
                   std::to_string(b.places()) + " places of its box");
        buckets.push_back(b);
    }
    if (buckets.empty()) r.fail("units: none");
    return buckets;
}

std::vector<Unit> get_units(const ByteReader& r, RangeDecoder& bits,
                            const std::vector<UnitBucket>& buckets, glm::ivec3 dims,
                            std::uint64_t max_places) {
    std::uint64_t places = 0, held = 0;
    for (const UnitBucket& b : buckets) {
        places += b.places();
        held += Occupancy::held(b.size);
    }
    if (places > max_places)
        r.fail("units: boxes of " + std::to_string(places) + " places, more than the coded " +
               "stream can hold (" + std::to_string(max_places) + ")");
    if (held > kMaxUnitBoxPlaces)
        r.fail("units: boxes of " + std::to_string(held) + " places with their borders, over " +
               "the limit " + std::to_string(kMaxUnitBoxPlaces));
    std::vector<Unit> units;
    std::vector<BitProbability> context(kOccupancyContexts);
    for (const UnitBucket& b : buckets) {
        Occupancy occupied(b.size);
        occupied.code(context, [&](BitProbability& p, unsigned) { return bits.bit(p); });
        std::uint64_t set = 0;
        for (int z = 0; z < b.size.z; ++z)
            for (int y = 0; y < b.size.y; ++y)
                for (int x = 0; x < b.size.x; ++x) {
                    if (!occupied.at({x, y, z}) || ++set > b.count) continue;
                    const Unit u{(b.origin + glm::ivec3(x, y, z)) << b.level, b.level};
                    if (!complete(u, dims))
                        r.fail("unit " + std::to_string(units.size()) + ": a meta-cell of level " +
                               std::to_string(b.level) + " that reaches past the volume");
                    units.push_back(u);
                }
        if (set != b.count)
            r.fail("units of level " + std::to_string(b.level) + ": " + std::to_string(set) +
                   " in the box's bits, " + std::to_string(b.count) + " in its count");
    }
    return units;
}

}  // namespace isowall::remote::cells
