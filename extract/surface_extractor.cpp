// SurfaceExtractor for each voxel type.
//
// The three parts of an extractor, split by who may touch them once several threads
// extract side by side (STYLE.md, "Threads"):
//   ExtractionData<T>  shared, read-only after construction: the volume view and its octree.
//                      Any number of workers read it at once without a lock.
//   FrameState         per frame: the isovalue, the resolution, the visited cells and the
//                      meta-cells refined this frame. One per extractor, reset by begin(), and
//                      the one part the frame's workers write together (see the race below).
//   ExtractWorker<T>   per thread: a ray caster and a propagator with their scratch (interpolant
//                      cache, BFS queue, triangles under test) and the last-extract figure.
//                      Never shared, so its statistics need no lock either (Embree's per-thread
//                      g_stats); they are merged where they are read.
//
// Workers of one frame run side by side (the engine's --threads): each unit is claimed by a
// compare-and-swap in VisitedCells::insert, so exactly one pass takes it, and a meta-cell's
// refinement is claimed under FrameState's lock. Everything else a worker writes is its own.
#include "extract/surface_extractor.h"

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include "core/error.h"
#include "core/ray.h"
#include "core/thread_budget.h"
#include "extract/adaptive.h"
#include "extract/edge_cache.h"
#include "extract/group.h"
#include "extract/propagator.h"
#include "extract/raycaster.h"
#include "extract/visited.h"
#include "volume/lod_error.h"
#include "volume/octree.h"
#include "volume/surface_bricks.h"
#include "volume/volume.h"

namespace isowall {
namespace {

template <class T>
struct ExtractionData {
    // Builds the octree over `build` threads, or maps it from the cache.
    // The cache key covers every file the volume was read from, and a volume without one
    // finite voxel has no isovalue to offer: an error naming the file.
    ExtractionData(const Volume& v, const OctreeSource& source, OctreeStats* stats,
                   ThreadBudget build)
        : volume(v),
          view(v.view<T>()),
          octree(MinMaxOctree<T>::load_or_build(view, with_files(source, v), stats, build)) {
        if (!octree.finite_range().any)
            throw InputError(v.source(), "data",
                             "no finite voxel (every voxel is NaN or infinite)");
        lod_source_ = with_files(source, v);
        lod_budget_ = build;
    }
    // The meta-cell errors of the error rule (lod_error.h): built (or mapped from the cache) on
    // first use only, since only a frame that asks for the rule needs them; any thread may ask.
    const LodTable& lod_table() const {
        std::call_once(lod_once_,
                       [this] { lod_ = load_or_build_lod(view, lod_source_, lod_budget_); });
        return lod_;
    }
    // Workers hold references to the view and the octree, so the data never moves.
    ExtractionData(const ExtractionData&) = delete;
    ExtractionData& operator=(const ExtractionData&) = delete;

    const Volume& volume;
    const VolumeView<T> view;
    const MinMaxOctree<T> octree;

  private:
    OctreeSource lod_source_;
    ThreadBudget lod_budget_;
    mutable std::once_flag lod_once_;
    mutable LodTable lod_;

    static OctreeSource with_files(OctreeSource s, const Volume& v) {
        for (const auto& f : v.files())
            if (f != s.volume_path) s.data_files.push_back(f);
        if (!v.own_octree().empty()) {
            s.own_file = v.own_octree();
            s.content_key = v.content_key();
        }
        return s;
    }
};

static_assert(VisitedCells::kLevels == kMaxMetaLevel + 1);

struct FrameState {
    explicit FrameState(glm::ivec3 cell_dims) : visited(cell_dims) {}

    // Starts a frame at `frame_iso`: forgets every visited cell and refinement.
    void begin(double frame_iso, const ResolutionMap& map, glm::ivec3 cell_dims) {
        iso = frame_iso;
        resolution = map;
        visited.reset(cell_dims, resolution.max_level());
        refined.reset(64);
    }
    // True when the meta-cell whose first cell is `unit` was not refined yet this frame; from
    // now on it is.
    bool claim_refinement(glm::ivec3 unit) {
        const std::lock_guard<std::mutex> lock(refined_lock);
        return refined.find_or_insert(visited.index(unit)).second;
    }
    // Whether the unit (cell or meta-cell) that holds `cell` this frame was taken, and by whom.
    bool unit_taken(glm::ivec3 cell) const {
        const int level = resolution.level_of(cell);
        return visited.contains(cell & ~((1 << level) - 1), level);
    }
    std::uint32_t unit_group(glm::ivec3 cell) const {
        const int level = resolution.level_of(cell);
        return visited.group_of(cell & ~((1 << level) - 1), level);
    }

    double iso = 0;
    ResolutionMap resolution;  // default-constructed: full resolution
    VisitedCells visited;
    EdgeVertexCache refined{64};  // first cells of the meta-cells refined this frame
    std::mutex refined_lock;      // workers claim refinements side by side
};

template <class T>
class alignas(64) ExtractWorker {  // cache lines of its own: a worker's state is hot per ray
  public:
    explicit ExtractWorker(const ExtractionData<T>& data)
        : data_(data), caster_(data.view, data.octree), propagator_(data.view) {}

    // Takes the frame's resolution; a copy per worker, so the hot paths read no shared state.
    void begin_frame(const FrameState& frame) {
        // Footprint units show the full-resolution surface, which rays then find cell by cell.
        caster_.set_resolution(frame.resolution.footprint() ? ResolutionMap{} : frame.resolution);
        propagator_.set_resolution(frame.resolution);
    }

    // `ray` in object space; t is returned in the ray's own parameter.
    RayHit cast(const FrameState& frame, const Ray& ray, IntersectMode mode, float t_max) {
        return caster_.cast(to_voxel_space(ray, data_.view.spacing), frame.iso, mode, t_max);
    }

    Group propagate(FrameState& frame, glm::ivec3 seed, std::uint32_t group_id,
                    const PropagationParams& p, const Ray& ray,
                    const std::function<bool()>& interrupted) {
        const Ray vr = to_voxel_space(ray, data_.view.spacing);
        Group g = propagator_.propagate(seed, group_id, frame.iso, p, vr.o, vr.d, frame.visited,
                                        interrupted);
        extract_s_ = propagator_.last_extract_s();
        return g;
    }

    // An empty group (no triangles) when this frame refined the meta-cell already.
    Group refine(FrameState& frame, glm::ivec3 unit, int level, std::uint32_t group_id,
                 const PropagationParams& p) {
        extract_s_ = 0;
        if (!frame.claim_refinement(unit)) {
            Group none;
            none.id = group_id;
            none.seed = unit;
            none.level = level;
            none.iso = frame.iso;
            none.refinement = true;
            return none;
        }
        Group g = propagator_.refine(unit, level, group_id, frame.iso, p);
        extract_s_ = propagator_.last_extract_s();
        return g;
    }

    // Seconds of this worker's last propagate() or refine() spent in marching cubes.
    double last_extract_s() const { return extract_s_; }

  private:
    const ExtractionData<T>& data_;
    RayCaster<T> caster_;
    Propagator<T> propagator_;
    double extract_s_ = 0;
};

// One data, one frame state and a worker per thread of the budget. Every call of the
// single-threaded interface runs on the first worker; the others wait for a threaded caller.
template <class T>
class TypedExtractor final : public SurfaceExtractor {
  public:
    TypedExtractor(const Volume& volume, const OctreeSource& source, OctreeStats* stats,
                   int workers, ThreadBudget build)
        : TypedExtractor(std::make_shared<const ExtractionData<T>>(volume, source, stats, build),
                         workers) {}

    TypedExtractor(std::shared_ptr<const ExtractionData<T>> data, int workers)
        : data_holder_(std::move(data)), data_(*data_holder_), frame_(data_.view.cell_dims()) {
        // Reserved once and never resized: workers are not moved while the frame runs.
        workers_.reserve(static_cast<std::size_t>(workers));
        for (int i = 0; i < workers; ++i) workers_.emplace_back(data_);
    }

    const Volume& volume() const override { return data_.volume; }
    double value_min() const override { return data_.octree.finite_range().min; }
    double value_max() const override { return data_.octree.finite_range().max; }
    const OctreeShape& octree_shape() const override { return data_.octree.shape(); }
    std::size_t octree_bytes() const override { return data_.octree.bytes(); }
    int threads() const override { return static_cast<int>(workers_.size()); }
    ActiveBoxes active_boxes(double iso, std::size_t max_boxes, int finest_level) const override {
        const ActiveNodes a = active_nodes(data_.octree, iso, max_boxes, finest_level);
        return to_boxes(data_.octree.shape(), a, data_.view.spacing);
    }

    using SurfaceExtractor::begin_frame;
    void begin_frame(double iso, const ResolutionLevels& levels) override {
        const glm::ivec3 cells = data_.view.cell_dims();
        const LodErrors* errors =
            std::isfinite(levels.error_px) ? &data_.lod_table().errors : nullptr;
        frame_.begin(iso, ResolutionMap(levels, data_.view.spacing, cells, errors), cells);
        for (ExtractWorker<T>& w : workers_) w.begin_frame(frame_);
        const Volume& v = data_.volume;
        if (v.wants_brick_hint() && iso != hinted_iso_) {
            v.hint_bricks(surface_bricks(data_.octree, v.bricks(), v.brick_grid(), iso));
            hinted_iso_ = iso;
        }
    }
    double iso() const override { return frame_.iso; }
    const LodTable& prepare_lod_errors() const override { return data_.lod_table(); }

    RayHit cast_on(int w, const Ray& ray, IntersectMode mode, float t_max) override {
        return worker(w).cast(frame_, ray, mode, t_max);
    }
    bool visited(glm::ivec3 cell) const override { return frame_.unit_taken(cell); }
    std::uint32_t group_of(glm::ivec3 cell) override { return frame_.unit_group(cell); }
    std::size_t visited_count() const override { return frame_.visited.size(); }

    Group propagate_on(int w, glm::ivec3 seed, std::uint32_t group_id, const PropagationParams& p,
                       const Ray& ray, const std::function<bool()>& interrupted) override {
        return worker(w).propagate(frame_, seed, group_id, p, ray, interrupted);
    }

    Group refine_on(int w, glm::ivec3 unit, int level, std::uint32_t group_id,
                    const PropagationParams& p) override {
        return worker(w).refine(frame_, unit, level, group_id, p);
    }

    double last_extract_s_on(int w) const override {
        return workers_.at(static_cast<std::size_t>(w)).last_extract_s();
    }

    Mesh extract_full(double iso, ExtractStats* stats) const override {
        return isowall::extract_full(data_.view, data_.octree, iso, stats);
    }

    bool mark_taken(glm::ivec3 base, int level, std::uint32_t group_id) override {
        return Propagator<T>::insert(frame_.visited, base, level, group_id);
    }

    std::unique_ptr<SurfaceExtractor> share() const override {
        return std::make_unique<TypedExtractor<T>>(data_holder_, threads());
    }

  private:
    ExtractWorker<T>& worker(int w) { return workers_.at(static_cast<std::size_t>(w)); }

    std::shared_ptr<const ExtractionData<T>> data_holder_;
    const ExtractionData<T>& data_;
    FrameState frame_;
    std::vector<ExtractWorker<T>> workers_;  // at least one
    double hinted_iso_ = std::nan("");       // the isovalue a paged volume was last hinted at
};

}  // namespace

std::unique_ptr<SurfaceExtractor> make_surface_extractor(const Volume& volume,
                                                         const OctreeSource& source,
                                                         OctreeStats* stats,
                                                         std::optional<ThreadBudget> budget) {
    const int workers = budget ? budget->usable() : 1;
    const ThreadBudget build = budget ? *budget : ThreadBudget::hardware();
    return dispatch_voxel_type(volume.type(), [&](auto tag) -> std::unique_ptr<SurfaceExtractor> {
        return std::make_unique<TypedExtractor<decltype(tag)>>(volume, source, stats, workers,
                                                               build);
    });
}

Mesh SurfaceExtractor::full_surface(const FrameView& view, ExtractStats* stats) const {
    Mesh mesh = extract_full(view.iso, stats);
    clip_mesh(mesh, in_object_space(view.clip, volume().spacing()));
    return mesh;
}

}  // namespace isowall
