#include "remote/cell_codec.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "common/extract/edge_cache.h"
#include "common/extract/marching_cubes.h"
#include "common/extract/mc_tables.h"

namespace isowall::remote {
namespace {

// A meta-cell of level 16 spans 65536 cells a side: past what kMaxCellBoxVoxels lets a group hold.
constexpr int kMaxUnitLevel = 16;
constexpr std::uint32_t kMaxUnits = kMaxGroupTriangles;

struct Unit {
    glm::ivec3 base{0};  // its first cell, a multiple of 2^level on each axis
    int level = 0;
};

// Units per axis at `level` in a volume of `dims` voxels.
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

// Sorted by level, then by index in that level's grid of units: the order both sides triangulate.
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

// ---- the voxels a side holds -----------------------------------------------------------------

// The box of voxels the units read: their extent, one voxel around it, inside the volume.
struct VoxelBox {
    glm::ivec3 origin{0}, size{0};
    std::uint64_t voxels() const {
        return static_cast<std::uint64_t>(size.x) * static_cast<std::uint64_t>(size.y) *
               static_cast<std::uint64_t>(size.z);
    }
};

VoxelBox box_of(const std::vector<Unit>& units, glm::ivec3 dims) {
    glm::ivec3 lo(dims), hi(0);
    for (const Unit& u : units) {
        lo = glm::min(lo, u.base);
        hi = glm::max(hi, u.base + (1 << u.level));
    }
    const glm::ivec3 origin = glm::max(lo - 1, glm::ivec3(0));
    return {origin, glm::min(hi + 1, dims - 1) - origin + 1};
}

// Voxels of the box held in 4x4x4 bricks, a brick only once a voxel of it is named: a thin
// diagonal pass (a vessel) spans a box far larger than the voxels it reads. It is the view the
// client's marching cubes reads, in the volume's coordinates and with the volume's dims, so the
// client's arithmetic is the server's to the bit (marching_cubes.h: a bricked() view is read
// through at() alone; a voxel never named reads as 0, and marching cubes reads only named ones).
// Both sides fill it as values are sent, in the same order, and predict each from those known.
template <class T>
class BoxVoxels {
  public:
    static constexpr int kLog2 = 2;
    static constexpr int kSide = 1 << kLog2;
    static constexpr std::size_t kBrick = kSide * kSide * kSide;

    BoxVoxels(const VoxelBox& box, glm::ivec3 volume_dims, glm::vec3 spacing_)
        : dims(volume_dims), spacing(spacing_), origin_(box.origin), size_(box.size),
          grid_((box.size + (kSide - 1)) >> kLog2),
          directory_(static_cast<std::size_t>(grid_.x) * static_cast<std::size_t>(grid_.y) *
                         static_cast<std::size_t>(grid_.z),
                     kNone) {}

    // VolumeView's members as marching_cubes.h reads them; coordinates are the volume's.
    const T* data = nullptr;
    glm::ivec3 dims{0};
    glm::vec3 spacing{1.0f};
    bool bricked() const { return true; }
    std::size_t index(int, int, int) const { return 0; }
    T at(int x, int y, int z) const {
        const glm::ivec3 p = glm::ivec3(x, y, z) - origin_;
        const std::uint32_t b = directory_[brick_of(p)];
        return b == kNone ? T{} : voxels_[b * kBrick + inner(p)];
    }

    // Names the voxel at p; true when it was not named before.
    bool name(glm::ivec3 p) {
        p -= origin_;
        std::uint32_t& b = directory_[brick_of(p)];
        if (b == kNone) {
            b = static_cast<std::uint32_t>(marks_.size());
            marks_.push_back(0);
            known_.push_back(0);
            edges_.insert(edges_.end(), 3, 0);
            voxels_.resize(voxels_.size() + kBrick);
        }
        const std::uint64_t bit = std::uint64_t{1} << inner(p);
        if (marks_[b] & bit) return false;
        marks_[b] |= bit;
        return true;
    }
    // The value of the named voxel at p: known from now on.
    void set(glm::ivec3 p, T value) {
        p -= origin_;
        const std::uint32_t b = directory_[brick_of(p)];
        voxels_[b * kBrick + inner(p)] = value;
        known_[b] |= std::uint64_t{1} << inner(p);
    }
    // True the first time it is asked of the cell edge from the named voxel pa along `axis`.
    bool first_edge(glm::ivec3 pa, int axis) {
        pa -= origin_;
        std::uint64_t& bits = edges_[3 * directory_[brick_of(pa)] + static_cast<std::size_t>(axis)];
        const std::uint64_t bit = std::uint64_t{1} << inner(pa);
        if (bits & bit) return false;
        bits |= bit;
        return true;
    }
    // The value at p when it is known (set), through one directory lookup.
    bool known(glm::ivec3 p, T& value) const {
        p -= origin_;
        if (p.x < 0 || p.y < 0 || p.z < 0 || p.x >= size_.x || p.y >= size_.y || p.z >= size_.z)
            return false;
        const std::uint32_t b = directory_[brick_of(p)];
        if (b == kNone || (known_[b] >> inner(p) & 1) == 0) return false;
        value = voxels_[b * kBrick + inner(p)];
        return true;
    }

  private:
    static constexpr std::uint32_t kNone = 0xffffffffu;
    // p in box coordinates.
    std::size_t brick_of(glm::ivec3 p) const {
        return (static_cast<std::size_t>(p.z >> kLog2) * static_cast<std::size_t>(grid_.y) +
                static_cast<std::size_t>(p.y >> kLog2)) *
                   static_cast<std::size_t>(grid_.x) +
               static_cast<std::size_t>(p.x >> kLog2);
    }
    static std::size_t inner(glm::ivec3 p) {
        constexpr int m = kSide - 1;
        return static_cast<std::size_t>((p.z & m) << (2 * kLog2) | (p.y & m) << kLog2 | (p.x & m));
    }
    glm::ivec3 origin_, size_;
    glm::ivec3 grid_;
    std::vector<std::uint32_t> directory_;
    std::vector<std::uint64_t> marks_, known_;  // per brick: a bit per voxel named, known
    std::vector<std::uint64_t> edges_;          // per brick and axis: a bit per cell edge seen
    std::vector<T> voxels_;
};

// Which voxels of the box a phase names: each once, in increasing index, none an earlier phase
// named. Box indices run z, y, x like the volume's, so the order is the volume's too. On the
// client (`r` set) every voxel named must have its value in the bytes left, checked as it is
// named, so the bricks held stay within 64 voxels per byte received.
template <class T>
class PhaseVoxels {
  public:
    PhaseVoxels(BoxVoxels<T>& held, const VoxelBox& box, const ByteReader* r)
        : held_(held), box_(box), r_(r) {}
    void add(glm::ivec3 p) {
        if (!held_.name(p)) return;
        fresh_.push_back(static_cast<std::uint32_t>(linear(p - box_.origin, box_.size)));
        if (r_ && fresh_.size() > r_->remaining() / sizeof(T))
            r_->fail("voxel values: more voxels named than the " +
                     std::to_string(r_->remaining()) + " bytes left hold");
    }
    bool first_edge(glm::ivec3 pa, int axis) { return held_.first_edge(pa, axis); }
    // The voxels named since the last call, in increasing index.
    std::vector<std::uint32_t> take() {
        std::sort(fresh_.begin(), fresh_.end());
        return std::exchange(fresh_, {});
    }

  private:
    BoxVoxels<T>& held_;
    VoxelBox box_;
    const ByteReader* r_;
    std::vector<std::uint32_t> fresh_;
};

// What a side reads voxels through: the volume on the server, the received voxels of the box on
// the client. `dims` is the whole volume's.
template <class View>
struct Held {
    const View& view;
    glm::ivec3 dims{0};
    double iso = 0;

    void corners(const Unit& u, double c[8]) const { meta_cell_corners(view, u.base, u.level, c); }
};

// Each unit's corner values, read once phase 1's are in place.
using Corners = std::vector<std::array<double, 8>>;

bool crossed(const std::array<double, 8>& c, int e, double iso) {
    const auto& ends = mc::kEdgeCorners[static_cast<std::size_t>(e)];
    return (c[ends[0]] >= iso) != (c[ends[1]] >= iso);
}

// Phase 1: every unit's corners.
template <class T>
void phase_corners(const std::vector<Unit>& units, PhaseVoxels<T>& out) {
    for (const Unit& u : units)
        for (const auto& o : mc::kCornerOffset)
            out.add(u.base + (glm::ivec3(o[0], o[1], o[2]) << u.level));
}

// Phase 2: the inner voxels of each crossed edge of a meta-cell.
template <class View, class T>
void phase_edges(const Held<View>& h, const std::vector<Unit>& units, const Corners& corners,
                 PhaseVoxels<T>& out) {
    for (std::size_t i = 0; i < units.size(); ++i) {
        const Unit& u = units[i];
        if (u.level == 0) continue;
        const auto& c = corners[i];
        for (int e = 0; e < 12; ++e) {
            if (!crossed(c, e, h.iso)) continue;
            glm::ivec3 p = edge_start(u.base, u.level, e);
            const int axis = mc::kEdgeAxis[static_cast<std::size_t>(e)];
            for (int k = 1; k < (1 << u.level); ++k) {
                ++p[axis];
                out.add(p);
            }
        }
    }
}

// Phase 3: the six neighbours (inside the volume) of the two voxels that bracket each crossing,
// which central differences read for the vertex's normal. A cell edge is looked at once, not by
// each of the four cells around it.
template <class View, class T>
void phase_gradients(const Held<View>& h, const std::vector<Unit>& units, const Corners& corners,
                     PhaseVoxels<T>& out) {
    for (std::size_t i = 0; i < units.size(); ++i) {
        const Unit& u = units[i];
        const auto& c = corners[i];
        for (int e = 0; e < 12; ++e) {
            if (!crossed(c, e, h.iso)) continue;
            const auto& ends = mc::kEdgeCorners[static_cast<std::size_t>(e)];
            const glm::ivec3 pa = edge_start(u.base, u.level, e);
            const int axis = mc::kEdgeAxis[static_cast<std::size_t>(e)];
            if (u.level == 0 && !out.first_edge(pa, axis)) continue;
            const EdgeCrossing x =
                edge_crossing(h.view, pa, axis, u.level, h.iso, c[ends[0]], c[ends[1]]);
            glm::ivec3 q = pa;
            q[axis] += x.segment;
            for (int end = 0; end < 2; ++end, ++q[axis])
                for (int a = 0; a < 3; ++a) {
                    glm::ivec3 n = q;
                    if (q[a] > 0) {
                        n[a] = q[a] - 1;
                        out.add(n);
                    }
                    if (q[a] < h.dims[a] - 1) {
                        n[a] = q[a] + 1;
                        out.add(n);
                    }
                }
        }
    }
}

// The three phases in order, naming voxels in `named`; `take` is called with each phase's voxels
// (box indices) once the earlier phases' values are in place (the client reads them there).
// Returns each unit's corner values.
template <class View, class T, class Take>
Corners each_phase(const Held<View>& h, PhaseVoxels<T>& named, const std::vector<Unit>& units,
                   Take&& take) {
    phase_corners(units, named);
    take(named.take());
    Corners corners(units.size());
    for (std::size_t i = 0; i < units.size(); ++i) h.corners(units[i], corners[i].data());
    phase_edges(h, units, corners, named);
    take(named.take());
    phase_gradients(h, units, corners, named);
    take(named.take());
    return corners;
}

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

std::vector<Unit> get_units(ByteReader& r, glm::ivec3 dims) {
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
        if (count > kMaxUnits - units.size())
            r.fail("unit count " + std::to_string(count) + " over the limit " +
                   std::to_string(kMaxUnits));
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

// ---- voxel values: predicted, the residuals as byte planes ------------------------------------

// Integer voxels go as the difference to a prediction from the voxels already known (both sides
// know the same ones at each step): the mean of the known face neighbours, else the value sent
// just before. The difference is taken modulo 2^bits and zigzagged, so small ones of either sign
// are small numbers and every value round-trips. Floating-point voxels go as they are.
template <class T>
T predict(const BoxVoxels<T>& held, glm::ivec3 p, T previous) {
    if constexpr (!std::is_integral_v<T>) {
        return T{};
    } else {
        std::int64_t sum = 0;
        std::int64_t n = 0;
        for (int a = 0; a < 3; ++a)
            for (int d : {-1, 1}) {
                glm::ivec3 q = p;
                q[a] += d;
                T value;
                if (!held.known(q, value)) continue;
                sum += static_cast<std::int64_t>(value);
                ++n;
            }
        if (n == 0) return previous;
        return static_cast<T>(sum >= 0 ? (sum + n / 2) / n : -((-sum + n / 2) / n));
    }
}

template <class T>
auto residual(T value, T predicted) {
    if constexpr (!std::is_integral_v<T>) {
        return value;
    } else {
        using U = std::make_unsigned_t<T>;
        using S = std::make_signed_t<T>;
        const auto d = static_cast<S>(static_cast<U>(static_cast<U>(value) - static_cast<U>(predicted)));
        return static_cast<U>(static_cast<U>(static_cast<U>(d) << 1) ^
                              static_cast<U>(d >> (8 * sizeof(T) - 1)));
    }
}

template <class T, class R>
T from_residual(R r, T predicted) {
    if constexpr (!std::is_integral_v<T>) {
        return r;
    } else {
        using U = std::make_unsigned_t<T>;
        const auto d = static_cast<U>(static_cast<U>(r >> 1) ^ static_cast<U>(-static_cast<U>(r & 1)));
        return static_cast<T>(static_cast<U>(static_cast<U>(predicted) + d));
    }
}

template <class T>
using Residual = decltype(residual(T{}, T{}));

template <class T>
void put_values(ByteWriter& w, BoxVoxels<T>& held, const VolumeView<T>& v, const VoxelBox& box,
                const std::vector<std::uint32_t>& at) {
    std::vector<Residual<T>> out(at.size());
    T previous{};
    for (std::size_t i = 0; i < at.size(); ++i) {
        const glm::ivec3 p = box.origin + unlinear(at[i], box.size);
        const T value = v.at(p.x, p.y, p.z);
        out[i] = residual(value, predict(held, p, previous));
        held.set(p, value);
        previous = value;
    }
    std::vector<std::uint8_t> plane(at.size());
    for (std::size_t b = 0; b < sizeof(T); ++b) {
        for (std::size_t i = 0; i < at.size(); ++i)
            plane[i] = reinterpret_cast<const std::uint8_t*>(&out[i])[b];
        w.put_raw(std::span<const std::uint8_t>(plane));
    }
}

template <class T>
void get_values(ByteReader& r, BoxVoxels<T>& held, const VoxelBox& box,
                const std::vector<std::uint32_t>& at) {
    r.need_elements(at.size(), sizeof(T), "voxel values");
    std::vector<Residual<T>> in(at.size());
    for (std::size_t b = 0; b < sizeof(T); ++b) {
        const auto plane = r.get_span(at.size());
        for (std::size_t i = 0; i < at.size(); ++i)
            reinterpret_cast<std::uint8_t*>(&in[i])[b] = plane[i];
    }
    T previous{};
    for (std::size_t i = 0; i < at.size(); ++i) {
        const glm::ivec3 p = box.origin + unlinear(at[i], box.size);
        const T value = from_residual(in[i], predict(held, p, previous));
        held.set(p, value);
        previous = value;
    }
}

// ---- encoder and decoder, per voxel type -------------------------------------------------------

// The units whose triangles make the group's mesh: the active ones of its pass, or every active
// cell of a refinement's meta-cell; nullopt when one is not a complete unit of the volume.
template <class View>
std::optional<std::vector<Unit>> units_of(const Group& g, const Held<View>& h) {
    std::vector<Unit> all;
    if (g.refinement) {
        const int s = 1 << g.level;
        for (int z = 0; z < s; ++z)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) all.push_back({g.seed + glm::ivec3(x, y, z), 0});
    } else {
        for (std::size_t i = 0; i < g.cells.size(); ++i)
            all.push_back({g.cells[i], g.level_of_cell(i)});
    }
    std::vector<Unit> units;
    double c[8];
    for (const Unit& u : all) {
        if (u.level > kMaxUnitLevel) return std::nullopt;
        if (!complete(u, h.dims)) {
            if (g.refinement) continue;  // a cell past the volume holds no triangles
            return std::nullopt;
        }
        h.corners(u, c);
        const int cs = cell_case(c, h.iso);
        if (cs != 0 && cs != 255) units.push_back(u);
    }
    return units;
}

template <class T>
std::optional<std::vector<std::uint8_t>> encode_typed(const Group& g, const Volume& volume,
                                                      T) {
    const VolumeView<T> view = volume.view<T>();
    const Held<VolumeView<T>> h{view, volume.dims(), g.iso};
    auto units = units_of(g, h);
    if (!units || units->empty() || units->size() > kMaxUnits) return std::nullopt;
    sort_units(*units, h.dims);
    // The mesh must be the marching cubes of these units: the same triangle count, at least.
    std::size_t triangles = 0;
    double c[8];
    for (const Unit& u : *units) {
        h.corners(u, c);
        triangles += static_cast<std::size_t>(
            mc::kTriangleCount[static_cast<std::size_t>(cell_case(c, h.iso))]);
    }
    if (triangles != g.mesh.triangle_count()) return std::nullopt;
    const VoxelBox box = box_of(*units, h.dims);
    if (box.voxels() > kMaxCellBoxVoxels) return std::nullopt;
    ByteWriter w;
    w.put(static_cast<std::uint8_t>(volume.type()));
    for (int a = 0; a < 3; ++a) w.put(static_cast<std::int32_t>(h.dims[a]));
    for (int a = 0; a < 3; ++a) w.put(volume.spacing()[a]);
    put_units(w, *units, h.dims);
    BoxVoxels<T> sent(box, h.dims, volume.spacing());
    PhaseVoxels<T> named(sent, box, nullptr);
    each_phase(h, named, *units,
               [&](const std::vector<std::uint32_t>& at) { put_values(w, sent, view, box, at); });
    return w.take();
}

template <class T>
Mesh decode_typed(ByteReader& r, glm::ivec3 dims, glm::vec3 spacing, double iso,
                  const std::vector<Unit>& units, T) {
    // Every unit's corners are voxels no other phase sends, and each voxel is a corner of at
    // most eight units: the values of at least one voxel a unit must follow.
    r.need_elements(units.size(), sizeof(T), "units' corner values");
    const VoxelBox box = box_of(units, dims);
    if (box.voxels() > kMaxCellBoxVoxels)
        r.fail("units: spread over " + std::to_string(box.voxels()) +
               " voxels, over the limit " + std::to_string(kMaxCellBoxVoxels));
    BoxVoxels<T> held(box, dims, spacing);
    const Held<BoxVoxels<T>> h{held, dims, iso};
    PhaseVoxels<T> named(held, box, &r);
    const Corners corners = each_phase(
        h, named, units,
        [&](const std::vector<std::uint32_t>& at) { get_values(r, held, box, at); });
    std::vector<int> cases(units.size());
    std::size_t triangles = 0;
    for (std::size_t i = 0; i < units.size(); ++i) {
        cases[i] = cell_case(corners[i].data(), iso);
        triangles += static_cast<std::size_t>(mc::kTriangleCount[static_cast<std::size_t>(cases[i])]);
    }
    if (triangles > kMaxGroupTriangles)
        r.fail("units: " + std::to_string(triangles) + " triangles, over the limit " +
               std::to_string(kMaxGroupTriangles));
    Mesh mesh;
    mesh.indices.reserve(3 * triangles);
    HashEdgeCache cache(dims, 2 * units.size());
    for (std::size_t i = 0; i < units.size(); ++i)
        emit_meta_cell(held, units[i].base, units[i].level, iso, cases[i], corners[i].data(), cache,
                       mesh);
    return mesh;
}

}  // namespace

std::optional<std::vector<std::uint8_t>> encode_cell_body(const Group& group,
                                                          const Volume& volume) {
    if (!std::isfinite(group.iso)) return std::nullopt;
    return dispatch_voxel_type(volume.type(),
                               [&](auto t) { return encode_typed(group, volume, t); });
}

Mesh decode_cell_body(ByteReader& r, double iso) {
    const auto type = r.get<std::uint8_t>();
    if (type > static_cast<std::uint8_t>(VoxelType::f64))
        r.fail("voxel type: expected 0.." +
               std::to_string(static_cast<int>(VoxelType::f64)) + ", got " +
               std::to_string(type));
    glm::ivec3 dims;
    for (int a = 0; a < 3; ++a) {
        dims[a] = r.get<std::int32_t>();
        if (dims[a] < 2 || dims[a] > kMaxCellVolumeSide)
            r.fail("volume dims: expected 2.." + std::to_string(kMaxCellVolumeSide) + ", got " +
                   std::to_string(dims[a]));
    }
    glm::vec3 spacing;
    for (int a = 0; a < 3; ++a) {
        spacing[a] = r.get<float>();
        if (!(spacing[a] > 0) || !std::isfinite(spacing[a]))
            r.fail("spacing: expected a positive finite number, got " +
                   std::to_string(spacing[a]));
    }
    const std::vector<Unit> units = get_units(r, dims);
    return dispatch_voxel_type(static_cast<VoxelType>(type), [&](auto t) {
        return decode_typed(r, dims, spacing, iso, units, t);
    });
}

}  // namespace isowall::remote
