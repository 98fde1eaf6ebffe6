#include "cli/engine_cli.h"

#include <limits>

#include <glm/trigonometric.hpp>

#include "cli/cli_checks.h"
#include "core/error.h"

namespace isowall {

void add_engine_options(CLI::App& app, EngineCli& e) {
    app.add_option("--order", e.order,
                   "Ray order: grid (fixed refining grids), readback "
                   "(screen read-back), dynamic (dynamic grid) or gaps (the dynamic grid, then "
                   "every pixel still empty, then the refining grids)")
        ->check(CLI::IsMember({"grid", "refining", "readback", "dynamic", "gaps"}))
        ->capture_default_str();
    app.add_option("--intersect", e.intersect,
                   "exact (Moller-Trumbore on the cell's triangles) or approximate (first active "
                   "cell, then an exact second pass)")
        ->check(CLI::IsMember({"exact", "approximate"}))
        ->capture_default_str();
    app.add_option("--propagation", e.propagation,
                   "count (at most --max-count cells per seed) or angle (--cutoff-angle with "
                   "fold-back test)")
        ->check(CLI::IsMember({"count", "angle"}))
        ->capture_default_str();
    app.add_option("--max-count", e.max_count, "Cells per propagation pass (count mode)")
        ->transform(number_in(limits::kCellCount))
        ->capture_default_str();
    app.add_option("--cutoff-angle", e.cutoff_deg, "Cut-off angle in degrees (angle mode)")
        ->transform(number_in(limits::kCutoffDeg))
        ->capture_default_str();
    app.add_option("--foldback-tolerance", e.foldback_deg,
                   "Fold-back tolerance in degrees (angle mode)")
        ->transform(number_in(limits::kFoldbackDeg))
        ->capture_default_str();
    app.add_flag("--no-interpolant-cache", e.no_interpolant_cache,
                 "Do not share vertices between cells of a group");
    app.add_flag("--facing-only", e.facing_only,
                 "Visible-surface rule: a propagation pass does not go on from a cell where the "
                 "surface faces away from the eye (later rays seed what it leaves out)");
    app.add_flag("--no-screen-box", e.no_screen_box,
                 "Cast rays over the whole screen, not only the volume's projected box (turns "
                 "the screen mask off too: it lies within the box)");
    app.add_flag("--no-screen-mask", e.no_screen_mask,
                 "Cast every ray of the volume's projected box, also where no active octree node "
                 "projects (the box alone, to measure what the mask saves)");
    app.add_flag("--every-triangle", e.every_triangle,
                 "Make and draw every triangle of the surface the engine visits, also those that "
                 "cover no pixel centre (which change no pixel; by default they are neither made "
                 "nor drawn): for studies of what leaving them out saves");
    app.add_option("--footprint-pixels", e.footprint_pixels,
                   "Where cells project below a pixel, propagate over meta-cells that project "
                   "below this many pixels and draw, for each pixel centre one covers, the "
                   "full-resolution surface its ray meets there (the picture of every triangle, "
                   "at a cost that follows the pixels); 0: every cell at full resolution. Not "
                   "with --adaptive or --every-triangle")
        ->transform(number_in(limits::kFootprintPixels))
        ->capture_default_str();
    app.add_flag("--no-frontier-seeds", e.no_frontier_seeds,
                 "Do not seed, before the ray order's fill level, the units full propagation "
                 "passes left out and the cells beside missed hits whose pixels still show "
                 "nothing (the text's passes alone: only rays find what a pass stopped short of)");
    app.add_flag("--adaptive", e.adaptive,
                 "Adaptive resolution: extract regions whose cells project below a pixel as "
                 "meta-cells of 2^i cells per side");
    app.add_option("--adaptive-max-level", e.adaptive_max_level,
                   "Largest meta-cell level i with --adaptive")
        ->transform(number_in({1, double(kMaxMetaLevel), false, true}))
        ->capture_default_str();
    app.add_option("--adaptive-pixels", e.adaptive_pixels,
                   "With --adaptive: take a meta-cell where it projects below this many pixels "
                   "(1: the text's rule; 2: triangles of about a pixel, for volumes finer than "
                   "the screen)")
        ->transform(number_in(limits::kMetaCellPixels))
        ->capture_default_str();
    app.add_option("--adaptive-error", e.adaptive_error,
                   "With --adaptive: also take a meta-cell only where its surface lies within this "
                   "many pixels of the full-resolution surface, projected (a bound computed once "
                   "per volume, cached beside the octree; off by default: the size rule alone)")
        ->transform(number_in(limits::kMetaCellPixels));
    app.add_flag("--no-adaptive-refine", e.no_adaptive_refine,
                 "With --adaptive: never draw a meta-cell again at full resolution where a ray "
                 "sees the fine surface its triangles miss (the text's distance rule alone)");
}

EngineOptions to_engine_options(const EngineCli& c) {
    if (c.max_count < 1)
        throw InputError("--max-count", "value",
                         "expected a positive cell count, got " + std::to_string(c.max_count));
    if (c.adaptive_max_level < 1 || c.adaptive_max_level > kMaxMetaLevel)
        throw InputError("--adaptive-max-level", "value",
                         "expected 1 to " + std::to_string(kMaxMetaLevel) + ", got " +
                             std::to_string(c.adaptive_max_level));
    EngineOptions e;
    const auto order = parse_ray_order(c.order);
    if (!order)
        throw InputError("--order", "value",
                         "expected grid, readback, dynamic or gaps, got " + quote(c.order));
    e.order = *order;
    e.intersect = c.intersect == "approximate" ? IntersectMode::approximate : IntersectMode::exact;
    e.propagation.mode =
        c.propagation == "angle" ? PropagationMode::cutoff_angle : PropagationMode::max_count;
    e.propagation.max_count = c.max_count;
    e.propagation.cutoff_rad = glm::radians(c.cutoff_deg);
    e.propagation.foldback_rad = glm::radians(c.foldback_deg);
    e.propagation.interpolant_cache = !c.no_interpolant_cache;
    e.propagation.facing_only = c.facing_only;
    e.screen_box = !c.no_screen_box;
    e.screen_mask = !c.no_screen_mask;
    e.frontier_seeds = !c.no_frontier_seeds;
    e.sampled_triangles = !c.every_triangle;
    e.footprint_pixels = c.footprint_pixels;
    e.adaptive = c.adaptive;
    e.adaptive_max_level = c.adaptive_max_level;
    e.adaptive_pixels = c.adaptive_pixels;
    e.adaptive_refine = !c.no_adaptive_refine;
    e.adaptive_error_px = c.adaptive_error.value_or(std::numeric_limits<float>::infinity());
    return e;
}

}  // namespace isowall
