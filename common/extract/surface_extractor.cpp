#include "common/extract/surface_extractor.h"

namespace isowall {
namespace {

template <class T>
class TypedExtractor final : public SurfaceExtractor {
public:
    TypedExtractor(const Volume& volume, const OctreeSource& source, OctreeStats* stats)
        : volume_(volume),
          view_(volume.view<T>()),
          octree_(MinMaxOctree<T>::load_or_build(view_, source, stats)),
          caster_(view_, octree_),
          propagator_(view_),
          visited_(view_.cell_dims()) {}

    const Volume& volume() const override { return volume_; }
    double value_min() const override { return static_cast<double>(octree_.value_min()); }
    double value_max() const override { return static_cast<double>(octree_.value_max()); }
    const OctreeShape& octree_shape() const override { return octree_.shape(); }
    std::size_t octree_bytes() const override { return octree_.bytes(); }

    using SurfaceExtractor::begin_frame;
    void begin_frame(double iso, const ResolutionLevels& levels) override {
        iso_ = iso;
        visited_.reset(view_.cell_dims());
        refined_.reset(64);
        const ResolutionMap resolution(levels, view_.spacing, view_.cell_dims());
        caster_.set_resolution(resolution);
        propagator_.set_resolution(resolution);
    }
    double iso() const override { return iso_; }

    RayHit cast(const Ray& ray, IntersectMode mode, float t_max) override {
        return caster_.cast(to_voxel_space(ray, view_.spacing), iso_, mode, t_max);
    }
    bool visited(glm::ivec3 cell) const override { return visited_.contains(cell); }
    std::uint32_t group_of(glm::ivec3 cell) override { return visited_.group_of(cell); }
    std::size_t visited_count() const override { return visited_.size(); }

    Group propagate(glm::ivec3 seed, std::uint32_t group_id, const PropagationParams& p,
                    const Ray& ray, const std::function<bool()>& interrupted) override {
        const Ray vr = to_voxel_space(ray, view_.spacing);
        Group g = propagator_.propagate(seed, group_id, iso_, p, vr.o, vr.d, visited_, interrupted);
        extract_s_ = propagator_.last_extract_s();
        return g;
    }

    Group refine(glm::ivec3 unit, int level, std::uint32_t group_id,
                 const PropagationParams& p) override {
        extract_s_ = 0;
        if (!refined_.find_or_insert(visited_.index(unit)).second) {
            Group none;
            none.id = group_id;
            none.refinement = true;
            return none;
        }
        Group g = propagator_.refine(unit, level, group_id, iso_, p);
        extract_s_ = propagator_.last_extract_s();
        return g;
    }

    double last_extract_s() const override { return extract_s_; }

    Mesh extract_full(double iso, ExtractStats* stats) const override {
        return isowall::extract_full(view_, octree_, iso, stats);
    }

private:
    const Volume& volume_;
    VolumeView<T> view_;
    MinMaxOctree<T> octree_;
    RayCaster<T> caster_;
    Propagator<T> propagator_;
    VisitedCells visited_;
    EdgeVertexCache refined_;  // first cells of the meta-cells refined this frame
    double iso_ = 0;
    double extract_s_ = 0;
};

}  // namespace

std::unique_ptr<SurfaceExtractor> make_surface_extractor(const Volume& volume,
                                                         const OctreeSource& source,
                                                         OctreeStats* stats) {
    return dispatch_voxel_type(volume.type(), [&](auto tag) -> std::unique_ptr<SurfaceExtractor> {
        return std::make_unique<TypedExtractor<decltype(tag)>>(volume, source, stats);
    });
}

}  // namespace isowall
