#include "progressive/ray_order.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "core/pixel_rect_ops.h"

namespace isowall {

std::string_view to_string(RayOrderKind kind) {
    switch (kind) {
        case RayOrderKind::refining_grid:
            return "grid";
        case RayOrderKind::screen_readback:
            return "readback";
        case RayOrderKind::dynamic_grid:
            return "dynamic";
        case RayOrderKind::dynamic_gaps:
            return "gaps";
    }
    return "?";
}

std::optional<RayOrderKind> parse_ray_order(std::string_view name) {
    if (name == "grid" || name == "refining") return RayOrderKind::refining_grid;
    if (name == "readback") return RayOrderKind::screen_readback;
    if (name == "dynamic") return RayOrderKind::dynamic_grid;
    if (name == "gaps") return RayOrderKind::dynamic_gaps;
    return std::nullopt;
}

namespace {

bool is_dynamic(RayOrderKind kind) {
    return kind == RayOrderKind::dynamic_grid || kind == RayOrderKind::dynamic_gaps;
}

PixelRect clip_to_screen(PixelRect r, int screen_width, int screen_height) {
    const int x0 = std::max(r.x, 0), y0 = std::max(r.y, 0);
    const int x1 = std::min(r.x + r.width, screen_width);
    const int y1 = std::min(r.y + r.height, screen_height);
    if (x1 <= x0 || y1 <= y0) return {};
    return {x0, y0, x1 - x0, y1 - y0};
}

void check_mask_size(std::span<const std::uint8_t> mask, std::size_t expected) {
    if (mask.size() != expected)
        throw std::invalid_argument("ray order: mask: expected " + std::to_string(expected) +
                                    " pixels (the whole screen), got " +
                                    std::to_string(mask.size()));
}

void check_coverage_size(std::span<const std::uint8_t> covered, std::size_t expected) {
    if (covered.size() != expected)
        throw std::invalid_argument("ray order: coverage: expected " + std::to_string(expected) +
                                    " pixels (the whole screen), got " +
                                    std::to_string(covered.size()));
}

// Offsets (from the rect's start) of the cell centres of a 2^k-cell split of a side of n pixels,
// floored and with repeats dropped. floor((i + 0.5) * n / 2^k) is computed exactly in integers
// as ((2i + 1) * n) >> (k + 1); it never decreases with i, so repeats are neighbours.
std::vector<int> refining_centres(int n, int k) {
    std::vector<int> centres;
    const std::int64_t cells = std::int64_t{1} << k;
    for (std::int64_t i = 0; i < cells; ++i) {
        const int c = int(((2 * i + 1) * n) >> (k + 1));
        if (centres.empty() || centres.back() != c) centres.push_back(c);
    }
    return centres;
}

// The deepest refining level: the grid stops doubling once a cell would be smaller than 2 pixels
// on the rect's larger side (level 0, the centre, is always there).
int last_refining_level(int max_side) {
    int k = 0;
    while (std::int64_t{max_side} >= (std::int64_t{4} << k)) ++k;  // cells of level k+1 >= 2 px
    return k;
}

// The first refining level whose cells (on the larger side) are smaller than `cell_px`.
int first_level_finer_than(int max_side, double cell_px) {
    int k = 0;
    while (double(max_side) / double(std::int64_t{1} << k) >= cell_px) ++k;
    return k;
}

class ProgressiveOrder : public RayOrder {
  public:
    ProgressiveOrder(RayOrderKind kind, int screen_width, int screen_height, PixelRect rect)
        : kind_(kind),
          screen_width_(screen_width),
          screen_height_(screen_height),
          rect_(rect),
          area_(is_empty(rect) ? 0 : std::size_t(rect.width) * std::size_t(rect.height)),
          cast_(area_, false),
          max_side_(std::max(rect.width, rect.height)),
          last_refining_(area_ == 0 ? -1 : last_refining_level(max_side_)) {}

    // Masked-out pixels are cast already: no level hands them out, and done() counts them.
    void drop_masked(std::span<const std::uint8_t> mask) {
        if (mask.empty()) return;
        check_mask_size(mask, std::size_t(screen_width_) * std::size_t(screen_height_));
        for (int ly = 0; ly < rect_.height; ++ly)
            for (int lx = 0; lx < rect_.width; ++lx) {
                const std::size_t s = std::size_t(rect_.y + ly) * std::size_t(screen_width_) +
                                      std::size_t(rect_.x + lx);
                const std::size_t i = std::size_t(ly) * std::size_t(rect_.width) + std::size_t(lx);
                if (mask[s] != 0 || cast_[i]) continue;
                cast_[i] = true;
                ++cast_count_;
            }
    }

    bool next_level(std::vector<glm::ivec2>& out) override {
        out.clear();
        if (done()) return false;
        // Grid levels can come out empty after dropping cast (or, for the dynamic level,
        // covered) pixels; skip them so a level always casts something. The fill level cannot
        // be empty while pixels remain, so this ends.
        while (out.empty()) {
            if (dynamic_pending_) {
                emit_dynamic_level(out);
                dynamic_pending_ = false;
                gap_pending_ = kind_ == RayOrderKind::dynamic_gaps;
            } else if (gap_pending_) {
                gap_pending_ = false;
                if (gap_coverage_) emit_gap_level(out);
            } else if (next_refining_ <= last_refining_) {
                emit_refining_level(next_refining_++, out);
            } else {
                emit_fill_level(out);
            }
        }
        // Rays on pixels that already show the surface are the least likely to find a new
        // piece, so they wait until the end of the level (screen read-back, section 3.1.2).
        // During the dynamic grid's search nothing in the rect is covered, so this is a no-op.
        if (kind_ != RayOrderKind::refining_grid && !coverage_.empty())
            std::stable_partition(out.begin(), out.end(),
                                  [this](glm::ivec2 p) { return !is_covered(p.x, p.y); });
        ++level_;
        return true;
    }

    bool wants_coverage() const override {
        if (level_ < 0 || done()) return false;
        switch (kind_) {
            case RayOrderKind::refining_grid:
                return false;
            case RayOrderKind::screen_readback:
                return true;
            // After the surface has been sized the rest is the fixed refining order; a caster
            // may still pass coverage to put uncovered pixels first, but need not read back.
            // Before the fill level (every pixel left, most of the screen's rays) the caster
            // tells what shows once more, and again between its two parts: the fill level then
            // hands out the pixels that show nothing first (the last slivers and pinholes, which
            // decide C = 1 - E; see emit_fill_level).
            case RayOrderKind::dynamic_grid:
                return searching_ || fill_next();
            case RayOrderKind::dynamic_gaps:
                return searching_ || gap_pending_ || fill_next();
        }
        return false;
    }

    void set_coverage(std::span<const std::uint8_t> covered) override {
        check_coverage_size(covered, std::size_t(screen_width_) * std::size_t(screen_height_));
        if (kind_ == RayOrderKind::refining_grid) return;  // fixed order: nothing to adapt
        coverage_.assign(covered.begin(), covered.end());
        if (gap_pending_)  // after the sized grid: a caster that can tell what shows did
            gap_coverage_ = std::any_of(coverage_.begin(), coverage_.end(),
                                        [](std::uint8_t c) { return c != 0; });
        if (!is_dynamic(kind_) || !searching_ || level_ < 0 || done()) return;
        const double size_px = surface_piece_size(coverage_, screen_width_, rect_);
        if (size_px == 0) return;
        // The aim of the dynamic grid (section 3.1.2): one piece of surface tells roughly how
        // much screen each seed's propagation covers, so a grid at half that size lands about
        // one ray on every piece and covers the screen quickly without gaps; rays on pixels
        // already drawn would only find the same piece again, so they are left for later.
        searching_ = false;
        dynamic_pending_ = true;
        dynamic_spacing_ = std::max(2, int(std::lround(size_px / 2)));
        next_refining_ = std::max(next_refining_, first_level_finer_than(max_side_, size_px / 2));
    }

    int level() const override { return level_; }

  private:
    bool done() const { return cast_count_ == area_; }
    bool fill_next() const {
        return !dynamic_pending_ && !gap_pending_ && next_refining_ > last_refining_;
    }

    bool is_covered(int x, int y) const {
        return coverage_[std::size_t(y) * std::size_t(screen_width_) + std::size_t(x)] != 0;
    }

    // Rect-local (lx, ly): hands the pixel out unless it was cast before.
    void take(int lx, int ly, std::vector<glm::ivec2>& out) {
        const std::size_t i = std::size_t(ly) * std::size_t(rect_.width) + std::size_t(lx);
        if (cast_[i]) return;
        cast_[i] = true;
        ++cast_count_;
        out.emplace_back(rect_.x + lx, rect_.y + ly);
    }

    void emit_refining_level(int k, std::vector<glm::ivec2>& out) {
        const std::vector<int> xs = refining_centres(rect_.width, k);
        const std::vector<int> ys = refining_centres(rect_.height, k);
        for (int ly : ys)
            for (int lx : xs) take(lx, ly, out);
    }

    // Cells of dynamic_spacing_ pixels from the rect's top-left; the last cell of a row or column
    // is clipped to the rect (its centre is that of the clipped part).
    void emit_dynamic_level(std::vector<glm::ivec2>& out) {
        const int s = dynamic_spacing_;
        for (int y0 = 0; y0 < rect_.height; y0 += s) {
            const int ly = (y0 + std::min(y0 + s, rect_.height)) / 2;
            for (int x0 = 0; x0 < rect_.width; x0 += s) {
                const int lx = (x0 + std::min(x0 + s, rect_.width)) / 2;
                if (!is_covered(rect_.x + lx, rect_.y + ly)) take(lx, ly, out);
            }
        }
    }

    // Every pixel not cast yet that shows no surface after the sized grid: where a piece of the
    // surface is still missing, and the background around it. Under the strict measure (C = 1 -
    // E: C = 99% allows 0.01% of the pixels missing) the last slivers and pinholes, not the
    // pixels already drawn, decide when the picture is right, and the refining grids would reach
    // them only in their finest levels. Pixels that show the surface follow in the refining
    // grids (a nearer piece may still hide in front of them). Within the level the pixels come
    // in the refining grids' order, coarse to fine, so a gap anywhere is met early.
    void emit_gap_level(std::vector<glm::ivec2>& out) {
        for (int k = next_refining_; k <= last_refining_; ++k) {
            const std::vector<int> xs = refining_centres(rect_.width, k);
            const std::vector<int> ys = refining_centres(rect_.height, k);
            for (int ly : ys)
                for (int lx : xs)
                    if (!is_covered(rect_.x + lx, rect_.y + ly)) take(lx, ly, out);
        }
        for (int ly = 0; ly < rect_.height; ++ly)
            for (int lx = 0; lx < rect_.width; ++lx)
                if (!is_covered(rect_.x + lx, rect_.y + ly)) take(lx, ly, out);
    }

    // Every pixel not cast yet. Once a caster has told what shows (the dynamic orders ask before
    // this level), in two levels: first the pixels that showed nothing (the last holes, which
    // decide C = 1 - E), then, after the caster could seed what is still missing beside them,
    // the pixels that show the surface (a nearer piece may still hide in front of them).
    void emit_fill_level(std::vector<glm::ivec2>& out) {
        if (is_dynamic(kind_) && !fill_split_ && !coverage_.empty()) {
            fill_split_ = true;
            for (int ly = 0; ly < rect_.height; ++ly)
                for (int lx = 0; lx < rect_.width; ++lx)
                    if (!is_covered(rect_.x + lx, rect_.y + ly)) take(lx, ly, out);
            if (!out.empty()) return;
        }
        out.reserve(area_ - cast_count_);
        for (int ly = 0; ly < rect_.height; ++ly)
            for (int lx = 0; lx < rect_.width; ++lx) take(lx, ly, out);
    }

    RayOrderKind kind_;
    int screen_width_, screen_height_;
    PixelRect rect_;
    std::size_t area_;
    std::vector<bool> cast_;  // rect-local, row-major: one bit per pixel
    std::size_t cast_count_ = 0;
    int max_side_;
    int last_refining_;
    int next_refining_ = 0;
    int level_ = -1;
    std::vector<std::uint8_t> coverage_;  // the latest coverage given; empty until then
    bool searching_ = true;               // dynamic grid: no surface seen in the rect yet
    bool dynamic_pending_ = false;        // dynamic grid: the sized grid is the next level
    bool gap_pending_ = false;            // dynamic grid: the gap level is the next level
    bool gap_coverage_ = false;           // coverage after the sized grid shows something
    int dynamic_spacing_ = 0;
    bool fill_split_ = false;  // the fill level's pixels that showed nothing are handed out
};

}  // namespace

std::unique_ptr<RayOrder> make_ray_order(RayOrderKind kind, int screen_width, int screen_height,
                                         PixelRect rect, std::span<const std::uint8_t> mask) {
    screen_width = std::max(screen_width, 0);
    screen_height = std::max(screen_height, 0);
    auto order = std::make_unique<ProgressiveOrder>(
        kind, screen_width, screen_height, clip_to_screen(rect, screen_width, screen_height));
    order->drop_masked(mask);
    return order;
}

double surface_piece_size(std::span<const std::uint8_t> covered, int screen_width, PixelRect rect) {
    if (is_empty(rect)) return 0;
    const std::size_t rows_needed = std::size_t(rect.y + rect.height);
    if (rect.x < 0 || rect.y < 0 || rect.x + rect.width > screen_width ||
        covered.size() < rows_needed * std::size_t(screen_width))
        throw std::invalid_argument("surface_piece_size: rect: expected inside the " +
                                    std::to_string(screen_width) + "-pixel-wide coverage of " +
                                    std::to_string(covered.size()) + " pixels");
    const auto at = [&](int lx, int ly) {
        return covered[std::size_t(rect.y + ly) * std::size_t(screen_width) +
                       std::size_t(rect.x + lx)] != 0;
    };
    const std::size_t w = std::size_t(rect.width);
    std::size_t seed = 0, area = std::size_t(rect.width) * std::size_t(rect.height);
    while (seed < area && !at(int(seed % w), int(seed / w))) ++seed;
    if (seed == area) return 0;

    // 4-connected flood fill from the seed, kept inside the rect.
    std::vector<std::uint8_t> seen(area, 0);
    std::vector<std::size_t> stack{seed};
    seen[seed] = 1;
    std::size_t region_px = 0;
    while (!stack.empty()) {
        const std::size_t i = stack.back();
        stack.pop_back();
        ++region_px;
        const int lx = int(i % w), ly = int(i / w);
        const auto visit = [&](int nx, int ny) {
            if (nx < 0 || ny < 0 || nx >= rect.width || ny >= rect.height) return;
            const std::size_t j = std::size_t(ny) * w + std::size_t(nx);
            if (seen[j] || !at(nx, ny)) return;
            seen[j] = 1;
            stack.push_back(j);
        };
        visit(lx - 1, ly);
        visit(lx + 1, ly);
        visit(lx, ly - 1);
        visit(lx, ly + 1);
    }
    // A tiny piece (a few pixels seen at the first hit) would make a grid as fine as the fill,
    // hence the floor of 4; the rect's larger side caps it since a coarser grid adds nothing.
    const double max_side = double(std::max(rect.width, rect.height));
    return std::min(std::max(std::sqrt(double(region_px)), 4.0), max_side);
}

}  // namespace isowall
