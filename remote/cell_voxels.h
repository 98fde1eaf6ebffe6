#pragma once
// The voxels of a `cells` group (remote/cell_codec.h) on either side: the sparse store the client
// triangulates from, which voxels each of the three phases names, and how their values travel
// (remote/cell_values.h). Templates over the voxel type, so the server's encoder and the
// client's decoder run the same code; internal to the codec.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "extract/marching_cubes.h"
#include "extract/mc_tables.h"
#include "remote/byte_io.h"
#include "remote/cell_units.h"

namespace isowall::remote::cells {

// through at() alone; a voxel never named reads as 0, and marching cubes reads only named ones).
// Both sides fill it as values are sent, in the same order, and predict each from those known.
template <class T>
class BoxVoxels {
  public:
    static constexpr int kLog2 = 2;
    static constexpr int kSide = 1 << kLog2;
    static constexpr std::size_t kBrick = kSide * kSide * kSide;

    BoxVoxels(const VoxelBox& box, glm::ivec3 volume_dims, glm::vec3 spacing_)
        : dims(volume_dims),
          spacing(spacing_),
          origin_(box.origin),
          size_(box.size),
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
// client (`r` set) the voxels named in all must stay within `max_named`, what the bytes received
// can hold values for (remote/cell_values.h), checked as each is named, so the bricks held stay
// within 64 voxels of that.
template <class T>
class PhaseVoxels {
  public:
    PhaseVoxels(BoxVoxels<T>& held, const VoxelBox& box, const ByteReader* r = nullptr,
                std::uint64_t max_named = 0)
        : held_(held), box_(box), r_(r), max_named_(max_named) {}
    void add(glm::ivec3 p) {
        if (!held_.name(p)) return;
        fresh_.push_back(static_cast<std::uint32_t>(linear(p - box_.origin, box_.size)));
        if (r_ && ++named_ > max_named_)
            r_->fail("voxel values: more voxels named than the bytes of values can hold (" +
                     std::to_string(max_named_) + ")");
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
    std::uint64_t max_named_, named_ = 0;
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

inline bool crossed(const std::array<double, 8>& c, int e, double iso) {
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

// The three phases in order (the third only with `gradients`), naming voxels in `named`; `take`
// is called with each phase's voxels (box indices) once the earlier phases' values are in place
// (the client reads them there). Returns each unit's corner values.
template <class View, class T, class Take>
Corners each_phase(const Held<View>& h, PhaseVoxels<T>& named, const std::vector<Unit>& units,
                   bool gradients, Take&& take) {
    phase_corners(units, named);
    take(named.take());
    Corners corners(units.size());
    for (std::size_t i = 0; i < units.size(); ++i) h.corners(units[i], corners[i].data());
    phase_edges(h, units, corners, named);
    take(named.take());
    if (!gradients) return corners;  // the normals travel as such (cell_codec.h)
    phase_gradients(h, units, corners, named);
    take(named.take());
    return corners;
}

}  // namespace isowall::remote::cells
