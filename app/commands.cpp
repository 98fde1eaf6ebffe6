#include "app/commands.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "app/render_report.h"
#include "app/surfaces_frame.h"
#include "app/whole_frame.h"
#include "cli/cli_checks.h"
#include "cli/iso_option.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/util.h"
#include "engine/progressive_engine.h"
#include "extract/surface_extractor.h"
#include "files/image_io.h"
#include "files/mesh_formats.h"
#include "master/legend.h"
#include "readers/voxel_ops.h"
#include "render/renderer.h"
#include "volume/phantom.h"

namespace isowall {
namespace {

std::unique_ptr<SurfaceExtractor> prepare(const OpenedVolume& ov, Timings& t,
                                          ThreadBudget budget = ThreadBudget::hardware()) {
    OctreeSource src;
    if (ov.file) src.volume_path = *ov.file;
    src.cache_dir = ov.cache_dir;
    OctreeStats st;
    Stopwatch sw;
    auto ex = make_surface_extractor(ov.volume, src, &st, budget);
    t.octree = sw.seconds();
    const double share = double(ex->octree_bytes()) / double(ov.volume.bytes().size());
    if (st.from_cache) {
        std::printf("octree: mapped %s  (%.3f s)\n", st.cache_file.c_str(), t.octree);
    } else {
        std::printf("octree: built in %.3f s (%.0f M voxels/s)%s%s\n", st.build_s,
                    double(ov.volume.voxel_count()) / std::max(st.build_s, 1e-9) / 1e6,
                    st.cache_file.empty() ? "" : ", cached to ", st.cache_file.c_str());
    }
    if (!st.cache_note.empty()) std::printf("octree: note: %s\n", st.cache_note.c_str());
    const OctreeShape& shape = ex->octree_shape();
    std::printf(
        "octree: %zu levels, depth %d, %zu nodes, %.2f MiB = %.2f%% of the volume bytes, values "
        "[%g, %g]\n",
        shape.levels.size(), shape.depth(), shape.node_count,
        double(ex->octree_bytes()) / (1024.0 * 1024.0), 100.0 * share, ex->value_min(),
        ex->value_max());
    return ex;
}

// With the error rule asked for (--adaptive --adaptive-error), its meta-cell errors are built or
// mapped here, before any frame is timed, and reported beside the octree.
void prepare_error_rule(const EngineOptions& e, const SurfaceExtractor& ex, const Volume& volume) {
    if (!e.adaptive || e.uniform_level > 0 || !std::isfinite(e.adaptive_error_px)) return;
    const LodTable& lod = ex.prepare_lod_errors();
    if (lod.from_cache)
        std::printf("octree: meta-cell errors mapped from the cache\n");
    else
        std::printf("octree: meta-cell errors computed in %.3f s (%.0f M voxels/s)\n", lod.build_s,
                    double(volume.voxel_count()) / std::max(lod.build_s, 1e-9) / 1e6);
    if (!lod.cache_note.empty()) std::printf("octree: note: %s\n", lod.cache_note.c_str());
}

// --iso for the volume `ov` that `ex` extracts from.
double volume_iso(const std::optional<double>& iso, const OpenedVolume& ov,
                  const SurfaceExtractor& ex) {
    return checked_iso(iso, {ov.file ? ov.file->string() : std::string("phantom"), !ov.file,
                             ex.value_min(), ex.value_max()});
}

// --iso's surfaces for the volume `ov` that `ex` extracts from.
std::vector<SurfaceStyle> volume_surfaces(const std::vector<std::string>& given,
                                          const OpenedVolume& ov, const SurfaceExtractor& ex) {
    return checked_surfaces(given, {ov.file ? ov.file->string() : std::string("phantom"), !ov.file,
                                    ex.value_min(), ex.value_max()});
}

Mesh extract_timed(const SurfaceExtractor& ex, const FrameView& fv, Timings& t) {
    const double iso = fv.iso;
    ExtractStats es;
    Stopwatch sw;
    Mesh mesh = ex.full_surface(fv, &es);
    t.extract = sw.seconds();
    std::printf(
        "extract: iso %g: %zu triangles, %zu vertices, %zu active cells, %zu octree nodes "
        "visited, %zu leaf bricks scanned (%.3f s)\n",
        iso, mesh.triangle_count(), mesh.vertex_count(), es.cells_active, es.nodes_visited,
        es.leaves_active, t.extract);
    return mesh;
}

// "out/img.png" + "_c99" -> "out/img_c99.png"
std::filesystem::path with_suffix(const std::string& path, const std::string& suffix) {
    std::filesystem::path p(path);
    return p.parent_path() / (p.stem().string() + suffix + p.extension().string());
}

std::filesystem::path percent_snapshot(const RenderOptions& o, double pct) {
    return with_suffix(o.out, (o.snapshot_measure == "c" ? "_c" : "_final") + percent_label(pct));
}

std::filesystem::path rays_snapshot(const RenderOptions& o, std::size_t rays) {
    return with_suffix(o.out, "_r" + std::to_string(rays));
}

// Every file `render` may write, checked before any work: a typo fails at once, and nothing is
// written at all when one of them cannot be.
void check_render_outputs(const RenderOptions& o) {
    std::vector<OutputPath> outputs{{"--out", o.out}};
    if (!o.depth_out.empty()) outputs.push_back({"--depth-out", o.depth_out});
    if (!o.timeline.empty()) outputs.push_back({"--timeline", o.timeline});
    for (double pct : o.snapshots) outputs.push_back({"--snapshots", percent_snapshot(o, pct)});
    for (std::size_t rays : o.snapshot_rays)
        outputs.push_back({"--snapshot-rays", rays_snapshot(o, rays)});
    check_outputs(outputs);
    for (const OutputPath& p : outputs)
        if (p.option != "--timeline")
            if (std::string problem = image_format_problem(p.path); !problem.empty())
                throw InputError(p.path.string(), p.option, problem);
}

// The view of `render`: the front full view, turned and zoomed; InputError naming the option
// when the result is degenerate (core/camera.h: camera_problem).
Camera render_camera(const RenderOptions& o, const Volume& volume, float aspect) {
    const Projection proj =
        o.projection == "orthographic" ? Projection::orthographic : Projection::perspective;
    const Box3 bounds = volume.bounds();
    Camera cam = front_full_view(bounds, volume.orientation().axes, aspect, proj);
    if (o.orbit.size() == 2) cam = orbit(cam, o.orbit[0], o.orbit[1]);
    cam = zoom(cam, float(o.zoom));
    if (std::string p = camera_problem(cam); !p.empty())
        throw InputError("--zoom", "value", "zoom " + percent_label(o.zoom) + ": " + p);
    return fit_depth_range(cam, bounds);
}

// The view of `render --warm-up`'s untimed frame: the view turned kWarmUpYawDeg about the vertical
// axis. The timed frame then finds the process as a running wall's ranks have it (memory touched,
// the renderer's buffers and bins made) without having visited its very cells just before.
constexpr double kWarmUpYawDeg = 30;
FrameView warm_up_view(const FrameView& fv, const Box3& bounds) {
    const Camera cam = fit_depth_range(orbit(fv.camera, kWarmUpYawDeg, 0), bounds);
    return FrameView{
        cam, cam.frustum(float(fv.width) / float(fv.height)), fv.width, fv.height, fv.iso, {}};
}

ThreadBudget render_threads(const RenderOptions& o) {
    return o.threads > 0 ? ThreadBudget{o.threads} : ThreadBudget::hardware();
}

EngineOptions engine_options(const RenderOptions& o) {
    EngineOptions e = to_engine_options(o.engine);
    e.sample_at_rays = o.snapshot_rays;
    e.threads = render_threads(o).usable();
    return e;
}

// The snapshots due at replayed sample `s`, staged in `batch`.
void stage_snapshots(const RenderOptions& o, const TimelineSample& s, const Image& img,
                     std::vector<bool>& c_done, std::vector<bool>& r_done, OutputFiles& batch) {
    for (std::size_t k = 0; k < o.snapshots.size(); ++k) {
        const double m = o.snapshot_measure == "c" ? s.correctness.c : s.correctness.final_pixels;
        if (c_done[k] || m < o.snapshots[k] / 100.0) continue;
        c_done[k] = true;
        const auto path = percent_snapshot(o, o.snapshots[k]);
        write_image(batch, path, img);
        std::printf("snapshot: %s (C %.4f, final pixels %.4f, %.3f s, %zu rays)\n", path.c_str(),
                    s.correctness.c, s.correctness.final_pixels, s.time_s, s.rays);
    }
    for (std::size_t k = 0; k < o.snapshot_rays.size(); ++k) {
        if (r_done[k] || s.rays < o.snapshot_rays[k]) continue;
        r_done[k] = true;
        const auto path = rays_snapshot(o, o.snapshot_rays[k]);
        write_image(batch, path, img);
        std::printf("snapshot: %s (C %.4f, %zu rays)\n", path.c_str(), s.correctness.c, s.rays);
    }
}

// The replay after the frame (outside its timings): snapshots, the correctness tables, the
// draw-only floor and the timeline. With --against-full (`full` drawn), every replayed image is
// also measured against the full surface: the time to C = 99% of the true picture, not only of
// the engine's own final one.
// `measure` replays the frame, handing each image to its argument when that is set
// (app/whole_frame.h measure_frame, app/surfaces_frame.h measure_surfaces); `renderer`, when
// given, draws the draw-only floor.
using ImageCallback = std::function<void(const TimelineSample&, const Image&)>;
void replay_and_report(const RenderOptions& o, FrameResult& fr, const FrameView& fv,
                       const std::function<void(const ImageCallback&)>& measure, Renderer* renderer,
                       const Image& full, OutputFiles& batch) {
    Stopwatch sw;
    std::vector<bool> c_done(o.snapshots.size()), r_done(o.snapshot_rays.size());
    std::vector<TimelineSample> vs_full;
    // Whole images only for snapshots and --against-full: without them the replay reads back
    // the final picture's box alone.
    const bool images = o.against_full || !o.snapshots.empty() || !o.snapshot_rays.empty();
    auto on_image = [&](const TimelineSample& s, const Image& img) {
        stage_snapshots(o, s, img, c_done, r_done, batch);
        if (!o.against_full) return;
        vs_full.push_back(s);
        vs_full.back().correctness = measure_correctness(img, full);
    };
    measure(images ? ImageCallback(on_image) : nullptr);
    print_thresholds(fr, fr.timeline);
    if (o.against_full) print_thresholds(fr, vs_full, "the full surface at full resolution");
    // The draw-only floor draws the triangles again in one go (about as long as the replay on a
    // volume finer than the screen): a figure for studies, with their options.
    if (renderer && (o.against_full || !o.timeline.empty())) print_draw_only(fr, fv, *renderer);
    if (!o.timeline.empty()) {
        write_timeline_csv(batch, o.timeline, fr.timeline, fr.rays_screen);
        std::printf("timeline: %s (%zu samples; plot with scripts/plot_timeline.py)\n",
                    o.timeline.c_str(), fr.timeline.size());
    }
    std::printf("measure: replayed %zu samples in %.3f s (not part of the timings above)\n",
                fr.timeline.size(), sw.seconds());
}

// Whether the frame is replayed after it (replay_and_report): for the correctness tables, unless
// --no-measure, and for every output that needs the replayed images.
bool wants_replay(const RenderOptions& o) {
    return !o.no_measure || o.against_full || !o.timeline.empty() || !o.snapshots.empty() ||
           !o.snapshot_rays.empty();
}

// A coloured surface's legend (master/legend.h) and the engine's hook that colours it.
struct Colouring {
    std::function<void(Mesh&)> hook;
    std::optional<ColourScale> scale;
    std::string label;

    // `img` as written out: with the legend when the surface is coloured.
    Image written(const Image& img) const {
        if (!scale) return img;
        Image out = img;
        draw_legend(out, *scale, label);
        return out;
    }
};

Colouring colouring(const std::optional<OpenedColourField>& field, const ColourOptions& o,
                    const Volume& surface) {
    if (!field) return {};
    return {colour_hook(field->field, surface.spacing()), field->field.scale,
            colour_label(o, field->field.scale)};
}

std::size_t render_progressive(const RenderOptions& o, SurfaceExtractor& ex, Renderer& renderer,
                               const FrameView& fv, Timings& t, OutputFiles& batch,
                               const Colouring& colour) {
    warm_up(renderer);
    EngineOptions options = engine_options(o);
    options.colour = colour.hook;
    ProgressiveEngine engine(ex, options);
    auto progress = [&](const TimelineSample& s) {
        if (o.quiet) return;
        std::printf("  %7.2f s  level %2d  rays %9zu (%6.2f%%)  groups %6zu  triangles %9zu\n",
                    s.time_s, s.level, s.rays,
                    100.0 * double(s.rays) / double(fv.width) / double(fv.height), s.groups,
                    s.triangles);
        std::fflush(stdout);
    };
    if (o.warm_up) {
        const FrameResult w = draw_frame(engine, warm_up_view(fv, ex.volume().bounds()), renderer);
        std::printf(
            "warm-up: an untimed frame of the view turned %g degrees: %zu triangles in "
            "%.3f s\n",
            kWarmUpYawDeg, w.timeline.back().triangles, w.elapsed_s);
    }
    const double frame_at = t.command.seconds();
    const double cpu0 = thread_cpu_seconds();
    FrameResult fr = draw_frame(engine, fv, renderer, nullptr, progress);
    const double caller_cpu = thread_cpu_seconds() - cpu0;
    preload_image_io();  // OpenImageIO loads beside the report, not after it
    const TimelineSample& last = fr.timeline.back();
    t.frame = fr.elapsed_s;
    std::printf(
        "progressive: %s order, %s intersection, %s, %d thread%s: %zu rays (%.2f%% of the screen; "
        "box %dx%d) in %.3f s: %zu groups, %zu triangles, %zu cells visited\n",
        std::string(to_string(engine.options().order)).c_str(), o.engine.intersect.c_str(),
        o.engine.propagation == "angle"
            ? "cut-off angle"
            : ("max count " + std::to_string(o.engine.max_count)).c_str(),
        std::min(engine.options().threads, ex.threads()),
        std::min(engine.options().threads, ex.threads()) == 1 ? "" : "s", fr.rays_cast,
        100.0 * double(fr.rays_cast) / double(fr.rays_screen), fr.screen_rect.width,
        fr.screen_rect.height, fr.elapsed_s, fr.groups.size(), last.triangles, last.cells_visited);
    std::printf(
        "stages (summed over threads): intersection %.3f s | propagation %.3f s | extraction "
        "%.3f s | rendering %.3f s\n",
        last.t_intersect_s, last.t_propagate_s, last.t_extract_s, last.t_render_s);
    if (fr.workers.sum_s > 0)
        std::printf(
            "CPU: the drawing thread %.3f s, the other threads %.3f s (the busiest ran %.3f s "
            "past the drawing thread's levels)\n",
            caller_cpu, fr.workers.sum_s, fr.workers.beyond_s);
    std::printf("covered: the final image covers %zu px\n", covered_pixels(fr.final_image));
    std::printf("drawn: %zu of the %zu triangles cover a pixel centre%s\n", fr.triangles_drawn,
                last.triangles,
                o.engine.every_triangle ? " (all made and drawn: --every-triangle)"
                                        : "; the others change no pixel and are not drawn");
    print_first_picture(fr, frame_at, t.load, t.octree);
    if (fr.mask_level >= 0)
        std::printf("screen mask: %zu active nodes of octree level %d, %zu pixels to cast\n",
                    fr.mask_nodes, fr.mask_level, fr.screen_pixels);

    Image full;
    if (o.against_full) full = print_against_full(ex, renderer, fv, fr.final_image, colour.hook);
    if (o.against_truth) print_against_truth(ex, renderer, fv, fr.final_image, colour.hook);

    if (wants_replay(o))
        replay_and_report(
            o, fr, fv,
            [&](const ImageCallback& on_image) { measure_frame(fr, fv, renderer, on_image); },
            &renderer, full, batch);

    // After the replay, by when OpenImageIO has loaded beside it (preload_image_io above).
    Stopwatch sw;
    write_image(batch, o.out, colour.written(fr.final_image));
    if (!o.depth_out.empty()) write_depth(batch, o.depth_out, fr.final_image);
    t.write = sw.seconds();
    return last.triangles;
}

// The layers of several surfaces: the first draws with `ex` and `renderer`, every other with an
// extractor sharing its octree and a renderer of its own (all kept in `keep`).
struct SurfaceParts {
    std::vector<std::unique_ptr<SurfaceExtractor>> extractors;
    std::vector<std::unique_ptr<Renderer>> renderers;
    std::vector<std::unique_ptr<ProgressiveEngine>> engines;
    std::vector<SurfaceLayer> layers;
};

SurfaceParts surface_parts(const RenderOptions& o, SurfaceExtractor& ex, Renderer& renderer,
                           const std::vector<SurfaceStyle>& styles, const Colouring& colour) {
    SurfaceParts p;
    for (std::size_t k = 0; k < styles.size(); ++k) {
        SurfaceExtractor* e = &ex;
        Renderer* r = &renderer;
        if (k > 0) {
            p.extractors.push_back(ex.share());
            e = p.extractors.back().get();
            p.renderers.push_back(make_renderer(o.gl));
            r = p.renderers.back().get();
        }
        warm_up(*r);
        EngineOptions options = engine_options(o);
        options.colour = surface_colour_hook(styles[k], colour.hook);
        p.engines.push_back(std::make_unique<ProgressiveEngine>(*e, options));
        p.layers.push_back({p.engines.back().get(), r, styles[k]});
    }
    return p;
}

// Each layer's full surface, coloured as its engine colours groups; `triangles` counts them. With
// `t`, each extraction is timed and printed (extract_timed) and their sum kept in t->extract.
std::vector<Mesh> full_meshes(const SurfaceExtractor& ex, const std::vector<SurfaceLayer>& layers,
                              const FrameView& fv, std::size_t& triangles, Timings* t = nullptr) {
    std::vector<Mesh> meshes;
    for (const SurfaceLayer& l : layers) {
        FrameView v = fv;
        v.iso = l.style.iso;
        Timings one;
        meshes.push_back(t ? extract_timed(ex, v, one) : ex.full_surface(v));
        if (t) t->extract += one.extract;
        if (l.engine->options().colour) l.engine->options().colour(meshes.back());
        triangles += meshes.back().triangle_count();
    }
    return meshes;
}

void print_surfaces_frame(const SurfacesFrame& sf, const SurfaceParts& parts) {
    const FrameResult& fr = sf.frame;
    const TimelineSample& last = fr.timeline.back();
    std::printf(
        "progressive: %zu surfaces, one ray-order level of each in turn: %zu rays in %.3f s: %zu "
        "groups, %zu triangles, %zu cells visited\n",
        sf.layers.size(), fr.rays_cast, fr.elapsed_s, fr.group_count, last.triangles,
        last.cells_visited);
    for (std::size_t k = 0; k < sf.layers.size(); ++k) {
        const FrameResult& l = sf.layers[k];
        std::printf("  surface %s: %zu rays, %zu groups, %zu triangles (%zu drawn)\n",
                    surface_style_text(parts.layers[k].style).c_str(), l.rays_cast, l.group_count,
                    l.timeline.back().triangles, l.triangles_drawn);
    }
    std::printf(
        "stages (summed over threads and surfaces): intersection %.3f s | propagation %.3f s | "
        "extraction %.3f s | rendering %.3f s\n",
        last.t_intersect_s, last.t_propagate_s, last.t_extract_s, last.t_render_s);
    std::printf("covered: the final image covers %zu px\n", covered_pixels(fr.final_image));
}

// Several surfaces, or one translucent (core/surface_style.h): app/surfaces_frame.h's frame,
// reported as render_progressive reports one surface's.
std::size_t render_surfaces(const RenderOptions& o, SurfaceExtractor& ex, Renderer& renderer,
                            const std::vector<SurfaceStyle>& styles, const FrameView& fv,
                            Timings& t, OutputFiles& batch, const Colouring& colour) {
    SurfaceParts parts = surface_parts(o, ex, renderer, styles, colour);
    if (o.warm_up) {
        const SurfacesFrame w = draw_surfaces(parts.layers, warm_up_view(fv, ex.volume().bounds()));
        std::printf(
            "warm-up: an untimed frame of the view turned %g degrees: %zu triangles in "
            "%.3f s\n",
            kWarmUpYawDeg, w.frame.timeline.back().triangles, w.frame.elapsed_s);
    }
    const double frame_at = t.command.seconds();
    SurfacesFrame sf = draw_surfaces(parts.layers, fv);
    preload_image_io();
    t.frame = sf.frame.elapsed_s;
    FrameResult& fr = sf.frame;
    print_surfaces_frame(sf, parts);
    print_first_picture(fr, frame_at, t.load, t.octree);

    Image full;
    if (o.against_full || o.against_truth) {
        Stopwatch sw;
        std::size_t triangles = 0;
        const std::vector<Mesh> meshes = full_meshes(ex, parts.layers, fv, triangles);
        full = draw_surfaces_alone(parts.layers, meshes, fv);
        if (o.against_full) print_full_comparison(full, triangles, fr.final_image, sw.seconds());
        if (o.against_truth)
            print_truth_comparison(draw_surfaces_alone(parts.layers, meshes, fv, kTruthSamples),
                                   full, triangles, fr.final_image, sw.seconds());
    }
    if (wants_replay(o))
        replay_and_report(
            o, fr, fv,
            [&](const ImageCallback& on_image) {
                measure_surfaces(sf, parts.layers, fv, on_image);
            },
            nullptr, full, batch);
    Stopwatch sw;
    write_image(batch, o.out, colour.written(fr.final_image));
    if (!o.depth_out.empty()) write_depth(batch, o.depth_out, fr.final_image);
    t.write = sw.seconds();
    return fr.timeline.back().triangles;
}

// `render --full`'s picture written (with the legend of a coloured surface) and committed.
void write_full_picture(const RenderOptions& o, const Image& image, const Colouring& colour,
                        Timings& t, OutputFiles& batch) {
    Stopwatch sw;
    write_image(batch, o.out, colour.written(image));
    if (!o.depth_out.empty()) write_depth(batch, o.depth_out, image);
    batch.commit();
    t.write = sw.seconds();
    std::printf("wrote %s%s%s\n", o.out.c_str(), o.depth_out.empty() ? "" : " and ",
                o.depth_out.c_str());
}

// `render --full`: the surface extracted whole and drawn in one go; its triangles.
std::size_t render_full_surface(const RenderOptions& o, SurfaceExtractor& ex, Renderer& renderer,
                                const FrameView& fv, Timings& t, OutputFiles& batch,
                                const Colouring& colour) {
    if (o.warm_up) {
        Stopwatch warm;
        Mesh once = ex.full_surface(fv);
        if (colour.hook) colour.hook(once);
        draw_alone(renderer, once, fv);
        std::printf("warm-up: the full surface extracted and drawn once, untimed (%.3f s)\n",
                    warm.seconds());
    }
    Mesh mesh = extract_timed(ex, fv, t);
    if (colour.hook) colour.hook(mesh);
    Stopwatch sw;
    const Image image = draw_alone(renderer, mesh, fv);
    t.render = sw.seconds();
    const std::size_t covered = covered_pixels(image);
    std::printf("render: %s %dx%d, %.1f%% of pixels covered, %zu px (%.3f s)\n",
                std::string(renderer.name()).c_str(), fv.width, fv.height,
                100.0 * double(covered) / double(image.pixel_count()), covered, t.render);
    write_full_picture(o, image, colour, t, batch);
    return mesh.triangle_count();
}

// `render --full` of several surfaces: each extracted whole, drawn alone into its layer, and the
// layers composited; their triangles.
std::size_t render_full_surfaces(const RenderOptions& o, SurfaceExtractor& ex, Renderer& renderer,
                                 const std::vector<SurfaceStyle>& styles, const FrameView& fv,
                                 Timings& t, OutputFiles& batch, const Colouring& colour) {
    SurfaceParts parts = surface_parts(o, ex, renderer, styles, colour);
    std::size_t triangles = 0;
    const std::vector<Mesh> meshes = full_meshes(ex, parts.layers, fv, triangles, &t);
    Stopwatch sw;
    const Image image = draw_surfaces_alone(parts.layers, meshes, fv);
    t.render = sw.seconds();
    std::printf("render: %zu surfaces composited, %dx%d, %zu px covered (%.3f s)\n", meshes.size(),
                fv.width, fv.height, covered_pixels(image), t.render);
    write_full_picture(o, image, colour, t, batch);
    return triangles;
}

// What the file carried that a user checks (format, modality, series, scaling), and where the
// volume lies in patient space when the file said.
void print_file_facts(const Volume& v) {
    for (const VolumeFact& f : v.facts()) std::printf("%s: %s\n", f.name.c_str(), f.value.c_str());
    const Orientation& o = v.orientation();
    if (!o.known) return;
    const Box3 p = formats::patient_bounds(v);
    std::printf(
        "orientation: %s (where x, y, z point: L R left right, A P front back, S I up down)\n",
        formats::orientation_letters(o.axes).c_str());
    std::printf("patient bounds: (%g, %g, %g) - (%g, %g, %g) mm, LPS\n", double(p.min.x),
                double(p.min.y), double(p.min.z), double(p.max.x), double(p.max.y),
                double(p.max.z));
}

}  // namespace

int run_info(const InfoOptions& o) {
    Timings t;
    OpenedVolume ov = open_volume(o.volume, /*quiet=*/false, VolumeUse{.casts = false});
    t.load = ov.load_s;
    prepare(ov, t);
    const Box3 b = ov.volume.bounds();
    std::printf("bounds: (%g, %g, %g) - (%g, %g, %g) object units\n", double(b.min.x),
                double(b.min.y), double(b.min.z), double(b.max.x), double(b.max.y),
                double(b.max.z));
    print_file_facts(ov.volume);
    if (!ov.file)
        std::printf("suggested isovalues: skin %g, bone %g\n", kPhantomSkinIso, kPhantomBoneIso);
    return 0;
}

int run_extract(const ExtractOptions& o) {
    check_outputs({{"--out", o.out}});
    const std::optional<MeshFormat> format = mesh_format_of(o.out);
    if (!format)
        throw InputError(o.out, "--out",
                         "unknown mesh format " +
                             quote(std::filesystem::path(o.out).extension().string()) +
                             ": expected " + mesh_formats_named());
    const bool meshopt = o.compress == "meshopt";
    if (meshopt && *format != MeshFormat::glb)
        throw InputError(
            "--compress", "value",
            "meshopt compresses a .glb, not " + quote(o.out) + "; give --out FILE.glb");
    FrameView cut;  // extraction needs only the isovalue and the planes
    cut.clip = checked_clip(o.clip);
    Timings t;
    OpenedVolume ov = open_volume(o.volume);
    t.load = ov.load_s;
    auto ex = prepare(ov, t);
    cut.iso = volume_iso(o.iso, ov, *ex);
    check_clip_keeps(cut.clip, ov.volume.dims(), "--clip", "value");
    Mesh mesh = extract_timed(*ex, cut, t);
    print_paging(ov);
    Stopwatch sw;
    write_mesh(o.out, mesh, *format, meshopt);
    t.write = sw.seconds();
    std::printf("wrote %s\n", o.out.c_str());
    t.print(mesh.triangle_count());
    return 0;
}

int run_render(const RenderOptions& o) {
    const auto size = parse_size(o.size);
    if (!size)
        throw InputError(
            "--size", "value",
            "expected WIDTHxHEIGHT, each an integer in [1, 32768], got " + quote(o.size));
    check_render_outputs(o);
    check_surface_texts(o.iso);                 // fails early on a bad --iso
    (void)engine_options(o);                    // and on a bad --order
    const ClipSet clip = checked_clip(o.clip);  // and on a bad --clip, before the volume is read
    (void)checked_colour_map(o.colour);         // and on a bad --colormap
    Timings t;
    // One thread is one core, as on a wall rank with one (app/wall_run.cpp): llvmpipe then
    // rasterises in the drawing thread instead of its own threads on the other cores. The
    // variable must be set before the first context; a vendor driver ignores it.
    if (render_threads(o).usable() == 1) setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);
    // Create the GL context first: a missing driver should fail before the volume is read.
    auto renderer = make_renderer(o.gl);
    // One frame keeps the map under --huge-pages auto; --warm-up times the frame as a running
    // wall's ranks have it, and they hold the copy.
    OpenedVolume ov = open_volume(o.volume, /*quiet=*/false, VolumeUse{.one_frame = !o.warm_up});
    t.load = ov.load_s;
    auto ex = prepare(ov, t, render_threads(o));
    if (!o.full) prepare_error_rule(engine_options(o), *ex, ov.volume);
    const std::vector<SurfaceStyle> surfaces = volume_surfaces(o.iso, ov, *ex);
    const double iso = surfaces[0].iso;
    const bool layered = !one_opaque_surface(surfaces);
    const std::optional<OpenedColourField> field = open_colour_field(o.colour, o.volume, ov.volume);
    Colouring colour = colouring(field, o.colour, ov.volume);
    if (!layered) colour.hook = surface_colour_hook(surfaces[0], colour.hook);

    const float aspect = float(size->x) / float(size->y);
    const Camera cam = render_camera(o, ov.volume, aspect);
    FrameView fv{cam, cam.frustum(aspect), size->x, size->y, iso, clip};
    check_clip_keeps(fv.clip, ov.volume.dims(), "--clip", "value");

    // Every output is staged here and appears at the end, all together (no partial output).
    OutputFiles batch;
    if (!o.full) {
        const std::size_t triangles =
            layered ? render_surfaces(o, *ex, *renderer, surfaces, fv, t, batch, colour)
                    : render_progressive(o, *ex, *renderer, fv, t, batch, colour);
        const std::size_t files = batch.size();
        batch.commit();
        std::printf("wrote %s%s%s (%zu file(s) in all)\n", o.out.c_str(),
                    o.depth_out.empty() ? "" : " and ", o.depth_out.c_str(), files);
        print_paging(ov);
        t.print(triangles);
        return 0;
    }
    const std::size_t triangles =
        layered ? render_full_surfaces(o, *ex, *renderer, surfaces, fv, t, batch, colour)
                : render_full_surface(o, *ex, *renderer, fv, t, batch, colour);
    print_paging(ov);
    t.print(triangles);
    return 0;
}

}  // namespace isowall
