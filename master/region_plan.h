#pragma once
// Regions from the work: at its defaults the screen-region scheduler cuts each tile
// where the work is, not on a grid of one size. A tile's work is estimated on a grid of cells:
//   - every frame: the active octree nodes at the isovalue (what the engine's screen mask casts
//     into) projected through the tile's view, each adding the pixels it covers to the cells it
//     overlaps (ray-box pairs: the surface's depth complexity on screen);
//   - from the second frame on: scaled, cell by cell, by how much more or less than estimated the
//     region holding the cell cost in the last frame (frame coherence, as Equalizer's load
//     equalizer uses the last frame's measured split costs).
// A tile is then cut by a k-d split at the work median of its longer side until each region holds
// at most a target share of the wall's work: small regions where the surface is dense, one large
// one where the screen is empty. All pure: tested without MPI or GL.
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/box.h"
#include "core/camera.h"
#include "core/view.h"
#include "master/job_board.h"

namespace isowall {

// A tile's estimated work on a grid of kCell x kCell pixel cells (the last row and column
// smaller), in arbitrary units: only ratios matter.
struct WorkMap {
    static constexpr int kCell = 16;
    int width = 0, height = 0;  // the tile's pixels
    int cols = 0, rows = 0;
    std::vector<double> work;  // per cell, row-major

    WorkMap() = default;
    WorkMap(int width, int height);
    double& at(int col, int row) { return work[static_cast<std::size_t>(row * cols + col)]; }
    double at(int col, int row) const { return work[static_cast<std::size_t>(row * cols + col)]; }
    // The cells [c0, c1) x [r0, r1) whose top-left pixel lies in `r`.
    struct Cells {
        int c0, r0, c1, r1;
    };
    Cells cells_in(const PixelRect& r) const;
    // The work of those cells.
    double sum(const PixelRect& r) const;
    double total() const;
};

// The first estimate: each box (object space) seen through `view` and `frustum` on a width x
// height screen adds, to every cell, the pixels of the cell its projected rectangle covers.
WorkMap projected_work(std::span<const Box3> boxes, const glm::mat4& view, const Frustum& frustum,
                       int width, int height);

// A region of the last frame: the work estimated for it and the CPU seconds it took.
struct RegionCost {
    PixelRect rect;
    double estimated = 0, measured = 0;
};

// `map` with each cell scaled by its last-frame region's measured / estimated cost relative to
// `wall_ratio` (the whole wall's measured / estimated), clamped to [1/8, 8]: cells no measured
// region holds keep their estimate.
WorkMap corrected(WorkMap map, std::span<const RegionCost> last, double wall_ratio);

// How many regions a worker rank gets, on average, at the wall's estimated work: enough that the
// last job of a busy tile is short against the frame, few enough that each job's fixed cost (a
// renderer flush, a read-back, a message) stays small.
inline constexpr double kRegionsPerRank = 8;
// How many active nodes the work estimate projects: the screen mask's budget (a few thousand
// boxes project in well under a millisecond per tile).
inline constexpr std::size_t kWorkBoxes = 4096;
// The smallest region side, in cells (32 pixels).
inline constexpr int kMinRegionCells = 2;

// The regions of one tile, in row-major order of their top-left corners: a k-d split at the work
// median of the longer side, on cell boundaries, until a region's work is at most `target` or
// it is too small to split. A tile with no estimated work is one region.
std::vector<PixelRect> plan_regions(const WorkMap& map, double target);

// The target work of a region: the wall's estimated work over kRegionsPerRank per worker rank.
inline double region_target(double wall_work, int workers) {
    return wall_work / (kRegionsPerRank * (workers > 0 ? workers : 1));
}

// What a pixel inside the volume's screen box that no active node covers costs, in the units of
// projected_work (one ray meeting one node's box): a region holding only such pixels still gets
// its job, the cheapest of all.
inline constexpr double kEmptyPixelWork = 1e-3;

// Every tile's regions and their estimated work for one frame (the job board's input).
struct FramePlan {
    std::vector<std::vector<PixelRect>> regions;  // by rank; [0], the master, has none
    std::vector<std::vector<double>> work;
    // Each region's estimate before the last frame's costs corrected it: what its measured cost
    // is set against in the next frame (set against `work`, a correction that was right would
    // read as none, and the frame after would undo it).
    std::vector<std::vector<double>> base;
};

// The plan of a frame seen through views[rank] (width 0: not a tile rank), with the active
// nodes `boxes` (or the volume's box alone, as a uniform estimate over the screen box) and, by
// rank, the last frame's region costs (may be empty). A region outside the volume's screen box
// (with `screen_box`, as the engine clips) gets zero work: no job.
FramePlan plan_frame(std::span<const FrameView> views, std::span<const Box3> boxes,
                     std::span<const std::vector<RegionCost>> last, const Box3& bounds,
                     bool screen_box);

// The plan of a fixed grid of region_w x region_h regions (0 x 0: one region per tile), each
// estimated by its rays inside the volume's screen box: the static wall, and `--region WxH`.
FramePlan grid_plan(std::span<const FrameView> views, int region_w, int region_h,
                    const Box3& bounds, bool screen_box);

// The regions of `board`'s frame whose coarse and fine jobs are both done, by owner rank, with
// their estimated work and the CPU they took (a fine band a helper cast again from the first
// level holds the whole region's cost). With `plan`, the plan the board was made from, a region's
// estimate is its uncorrected one (FramePlan::base).
std::vector<std::vector<RegionCost>> region_costs(const JobBoard& board, std::size_t ranks,
                                                  const FramePlan* plan = nullptr);

// The master's plans across frames: it keeps the costs of the last frame that measured any region
// and the work boxes of the current isovalue (asked of `boxes` once per isovalue; unset, the
// volume's box alone).
class RegionPlanner {
  public:
    explicit RegionPlanner(std::function<std::vector<Box3>(double iso)> boxes = {})
        : boxes_of_(std::move(boxes)) {}
    // The plan of a new frame at `iso`; `previous` is the board of the frame it replaces (null
    // for the first), whose measured regions then correct the estimate.
    FramePlan next(std::span<const FrameView> views, double iso, const JobBoard* previous,
                   const Box3& bounds, bool screen_box);

  private:
    std::function<std::vector<Box3>(double)> boxes_of_;
    std::optional<double> boxes_iso_;
    std::vector<Box3> boxes_;
    std::vector<std::vector<RegionCost>> last_;
    FramePlan planned_;  // the plan of the frame `previous` will be the board of
};

}  // namespace isowall
