#include "app/render_report.h"

#include <algorithm>
#include <cstdio>
#include <optional>

#include "app/whole_frame.h"
#include "core/util.h"
#include "progressive/correctness.h"
#include "progressive/timeline.h"

namespace isowall {

void Timings::print(std::size_t triangles) const {
    if (frame >= 0) {
        std::printf(
            "timing: load %.3f s | octree %.3f s | progressive frame %.3f s | write %.3f s"
            " | triangles %zu | peak RSS %.1f MiB\n",
            load, octree, frame, write, triangles, peak_rss_mib());
        return;
    }
    std::printf(
        "timing: load %.3f s | octree %.3f s | extract %.3f s | render %.3f s | write %.3f s"
        " | triangles %zu | peak RSS %.1f MiB\n",
        load, octree, extract, render, write, triangles, peak_rss_mib());
}

std::size_t covered_pixels(const Image& image) {
    std::size_t covered = 0;
    for (float d : image.depth) covered += d < 1.0f;
    return covered;
}

std::string percent_label(double pct) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%g", pct);
    return buf;
}

// Both measures: the share of final pixels (chapters 2-3, which the dissertation's tables call C)
// and C = 1 - E (section 4.2). The second counts an undrawn pixel as a full error and takes the
// RMS, so C = 0.99 allows only 0.01% of the significant pixels to be missing.
void print_thresholds(const FrameResult& fr, const std::vector<TimelineSample>& timeline,
                      const char* against) {
    std::printf("correctness (replayed against %s):\n", against);
    std::printf("  %-20s %10s %10s %12s %12s %9s\n", "point", "time s", "rays", "rays %",
                "triangles", "groups");
    auto row = [&](const std::string& label, const std::optional<std::size_t>& i) {
        if (!i) {
            std::printf("  %-20s %10s\n", label.c_str(), "not reached");
            return;
        }
        const TimelineSample& s = timeline[*i];
        std::printf("  %-20s %10.3f %10zu %11.4f%% %12zu %9zu\n", label.c_str(), s.time_s, s.rays,
                    100.0 * double(s.rays) / double(fr.rays_screen), s.triangles, s.groups);
    };
    for (Measure m : {Measure::final_pixels, Measure::c}) {
        const char* name = m == Measure::c ? "C=1-E" : "final px";
        for (double th : {0.90, 0.99, 0.999})
            row(std::string(name) + " >= " + percent_label(100 * th) + "%",
                first_reaching(timeline, th, m));
        row(std::string(name) + " = 100%", first_reaching(timeline, 1.0, m));
    }
    row("all rays", timeline.size() - 1);
}

// The floor for "C = 99% in time T": drawing the same triangles in one go, with no extraction at
// all (the benchmark's target compares T with this).
void print_draw_only(const FrameResult& fr, const FrameView& fv, Renderer& renderer) {
    for (Measure m : {Measure::final_pixels, Measure::c}) {
        const auto i = first_reaching(fr.timeline, 0.99, m);
        if (!i) continue;
        Mesh merged;
        for (std::size_t g = 0; g < fr.timeline[*i].groups; ++g) merged.append(fr.groups[g].mesh);
        renderer.clear();
        renderer.finish();
        Stopwatch draw;
        renderer.draw(merged, fv.camera.view(), fv.frustum.matrix());
        renderer.finish();
        const double draw_s = draw.seconds();
        std::printf(
            "draw-only: the %zu triangles on screen at %s >= 99%% draw in %.3f s; the "
            "engine took %.3f s (%.2fx)\n",
            merged.triangle_count(), m == Measure::c ? "C" : "final px", draw_s,
            fr.timeline[*i].time_s, fr.timeline[*i].time_s / std::max(draw_s, 1e-9));
    }
}

// The progressive frame's final image against the full surface drawn in the same view (outside
// the timings): 1 and 100% at full resolution, up to the renderers' ties; below that, what
// adaptive resolution's meta-cells change on screen.
void print_full_comparison(const Image& full, std::size_t triangles, const Image& final_image,
                           double seconds) {
    const Correctness c = measure_correctness(final_image, full);
    std::printf(
        "against the full surface (%zu triangles, %zu px): C = %.5f, final px %.3f%%, coverage "
        "IoU %.5f (%.3f s, not part of the timings)\n",
        triangles, c.significant, c.c, 100.0 * c.final_pixels, coverage_iou(final_image, full),
        seconds);
}

void print_truth_comparison(const Image& truth, const Image& full, std::size_t triangles,
                            const Image& final_image, double seconds) {
    const Fidelity at_one = measure_fidelity(full, truth);
    const Fidelity own = measure_fidelity(final_image, truth);
    const bool holds = passes_fidelity_gate(own, at_one);
    std::printf(
        "against the truth (the full surface, %zu triangles, at %dx%d samples a pixel, "
        "box-filtered: %zu px covered; %.3f s, not part of the timings):\n",
        triangles, kTruthSamples, kTruthSamples, covered_pixels(truth), seconds);
    auto row = [](const char* what, const Fidelity& f) {
        std::printf("  %-34s C_T = %.5f, coverage IoU %.5f, %.2f%% of px off by > 8/255\n", what,
                    f.c, f.iou, 100.0 * f.off_share);
    };
    row("final image:", own);
    row("full surface at 1 sample a pixel:", at_one);
    const double c_bar = at_one.c - kFidelityC, iou_bar = at_one.iou - kFidelityIoU;
    std::printf("  fidelity gate: %s (C_T %.5f %s %.5f, IoU %.5f %s %.5f)\n",
                holds ? "holds" : "FAILS", own.c, own.c >= c_bar ? ">=" : "<", c_bar, own.iou,
                own.iou >= iou_bar ? ">=" : "<", iou_bar);
}

Image print_against_full(const SurfaceExtractor& ex, Renderer& renderer, const FrameView& fv,
                         const Image& final_image, const std::function<void(Mesh&)>& colour) {
    Stopwatch sw;
    Mesh mesh = ex.full_surface(fv);
    if (colour) colour(mesh);
    Image full = draw_alone(renderer, mesh, fv);
    print_full_comparison(full, mesh.triangle_count(), final_image, sw.seconds());
    return full;
}

void print_against_truth(const SurfaceExtractor& ex, Renderer& renderer, const FrameView& fv,
                         const Image& final_image, const std::function<void(Mesh&)>& colour) {
    Stopwatch sw;
    Mesh mesh = ex.full_surface(fv);
    if (colour) colour(mesh);
    const Image truth = draw_truth(renderer, mesh, fv);
    print_truth_comparison(truth, draw_alone(renderer, mesh, fv), mesh.triangle_count(),
                           final_image, sw.seconds());
}

void print_first_picture(const FrameResult& fr, double frame_at, double load_s, double octree_s) {
    const auto first = std::find_if(fr.timeline.begin(), fr.timeline.end(),
                                    [](const TimelineSample& s) { return s.triangles > 0; });
    if (first == fr.timeline.end()) {
        std::printf("first picture: none (the frame drew nothing)\n");
        return;
    }
    std::printf(
        "first picture: %.3f s after the command began (volume %.3f s, octree %.3f s; the first "
        "group showed %.3f s into the frame)\n",
        frame_at + first->time_s, load_s, octree_s, first->time_s);
}

void print_paging(const OpenedVolume& ov) {
    if (ov.pager)
        std::printf("store: %s\n", store::paging_line(ov.pager->stats(), ov.pager->cap()).c_str());
}

}  // namespace isowall
