#include "master/region_plan.h"

#include <algorithm>
#include <cmath>

#include "core/ray.h"

namespace isowall {

WorkMap::WorkMap(int w, int h)
    : width(std::max(w, 0)),
      height(std::max(h, 0)),
      cols((width + kCell - 1) / kCell),
      rows((height + kCell - 1) / kCell),
      work(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows), 0.0) {}

WorkMap::Cells WorkMap::cells_in(const PixelRect& r) const {
    return {std::max(0, (r.x + kCell - 1) / kCell), std::max(0, (r.y + kCell - 1) / kCell),
            std::min(cols, (r.x + r.width + kCell - 1) / kCell),
            std::min(rows, (r.y + r.height + kCell - 1) / kCell)};
}

double WorkMap::sum(const PixelRect& r) const {
    const Cells c = cells_in(r);
    double s = 0;
    for (int y = c.r0; y < c.r1; ++y)
        for (int x = c.c0; x < c.c1; ++x) s += at(x, y);
    return s;
}

double WorkMap::total() const {
    double s = 0;
    for (double w : work) s += w;
    return s;
}

WorkMap projected_work(std::span<const Box3> boxes, const glm::mat4& view, const Frustum& frustum,
                       int width, int height) {
    WorkMap m(width, height);
    constexpr int C = WorkMap::kCell;
    for (const Box3& b : boxes) {
        const PixelRect p = screen_box(b, view, frustum, width, height);
        if (p.width <= 0 || p.height <= 0) continue;
        for (int row = p.y / C; row * C < p.y + p.height; ++row) {
            const int h = std::min(p.y + p.height, (row + 1) * C) - std::max(p.y, row * C);
            for (int col = p.x / C; col * C < p.x + p.width; ++col) {
                const int w = std::min(p.x + p.width, (col + 1) * C) - std::max(p.x, col * C);
                m.at(col, row) += double(w) * double(h);
            }
        }
    }
    return m;
}

WorkMap corrected(WorkMap map, std::span<const RegionCost> last, double wall_ratio) {
    if (!(wall_ratio > 0) || !std::isfinite(wall_ratio)) return map;
    for (const RegionCost& r : last) {
        if (!(r.estimated > 0) || !(r.measured > 0)) continue;
        const double f = std::clamp(r.measured / r.estimated / wall_ratio, 0.125, 8.0);
        const WorkMap::Cells c = map.cells_in(r.rect);
        for (int row = c.r0; row < c.r1; ++row)
            for (int col = c.c0; col < c.c1; ++col) map.at(col, row) *= f;
    }
    return map;
}

namespace {

// The k-d split over cells [c0, c1) x [r0, r1), with a summed-area table for the work of any
// block of cells.
class Splitter {
  public:
    Splitter(const WorkMap& m, double target) : m_(m), target_(target) {
        const auto w = static_cast<std::size_t>(m.cols + 1);
        sat_.assign(w * static_cast<std::size_t>(m.rows + 1), 0.0);
        for (int y = 0; y < m.rows; ++y)
            for (int x = 0; x < m.cols; ++x)
                sat_[idx(x + 1, y + 1)] =
                    m.at(x, y) + sat_[idx(x, y + 1)] + sat_[idx(x + 1, y)] - sat_[idx(x, y)];
    }

    void split(int c0, int r0, int c1, int r1, std::vector<PixelRect>& out) const {
        const double w = work(c0, r0, c1, r1);
        const bool can_x = c1 - c0 >= 2 * kMinRegionCells, can_y = r1 - r0 >= 2 * kMinRegionCells;
        if (w <= target_ || (!can_x && !can_y)) {
            out.push_back(pixels(c0, r0, c1, r1));
            return;
        }
        // An empty margin at least kMinRegionCells wide is cut off first, as a region of its own:
        // the regions that hold the work then hold little empty screen, which a helper would
        // otherwise render, read back and send for nothing.
        if (cut_margin(c0, r0, c1, r1, out)) return;
        // The longer side in pixels (the cells are square), or the only one that can be split.
        const bool along_x = can_x && (!can_y || c1 - c0 >= r1 - r0);
        const int lo = (along_x ? c0 : r0) + kMinRegionCells;
        const int hi = (along_x ? c1 : r1) - kMinRegionCells;
        int best = lo;
        double best_gap = -1;
        for (int k = lo; k <= hi; ++k) {
            const double left = along_x ? work(c0, r0, k, r1) : work(c0, r0, c1, k);
            const double gap = std::abs(2 * left - w);
            if (best_gap < 0 || gap < best_gap) best = k, best_gap = gap;
        }
        if (along_x) {
            split(c0, r0, best, r1, out);
            split(best, r0, c1, r1, out);
        } else {
            split(c0, r0, c1, best, out);
            split(c0, best, c1, r1, out);
        }
    }

  private:
    // Cuts off one empty margin of [c0, c1) x [r0, r1) (left, right, top, bottom, the first wide
    // enough) and splits the rest; false when none is.
    bool cut_margin(int c0, int r0, int c1, int r1, std::vector<PixelRect>& out) const {
        int l = c0, r = c1, t = r0, b = r1;
        while (l < c1 && work(l, r0, l + 1, r1) <= 0) ++l;
        while (r > l && work(r - 1, r0, r, r1) <= 0) --r;
        while (t < r1 && work(c0, t, c1, t + 1) <= 0) ++t;
        while (b > t && work(c0, b - 1, c1, b) <= 0) --b;
        if (l - c0 >= kMinRegionCells) {
            out.push_back(pixels(c0, r0, l, r1));
            split(l, r0, c1, r1, out);
        } else if (c1 - r >= kMinRegionCells) {
            out.push_back(pixels(r, r0, c1, r1));
            split(c0, r0, r, r1, out);
        } else if (t - r0 >= kMinRegionCells) {
            out.push_back(pixels(c0, r0, c1, t));
            split(c0, t, c1, r1, out);
        } else if (r1 - b >= kMinRegionCells) {
            out.push_back(pixels(c0, b, c1, r1));
            split(c0, r0, c1, b, out);
        } else {
            return false;
        }
        return true;
    }

    std::size_t idx(int x, int y) const {
        return static_cast<std::size_t>(y) * static_cast<std::size_t>(m_.cols + 1) +
               static_cast<std::size_t>(x);
    }
    double work(int c0, int r0, int c1, int r1) const {
        return sat_[idx(c1, r1)] - sat_[idx(c0, r1)] - sat_[idx(c1, r0)] + sat_[idx(c0, r0)];
    }
    PixelRect pixels(int c0, int r0, int c1, int r1) const {
        constexpr int C = WorkMap::kCell;
        return {c0 * C, r0 * C, std::min(m_.width, c1 * C) - c0 * C,
                std::min(m_.height, r1 * C) - r0 * C};
    }

    const WorkMap& m_;
    double target_;
    std::vector<double> sat_;
};

}  // namespace

std::vector<PixelRect> plan_regions(const WorkMap& map, double target) {
    std::vector<PixelRect> out;
    if (map.cols == 0 || map.rows == 0) return out;
    if (!(target > 0)) target = map.total();  // nothing to balance: one region
    Splitter(map, target).split(0, 0, map.cols, map.rows, out);
    std::sort(out.begin(), out.end(), [](const PixelRect& a, const PixelRect& b) {
        return a.y != b.y ? a.y < b.y : a.x < b.x;
    });
    return out;
}

FramePlan plan_frame(std::span<const FrameView> views, std::span<const Box3> boxes,
                     std::span<const std::vector<RegionCost>> last, const Box3& bounds,
                     bool screen_box) {
    const std::span<const Box3> uniform(&bounds, 1);
    if (boxes.empty()) boxes = uniform;
    double measured = 0, estimated = 0;
    for (const auto& tile : last)
        for (const RegionCost& r : tile)
            if (r.estimated > 0 && r.measured > 0) measured += r.measured, estimated += r.estimated;
    const double wall_ratio = estimated > 0 ? measured / estimated : 0;
    std::vector<WorkMap> base(views.size()), maps(views.size());
    double total = 0;
    int workers = 0;
    for (std::size_t k = 0; k < views.size(); ++k) {
        const FrameView& v = views[k];
        if (v.width <= 0 || v.height <= 0) continue;
        ++workers;
        base[k] = projected_work(boxes, v.camera.view(), v.frustum, v.width, v.height);
        maps[k] = k < last.size() ? corrected(base[k], last[k], wall_ratio) : base[k];
        total += maps[k].total();
    }
    const double target = region_target(total, workers);
    FramePlan p;
    p.regions.resize(views.size());
    p.work.resize(views.size());
    p.base.resize(views.size());
    for (std::size_t k = 0; k < views.size(); ++k) {
        if (maps[k].cols == 0) continue;
        p.regions[k] = plan_regions(maps[k], target);
        const std::vector<double> px = estimated_rays(views[k], p.regions[k], bounds, screen_box);
        for (std::size_t i = 0; i < px.size(); ++i) {
            const double empty = kEmptyPixelWork * px[i];
            p.work[k].push_back(px[i] > 0 ? maps[k].sum(p.regions[k][i]) + empty : 0.0);
            p.base[k].push_back(px[i] > 0 ? base[k].sum(p.regions[k][i]) + empty : 0.0);
        }
    }
    return p;
}

FramePlan grid_plan(std::span<const FrameView> views, int region_w, int region_h,
                    const Box3& bounds, bool screen_box) {
    FramePlan p;
    p.regions.resize(views.size());
    p.work.resize(views.size());
    for (std::size_t k = 0; k < views.size(); ++k) {
        if (views[k].width <= 0 || views[k].height <= 0) continue;
        p.regions[k] = cut_into_regions(views[k].width, views[k].height, region_w, region_h);
        p.work[k] = estimated_rays(views[k], p.regions[k], bounds, screen_box);
    }
    return p;
}

namespace {

// The uncorrected estimate of `owner`'s region `rect` in `plan`, or -1 when it has none.
double base_estimate(const FramePlan& plan, std::size_t owner, const PixelRect& rect) {
    if (owner >= plan.regions.size() || owner >= plan.base.size()) return -1;
    const auto& regions = plan.regions[owner];
    for (std::size_t i = 0; i < regions.size() && i < plan.base[owner].size(); ++i)
        if (regions[i].x == rect.x && regions[i].y == rect.y && regions[i].width == rect.width &&
            regions[i].height == rect.height)
            return plan.base[owner][i];
    return -1;
}

}  // namespace

std::vector<std::vector<RegionCost>> region_costs(const JobBoard& board, std::size_t ranks,
                                                  const FramePlan* plan) {
    std::vector<std::vector<RegionCost>> out(ranks);
    for (std::uint32_t id = 0; id + 1 < board.size(); ++id) {
        const BoardJob& coarse = board.job(id);
        if (coarse.band != Band::coarse) continue;
        const BoardJob& fine = board.job(id + 1);  // always right after its coarse job
        if (coarse.state != BoardJob::State::done || fine.state != BoardJob::State::done) continue;
        const auto owner = static_cast<std::size_t>(coarse.owner);
        if (owner >= ranks) continue;
        const double cpu = fine.worker == fine.holder ? coarse.cpu + fine.cpu : fine.cpu;
        const double estimated =
            plan ? base_estimate(*plan, owner, coarse.rect) : coarse.rays + fine.rays;
        if (estimated > 0) out[owner].push_back({coarse.rect, estimated, cpu});
    }
    return out;
}

FramePlan RegionPlanner::next(std::span<const FrameView> views, double iso,
                              const JobBoard* previous, const Box3& bounds, bool screen_box) {
    if (previous) {
        auto costs = region_costs(*previous, views.size(), &planned_);
        if (std::any_of(costs.begin(), costs.end(), [](const auto& c) { return !c.empty(); }))
            last_ = std::move(costs);
    }
    if (boxes_of_ && boxes_iso_ != iso) {
        boxes_ = boxes_of_(iso);
        boxes_iso_ = iso;
    }
    planned_ = plan_frame(views, boxes_, last_, bounds, screen_box);
    return planned_;
}

}  // namespace isowall
