#pragma once
// The voxel values of a `cells` group (remote/cell_codec.h) on either side: each predicted from
// the voxels both sides already know, the residual coded by its context. Internal to the codec.
//
// Integer voxels go as the difference to a prediction (at 1 voxel, the mean of each axis's
// estimate, axis_estimate; else the mean of the known face neighbours at 2, else 4 voxels; else
// the value sent just before), taken modulo 2^bits and zigzagged so small ones of either sign are
// small numbers (the prediction: cell_predict.h). The residual's bit length goes through a binary
// tree of adaptive probabilities (remote/range_coder.h), one tree for each context: the phase that
// names the voxel, how far the known neighbours at 1 voxel disagree (or how few there are), and how
// far the prediction lies from the isovalue (voxels near the surface vary more). The two bits below
// the leading one are adaptive too, the rest go at one bit each. On one frame's groups
// (isowall_bench_codec's), this took the values from zstd on byte planes (what went before) to
// about 10% fewer bytes on cthead at 600 and the 256 head at 40; most of it is the adaptive coding
// of the bit length, a fifth the contexts. The models start afresh in each group, so a group
// decodes alone; a few contexts learn faster than many (3 x 10 x 4 here against 3 x 32 x 16: 2%
// fewer bytes on cthead).
//
// Floating-point voxels go as they are, as byte planes (zstd may pack the body outside,
// group_codec.h).
//
// Byte layout after the units' boxes: the value step's shift u8 (Bins: 0, or 2 and up on a coarse
// pass of integer voxels), the stream's length u32 and the range coder's stream (the units' bits,
// then integer values), then floating-point values as planes, phase by phase (every value's low
// byte, then the next, ...).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "remote/byte_io.h"
#include "remote/cell_exact.h"
#include "remote/cell_predict.h"
#include "remote/cell_voxels.h"
#include "remote/range_coder.h"

namespace isowall::remote::cells {

// Classes of the prediction's distance to the isovalue: its bit width / 4, capped.
inline constexpr int kDistanceClasses = 4;
// Phases: the units' corners, the inner voxels of long edges, the gradients' neighbours.
inline constexpr int kValuePhases = 3;
// Each value codes at least four decisions (its bit length's tree, 4 levels for 8-bit voxels),
// each at least 0.022 bits (range_coder.h): at most 91 values a byte of stream. A stream that
// names more than this many voxels a byte is forged.
inline constexpr std::uint64_t kMaxValuesPerByte = 128;

// The adaptive probabilities of one group's integer residuals.
template <class T>
class ValueModel {
  public:
    using R = Residual<T>;
    static constexpr int kBits = 8 * sizeof(T);
    // Bit lengths 0..kBits: a tree of 4 levels for 8 bits, 5 for 16, 6 for 32.
    static constexpr int kTreeBits = std::bit_width(static_cast<unsigned>(kBits));
    static constexpr bool kIntegral = std::is_integral_v<T>;

    // Floating-point voxels go as planes: their model holds nothing.
    explicit ValueModel(double iso)
        : iso_(iso),
          tree_(kIntegral
                    ? std::size_t{kValuePhases * kSpreadClasses * kDistanceClasses} << kTreeBits
                    : 0),
          first_(kIntegral ? kValuePhases * (kBits + 1) : 0),
          second_(kIntegral ? 2 * kValuePhases * (kBits + 1) : 0) {}

    void put(RangeEncoder& e, int phase, const Prediction<T>& p, R r) {
        const int width = static_cast<int>(std::bit_width(r));
        BitProbability* tree = &tree_[context(phase, p) << kTreeBits];
        unsigned node = 1;
        for (int i = kTreeBits - 1; i >= 0; --i) {
            const unsigned b = static_cast<unsigned>(width >> i) & 1u;
            e.bit(tree[node], b);
            node = 2 * node + b;
        }
        if (width < 2) return;  // 0 and 1 are their bit lengths
        const std::size_t at = static_cast<std::size_t>(phase * (kBits + 1) + width);
        const unsigned b1 = static_cast<unsigned>(r >> (width - 2)) & 1u;
        e.bit(first_[at], b1);
        if (width < 3) return;
        e.bit(second_[2 * at + b1], static_cast<unsigned>(r >> (width - 3)) & 1u);
        e.direct(static_cast<std::uint32_t>(r & ((R{1} << (width - 3)) - 1)), width - 3);
    }
    // nullopt: a bit length past the voxel type's (a forged stream).
    std::optional<R> get(RangeDecoder& d, int phase, const Prediction<T>& p) {
        BitProbability* tree = &tree_[context(phase, p) << kTreeBits];
        unsigned node = 1;
        for (int i = 0; i < kTreeBits; ++i) node = 2 * node + d.bit(tree[node]);
        const int width = static_cast<int>(node - (1u << kTreeBits));
        if (width > kBits) return std::nullopt;
        if (width < 2) return static_cast<R>(width);
        const std::size_t at = static_cast<std::size_t>(phase * (kBits + 1) + width);
        const unsigned b1 = d.bit(first_[at]);
        R r = static_cast<R>(2 | b1);
        if (width < 3) return r;
        r = static_cast<R>(r << 1 | d.bit(second_[2 * at + b1]));
        if (width > 3) r = static_cast<R>(static_cast<R>(r << (width - 3)) | d.direct(width - 3));
        return r;
    }

  private:
    std::size_t context(int phase, const Prediction<T>& p) const {
        const double off = std::abs(static_cast<double>(p.value) - iso_);
        const std::uint64_t whole = off < 0x1p62 ? static_cast<std::uint64_t>(off) : ~0ull;
        const int distance =
            std::min(static_cast<int>(std::bit_width(whole)) >> 2, kDistanceClasses - 1);
        return static_cast<std::size_t>((phase * kSpreadClasses + p.spread) * kDistanceClasses +
                                        distance);
    }
    double iso_;
    std::vector<BitProbability> tree_, first_, second_;
};

inline std::uint64_t zigzag(std::int64_t d) {
    return static_cast<std::uint64_t>(d) << 1 ^ static_cast<std::uint64_t>(d >> 63);
}
inline std::int64_t unzigzag(std::uint64_t z) {
    return static_cast<std::int64_t>(z >> 1) ^ -static_cast<std::int64_t>(z & 1);
}

// The server's side: each phase's values as each_phase names them, then finish().
template <class T>
class ValueWriter {
  public:
    // `shift`: the step (Bins) of the phases from `first_stepped` on, 0 for exact values; integer
    // voxels only. `exact`, if given, takes each stepped value's offset in its bin (cell_exact.h).
    // The units' bits are in `coder` already (cell_units.h).
    ValueWriter(ByteWriter& w, RangeEncoder& coder, double iso, int shift, int first_stepped = 0,
                ExactBitsWriter* exact = nullptr)
        : w_(w),
          coder_(coder),
          model_(iso),
          bins_{iso, shift},
          first_stepped_(first_stepped),
          exact_(exact) {
        w_.put(static_cast<std::uint8_t>(shift));
    }
    void phase(BoxVoxels<T>& held, const VolumeView<T>& v, const VoxelBox& box,
               const std::vector<std::uint32_t>& at) {
        std::vector<T> planes;
        T previous{};
        for (const std::uint32_t i : at) {
            const glm::ivec3 p = box.origin + unlinear(i, box.size);
            const T value = v.at(p.x, p.y, p.z);
            const Prediction<T> guess = predict(held, p, previous);
            T kept = value;
            if constexpr (!std::is_integral_v<T>) {
                planes.push_back(value);
            } else if (bins_.shift == 0 || phase_ < first_stepped_) {
                model_.put(coder_, phase_, guess, residual(value, guess.value));
            } else {
                const std::int64_t k = bins_.of(value);
                model_.put(coder_, phase_, guess,
                           static_cast<Residual<T>>(zigzag(k - bins_.of(guess.value))));
                kept = bins_.middle(k);
                if (exact_)
                    exact_->put(
                        static_cast<std::uint64_t>(static_cast<std::int64_t>(value) - bins_.low(k)),
                        bins_.shift);
            }
            held.set(p, kept);
            previous = kept;
        }
        ++phase_;
        if constexpr (!std::is_integral_v<T>) put_planes(planes);
    }
    // The stream's length and the stream, then floating-point values' planes.
    void finish() {
        const std::vector<std::uint8_t> stream = coder_.finish();
        w_.put(static_cast<std::uint32_t>(stream.size()));
        w_.put_raw(std::span<const std::uint8_t>(stream));
        w_.put_raw(std::span<const std::uint8_t>(planes_));
    }

  private:
    void put_planes(const std::vector<T>& values) {
        for (std::size_t b = 0; b < sizeof(T); ++b)
            for (std::size_t i = 0; i < values.size(); ++i)
                planes_.push_back(reinterpret_cast<const std::uint8_t*>(&values[i])[b]);
    }
    ByteWriter& w_;
    RangeEncoder& coder_;
    ValueModel<T> model_;
    Bins<T> bins_;
    int first_stepped_;
    ExactBitsWriter* exact_;
    std::vector<std::uint8_t> planes_;
    int phase_ = 0;
};

// The client's side: constructed where the values begin (after the units), it reads phase by
// phase into `held`; finish() checks the stream was whole.
template <class T>
class ValueReader {
  public:
    // `first_stepped`: the first phase the body's step applies to (as the writer's);
    // `undoable`: whether exact offsets may follow for its stepped values (apply_exact).
    ValueReader(ByteReader& r, double iso, int first_stepped, bool undoable)
        : r_(r),
          model_(iso),
          bins_{iso, r.get<std::uint8_t>()},
          first_stepped_(first_stepped),
          undoable_(undoable),
          coder_(std::span<const std::uint8_t>{}) {
        const int most = std::is_integral_v<T> ? 8 * static_cast<int>(sizeof(T)) - 2 : 0;
        if (bins_.shift == 1 || bins_.shift > most)
            r.fail("value step: expected 0" +
                   (most >= 2 ? " or 2.." + std::to_string(most) : std::string()) + ", got " +
                   std::to_string(bins_.shift));
        stream_bytes_ = r.get<std::uint32_t>();
        coder_ = RangeDecoder(r.get_span(stream_bytes_));
        if constexpr (std::is_integral_v<T>)
            max_named_ = kMaxValuesPerByte * stream_bytes_;
        else
            max_named_ = r.remaining() / sizeof(T);
    }
    // The units' bits come first in the stream (cell_units.h).
    RangeDecoder& coder() { return coder_; }
    std::uint64_t stream_bytes() const { return stream_bytes_; }
    // The most voxels the values received can name.
    std::uint64_t max_named() const { return max_named_; }
    void phase(BoxVoxels<T>& held, const VoxelBox& box, const std::vector<std::uint32_t>& at) {
        std::vector<T> values;
        if constexpr (!std::is_integral_v<T>) values = get_planes(at.size());
        T previous{};
        for (std::size_t k = 0; k < at.size(); ++k) {
            const glm::ivec3 p = box.origin + unlinear(at[k], box.size);
            const Prediction<T> guess = predict(held, p, previous);
            T value;
            if constexpr (std::is_integral_v<T>) {
                const auto got = model_.get(coder_, phase_, guess);
                if (!got) r_.fail("voxel values: a residual longer than the voxel type");
                if (bins_.shift == 0 || phase_ < first_stepped_) {
                    value = from_residual(*got, guess.value);
                } else {
                    value = bins_.middle(bins_.of(guess.value) + unzigzag(*got));
                    if (undoable_) stepped_.push_back(p);
                }
            } else {
                value = values[k];
            }
            held.set(p, value);
            previous = value;
        }
        ++phase_;
        if (coder_.overrun() > 0) r_.fail("voxel values: the coded stream is cut short");
    }
    void finish() const {
        if (!coder_.at_end()) r_.fail("voxel values: the coded stream does not end there");
    }
    // Whether values went to a step that exact offsets undo (an undoable body's).
    bool stepped() const { return !stepped_.empty(); }
    // How many bytes the exact offsets of the stepped values take (undoable bodies).
    std::size_t exact_bytes() const {
        return (stepped_.size() * static_cast<std::size_t>(bins_.shift) + 7) / 8;
    }
    // Puts every stepped value back at its exact value: its bin's least integer plus its offset
    // from `exact` (cell_exact.h; WireError for bits that do not fit the values, or a value past
    // T).
    void apply_exact(BoxVoxels<T>& held, std::span<const std::uint8_t> exact) const {
        if constexpr (std::is_integral_v<T>) {
            if (const std::string p = exact_bits_problem(exact, stepped_.size(), bins_.shift);
                !p.empty())
                r_.fail("exact values: " + p);
            ExactBitsReader bits(exact);
            for (const glm::ivec3 p : stepped_) {
                const std::int64_t k = bins_.of(held.at(p.x, p.y, p.z));
                const std::int64_t v =
                    bins_.low(k) + static_cast<std::int64_t>(bits.get(bins_.shift));
                if (v < static_cast<std::int64_t>(std::numeric_limits<T>::lowest()) ||
                    v > static_cast<std::int64_t>(std::numeric_limits<T>::max()))
                    r_.fail("exact values: a value past the voxel type");
                held.set(p, static_cast<T>(v));
            }
        }
    }

  private:
    std::vector<T> get_planes(std::size_t n) {
        r_.need_elements(n, sizeof(T), "voxel values");
        std::vector<T> values(n);
        for (std::size_t b = 0; b < sizeof(T); ++b) {
            const auto plane = r_.get_span(n);
            for (std::size_t i = 0; i < n; ++i)
                reinterpret_cast<std::uint8_t*>(&values[i])[b] = plane[i];
        }
        return values;
    }
    ByteReader& r_;
    ValueModel<T> model_;
    Bins<T> bins_;
    int first_stepped_;
    bool undoable_;
    std::vector<glm::ivec3> stepped_;  // undoable: where values went to the step, in their order
    RangeDecoder coder_;
    std::uint64_t max_named_ = 0, stream_bytes_ = 0;
    int phase_ = 0;
};

}  // namespace isowall::remote::cells
