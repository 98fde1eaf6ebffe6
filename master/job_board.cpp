#include "master/job_board.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "core/ray.h"

namespace isowall {

std::vector<PixelRect> cut_into_regions(int width, int height, int region_w, int region_h) {
    if (region_w <= 0 || region_w > width) region_w = width;
    if (region_h <= 0 || region_h > height) region_h = height;
    std::vector<PixelRect> out;
    for (int y = 0; y < height; y += region_h)
        for (int x = 0; x < width; x += region_w)
            out.push_back({x, y, std::min(region_w, width - x), std::min(region_h, height - y)});
    return out;
}

std::vector<double> estimated_rays(const FrameView& view, const std::vector<PixelRect>& regions,
                                   const Box3& bounds, bool screen_box) {
    const PixelRect box = screen_box ? isowall::screen_box(bounds, view.camera.view(), view.frustum,
                                                           view.width, view.height)
                                     : view.screen();
    std::vector<double> out;
    for (const PixelRect& r : regions) {
        const int w = std::min(r.x + r.width, box.x + box.width) - std::max(r.x, box.x);
        const int h = std::min(r.y + r.height, box.y + box.height) - std::max(r.y, box.y);
        out.push_back(w > 0 && h > 0 ? double(w) * double(h) : 0.0);
    }
    return out;
}

namespace {
constexpr double kCoarseShare = 1.0 / 16.0;  // the coarse band ends after ~1/16 of the rays
}

JobBoard::JobBoard(const std::vector<std::vector<PixelRect>>& regions,
                   const std::vector<std::vector<double>>& rays, bool balance, int depth,
                   std::vector<int> pools)
    : balance_(balance),
      depth_(depth),
      in_hand_(regions.size(), 0),
      pools_(pools.empty() ? std::vector<int>(regions.size(), 0) : std::move(pools)),
      orphans_(regions.size(), false),
      cpu_(2 * regions.size(), 0.0),
      rays_(2 * regions.size(), 0.0) {
    if (pools_.size() != regions.size())
        throw std::invalid_argument("job board: a pool for every rank, or none");
    for (std::size_t owner = 0; owner < regions.size(); ++owner) {
        for (std::size_t i = 0; i < regions[owner].size(); ++i) {
            const double r = rays.at(owner).at(i);
            if (r <= 0) continue;
            BoardJob coarse;
            coarse.owner = static_cast<int>(owner);
            coarse.rect = regions[owner][i];
            coarse.holder = coarse.owner;
            coarse.rays = r * kCoarseShare;
            BoardJob fine = coarse;
            fine.band = Band::fine;
            fine.rays = r - coarse.rays;
            fine.coarse = static_cast<std::uint32_t>(jobs_.size());
            jobs_.push_back(coarse);
            jobs_.push_back(fine);  // always right after its coarse job
        }
    }
}

// The recent cost per ray of the job's tile in its band (coarse rays find the seeds and pay for
// most extraction, fine rays mostly meet visited cells); else of the band wall-wide; else of any.
double JobBoard::cost(const BoardJob& j) const {
    const std::size_t b = j.band == Band::coarse ? 0 : 1;
    const std::size_t k = 2 * static_cast<std::size_t>(j.owner) + b;
    if (rays_[k] > 0) return j.rays * cpu_[k] / rays_[k];
    double cpu = 0, rays = 0, cpu_any = 0, rays_any = 0;
    for (std::size_t i = 0; i < cpu_.size(); ++i) {
        if (i % 2 == b) cpu += cpu_[i], rays += rays_[i];
        cpu_any += cpu_[i], rays_any += rays_[i];
    }
    if (rays > 0) return j.rays * cpu / rays;
    return j.rays * (rays_any > 0 ? cpu_any / rays_any : 1e-6);
}

JobBoard::Queues JobBoard::queued(Band band, int pool) const {
    Queues q{std::vector<double>(in_hand_.size(), 0.0),
             std::vector<std::optional<std::uint32_t>>(in_hand_.size())};
    for (std::uint32_t id = 0; id < jobs_.size(); ++id) {
        const BoardJob& j = jobs_[id];
        if (j.state != BoardJob::State::queued || j.band != band) continue;
        if (pools_[static_cast<std::size_t>(j.owner)] != pool) continue;
        const auto k = static_cast<std::size_t>(key(j));
        q.work[k] += cost(j);
        q.last[k] = id;
    }
    return q;
}

std::optional<std::uint32_t> JobBoard::steal(const Queues& q, Band band) const {
    const auto most =
        static_cast<std::size_t>(std::max_element(q.work.begin(), q.work.end()) - q.work.begin());
    if (!q.last[most] || band == Band::coarse) return q.last[most];
    // A stolen fine band is cast again from the region's first level, so the helper pays for its
    // coarse band too: worth it only while the holder keeps at least that much work of its own.
    const BoardJob& j = jobs_[*q.last[most]];
    const BoardJob& coarse = jobs_[j.coarse];
    const double again = (coarse.state == BoardJob::State::done ? coarse.cpu : cost(coarse));
    if (q.work[most] - cost(j) < again + cost(j)) return std::nullopt;
    return q.last[most];
}

std::optional<std::uint32_t> JobBoard::pick(int rank) const {
    auto first = [&](Band band) -> std::optional<std::uint32_t> {
        for (std::uint32_t id = 0; id < jobs_.size(); ++id) {
            const BoardJob& j = jobs_[id];
            if (j.state == BoardJob::State::queued && j.band == band && key(j) == rank) return id;
        }
        return std::nullopt;
    };
    const auto r = static_cast<std::size_t>(rank);
    for (const Band band : {Band::coarse, Band::fine}) {
        if (!balance_) {
            if (auto id = first(band)) return id;
            continue;
        }
        // A rank keeps to its own queue while it holds at least half the work of the busiest
        // one; else it helps there first (its own cheap jobs wait, and anyone may take them).
        const Queues q = queued(band, pools_[r]);
        const double most = *std::max_element(q.work.begin(), q.work.end());
        if (q.last[r] && q.work[r] >= 0.5 * most)
            if (auto id = first(band)) return id;
        if (auto id = steal(q, band)) return id;
        if (auto id = first(band)) return id;
    }
    // A lost rank's jobs: whoever of its pool asks.
    for (const Band band : {Band::coarse, Band::fine})
        for (std::uint32_t id = 0; id < jobs_.size(); ++id) {
            const BoardJob& j = jobs_[id];
            const auto k = static_cast<std::size_t>(key(j));
            if (j.state == BoardJob::State::queued && j.band == band && orphans_[k] &&
                pools_[static_cast<std::size_t>(j.owner)] == pools_[r])
                return id;
        }
    return std::nullopt;
}

void JobBoard::orphan(int rank) {
    orphans_.at(static_cast<std::size_t>(rank)) = true;
}

std::optional<std::uint32_t> JobBoard::next_for(int rank) {
    if (rank < 0 || static_cast<std::size_t>(rank) >= in_hand_.size())
        throw std::out_of_range("job board: no rank " + std::to_string(rank));
    if (in_hand_[static_cast<std::size_t>(rank)] >= depth_) return std::nullopt;
    const auto id = pick(rank);
    if (!id) return std::nullopt;
    BoardJob& j = jobs_[*id];
    j.state = BoardJob::State::running;
    j.worker = rank;
    if (rank != j.owner) ++migrated_;
    if (j.band == Band::coarse) jobs_[*id + 1].holder = rank;  // its fine band follows it
    ++in_hand_[static_cast<std::size_t>(rank)];
    return id;
}

void JobBoard::done(std::uint32_t id, double cpu_s) {
    BoardJob& j = jobs_.at(id);
    if (j.state != BoardJob::State::running)
        throw std::runtime_error("job " + std::to_string(id) + " reported done but not running");
    j.state = BoardJob::State::done;
    --in_hand_[static_cast<std::size_t>(j.worker)];
    j.cpu = cpu_s;
    // A fine band cast by a rank other than its holder cast the coarse band again: its cost is not
    // what a fine band costs, and counting it would make fine bands look worth stealing.
    if (j.band == Band::coarse || j.worker == j.holder) {
        const std::size_t k =
            2 * static_cast<std::size_t>(j.owner) + (j.band == Band::coarse ? 0 : 1);
        cpu_[k] += cpu_s;
        rays_[k] += j.rays;  // the estimate: what cost() scales
    }
    if (has_landed(j)) ++landed_;
}

void JobBoard::landed(std::uint32_t id) {
    BoardJob& j = jobs_.at(id);
    if (j.state == BoardJob::State::queued || j.worker == j.owner || j.arrived)
        throw std::runtime_error("job " + std::to_string(id) +
                                 " reported landed but no helper's result was due");
    j.arrived = true;
    if (has_landed(j)) ++landed_;
}

}  // namespace isowall
