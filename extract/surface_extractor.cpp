#include "extract/surface_extractor.h"

#include <cmath>
#include <memory>
#include <vector>

#include "extract/extractor_parts.h"
#include "volume/surface_bricks.h"

namespace isowall {
namespace {

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

}  // namespace isowall
