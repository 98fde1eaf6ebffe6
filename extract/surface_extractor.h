#pragma once
// One volume with its octree, behind a voxel-type-free interface: the per-type cores (RayCaster,
// Propagator, extract_full) are instantiated once per voxel type in surface_extractor.cpp, so
// callers (the progressive engine, the CLI, the wall) are not templates. Inside, an extractor is
// shared read-only data, one frame state and per-thread workers (surface_extractor.cpp).
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>

#include "core/thread_budget.h"
#include "core/view.h"
#include "extract/adaptive.h"
#include "extract/extract.h"
#include "extract/group.h"
#include "extract/propagator.h"
#include "extract/raycaster.h"
#include "volume/active_nodes.h"
#include "volume/volume.h"

namespace isowall {

class SurfaceExtractor {
  public:
    virtual ~SurfaceExtractor() = default;

    virtual const Volume& volume() const = 0;
    // The range of the finite voxels (NaN and infinity left out): the isovalues worth asking for.
    virtual double value_min() const = 0;
    virtual double value_max() const = 0;
    virtual const OctreeShape& octree_shape() const = 0;
    virtual std::size_t octree_bytes() const = 0;
    // The workers this extractor holds: its thread budget. The calls below run on the first;
    // their *_on forms run on worker `w` in [0, threads()), and different workers may run them
    // at once within one frame (never begin_frame, mark_taken or share).
    virtual int threads() const = 0;
    // The active octree nodes at `iso` of the finest level, not below `finest_level`, that has at
    // most `max_boxes` of them (active_nodes.h), as object-space boxes: where the surface may be.
    virtual ActiveBoxes active_boxes(double iso, std::size_t max_boxes, int finest_level) const = 0;

    // Starts a frame at `iso` at full resolution: forgets every visited cell.
    void begin_frame(double iso) { begin_frame(iso, ResolutionLevels{}); }
    // Starts a frame at `iso` with the view's D[] (adaptive resolution, chapter 2.1.3): from now on
    // cast() may hit meta-cells and propagate() runs at the level of its seed's unit.
    // With levels.error_px finite, the first such frame builds (or maps from the cache) the
    // volume's meta-cell errors, unless prepare_lod_errors() did.
    virtual void begin_frame(double iso, const ResolutionLevels& levels) = 0;
    // The meta-cell errors of the error rule (volume/lod_error.h), built or mapped now if
    // not yet: a caller that times its frames calls this first, outside the clock.
    virtual const LodTable& prepare_lod_errors() const = 0;
    virtual double iso() const = 0;

    // `ray` in object space; t is returned in the ray's own parameter.
    RayHit cast(const Ray& ray, IntersectMode mode,
                float t_max = std::numeric_limits<float>::max()) {
        return cast_on(0, ray, mode, t_max);
    }
    virtual RayHit cast_on(int w, const Ray& ray, IntersectMode mode, float t_max) = 0;
    virtual bool visited(glm::ivec3 cell) const = 0;
    virtual std::uint32_t group_of(glm::ivec3 cell) = 0;
    virtual std::size_t visited_count() const = 0;
    // A propagation pass from `seed` (must be active) for the seed ray `ray` (object space).
    Group propagate(glm::ivec3 seed, std::uint32_t group_id, const PropagationParams& p,
                    const Ray& ray, const std::function<bool()>& interrupted = {}) {
        return propagate_on(0, seed, group_id, p, ray, interrupted);
    }
    virtual Group propagate_on(int w, glm::ivec3 seed, std::uint32_t group_id,
                               const PropagationParams& p, const Ray& ray,
                               const std::function<bool()>& interrupted) = 0;
    // The refinement group of the meta-cell of `level` at `unit` (a RayHit with refine set), or an
    // empty group (no triangles) when this frame refined it already.
    Group refine(glm::ivec3 unit, int level, std::uint32_t group_id, const PropagationParams& p) {
        return refine_on(0, unit, level, group_id, p);
    }
    virtual Group refine_on(int w, glm::ivec3 unit, int level, std::uint32_t group_id,
                            const PropagationParams& p) = 0;
    // Seconds of the last propagate() or refine() spent in marching cubes (the "extraction" stage).
    double last_extract_s() const { return last_extract_s_on(0); }
    virtual double last_extract_s_on(int w) const = 0;
    // Every triangle of the surface at `iso` (the oracle; does not touch visited cells).
    virtual Mesh extract_full(double iso, ExtractStats* stats = nullptr) const = 0;
    // What a frame of `view` must end up showing: extract_full at view.iso, cut by view.clip.
    Mesh full_surface(const FrameView& view, ExtractStats* stats = nullptr) const;

    // Marks the unit of `level` at `base` (its first cell) as taken by `group_id` in this frame,
    // as a propagation pass would have: a frame that goes on from groups a client already holds
    // (cached primitives, the dissertation's section 4.1.4). False when a cell of it was taken.
    virtual bool mark_taken(glm::ivec3 base, int level, std::uint32_t group_id) = 0;

    // Another extractor of the same volume and octree (shared, read-only, never copied) with a
    // frame state and workers of its own: one per client of a server, or per level of detail.
    // This extractor must outlive the new one.
    virtual std::unique_ptr<SurfaceExtractor> share() const = 0;
};

// Builds (or maps from the cache) the octree of `volume`, which must outlive the extractor.
// `budget` is the rank's: the octree build runs on its threads and the extractor holds one worker
// per thread. Without one, the build takes every core (ThreadBudget::hardware()) and there is one
// worker.
std::unique_ptr<SurfaceExtractor> make_surface_extractor(
    const Volume& volume, const OctreeSource& source = {}, OctreeStats* stats = nullptr,
    std::optional<ThreadBudget> budget = std::nullopt);

}  // namespace isowall
