#pragma once
// The screen-region scheduler's state (dissertation, section 5.2.2): which job each rank runs,
// pure and without messages, so the policy is tested alone. Every tile's screen is cut into
// regions; each region is two jobs, its coarse band then its fine band (see Band). A rank asks for
// work whenever it has fewer than `depth` jobs in hand and gets a coarse job if any is left
// anywhere (coarse levels over every tile come before fine levels anywhere), else a fine job:
//   - coarse: of its own tile while that holds at least half the estimated work of the busiest
//     tile, else (balancing) of the busiest tile;
//   - fine: one whose coarse band it cast itself (it holds that region's ray order and groups, so
//     nothing is cast twice) under the same rule, else (balancing) one of the busiest holder:
//     the region is cast again from its first level by the helper, whose image must show all of
//     it, so only while that holder keeps more work than the helper's whole region costs.
// Stolen jobs are taken from the end of a queue, the owner works from its front. Estimated work is
// a job's estimate (its region's work from region_plan.h, or its rays inside the volume's screen
// box for a fixed grid; 1/16 of it coarse) times the recent CPU cost per unit of estimate of its
// tile in its band.
#include <cstdint>
#include <optional>
#include <vector>

#include "core/box.h"
#include "core/camera.h"
#include "core/view.h"
#include "wall_protocol/protocol.h"

namespace isowall {

// The regions of a tile of `width` x `height` pixels, `region_w` x `region_h` each (the last row
// and column smaller), in row-major order. Sizes <= 0 or larger than the tile mean the whole tile.
std::vector<PixelRect> cut_into_regions(int width, int height, int region_w, int region_h);

// The rays each region of `view`'s screen will cast: its pixels inside the volume's screen box
// (all its pixels when `screen_box` is off, as the engine does).
std::vector<double> estimated_rays(const FrameView& view, const std::vector<PixelRect>& regions,
                                   const Box3& bounds, bool screen_box);

struct BoardJob {
    int owner = 0;
    PixelRect rect;
    Band band = Band::coarse;
    double rays = 0;  // estimated work (rays, or region_plan.h's units)
    enum class State : std::uint8_t { queued, running, done } state = State::queued;
    bool arrived = false;      // the owner has composited the helper's result (helpers only)
    int worker = -1;           // the rank it was handed to
    int holder = -1;           // the rank whose turn it is (the owner, or who cast the coarse band)
    std::uint32_t coarse = 0;  // fine jobs: the id of the region's coarse job
    double cpu = 0;            // CPU seconds it took (once done)
};

class JobBoard {
  public:
    // regions[rank] and rays[rank]: the rank's regions and the estimated work of each (rank 0,
    // the master, has none). Regions with no estimated ray get no job. pools[rank] (empty: one
    // pool): a rank takes jobs only of owners in its own pool. A stereo wall's eyes are two
    // pools: a rank's frame shares its visited cells and extraction choices between its jobs,
    // and those hold for one camera (a group extracted and culled for one eye misses triangles
    // the other sees at the silhouettes).
    JobBoard(const std::vector<std::vector<PixelRect>>& regions,
             const std::vector<std::vector<double>>& rays, bool balance, int depth = 1,
             std::vector<int> pools = {});

    // The next job for `rank`, now marked running, or nullopt when it has `depth` jobs in hand
    // or none is left for it.
    std::optional<std::uint32_t> next_for(int rank);
    // The worker finished: frees its slot and learns the CPU cost per unit of estimated work (the
    // estimate's units: rays, or region_plan.h's work). A job has landed once it is done and,
    // when a helper ran it, the owner has its result (the two messages come from different ranks,
    // so in either order).
    void done(std::uint32_t id, double cpu_s);
    void landed(std::uint32_t id);
    // `rank` is lost (master/wall_master.h): it takes no job, and any rank of its pool takes its
    // jobs when none of its own or a steal is left, balanced or not. Call before handing out.
    void orphan(int rank);

    const BoardJob& job(std::uint32_t id) const { return jobs_.at(id); }
    std::size_t size() const { return jobs_.size(); }
    bool complete() const { return landed_ == jobs_.size(); }
    bool has_landed(const BoardJob& j) const {
        return j.state == BoardJob::State::done && (j.worker == j.owner || j.arrived);
    }
    int in_hand(int rank) const { return in_hand_.at(static_cast<std::size_t>(rank)); }
    std::size_t migrated() const { return migrated_; }  // jobs run by a rank other than the owner

  private:
    // Estimated work queued and the last queued job, per key (owner or holder), in one band.
    struct Queues {
        std::vector<double> work;
        std::vector<std::optional<std::uint32_t>> last;
    };
    Queues queued(Band band, int pool) const;
    std::optional<std::uint32_t> pick(int rank) const;
    std::optional<std::uint32_t> steal(const Queues& q, Band band) const;
    double cost(const BoardJob& j) const;
    int key(const BoardJob& j) const { return j.band == Band::coarse ? j.owner : j.holder; }

    std::vector<BoardJob> jobs_;
    bool balance_;
    int depth_;
    std::vector<int> in_hand_;
    std::vector<int> pools_;          // by rank
    std::vector<bool> orphans_;       // by rank: lost, its jobs anyone's
    std::vector<double> cpu_, rays_;  // by owner and band (2 * owner + band): of the jobs done
    std::size_t landed_ = 0, migrated_ = 0;
};

}  // namespace isowall
