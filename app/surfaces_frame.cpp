#include "app/surfaces_frame.h"

#include <algorithm>
#include <memory>
#include <optional>

#include "core/image_ops.h"
#include "core/util.h"
#include "progressive/correctness.h"
#include "render/renderer_sink.h"

namespace isowall {
namespace {

constexpr double kProgressIntervalS = 0.5;

// One surface's frame while it is cast.
struct LiveLayer {
    FrameView view;
    std::unique_ptr<RendererSink> draw;
    RecordingSink record;
    std::unique_ptr<TeeSink> both;
    std::unique_ptr<EngineFrame> frame;
    RegionCursor cursor;
    double offset_s = 0;  // when its frame began, on the picture's clock
    bool ok = true;       // false once stopped
};

// One timeline on the picture's clock: at each surface's sample, what every surface had by then.
void merge_timelines(SurfacesFrame& out, const std::vector<double>& offsets) {
    struct Event {
        double t;
        std::size_t layer, index;
    };
    std::vector<Event> events;
    for (std::size_t k = 0; k < out.layers.size(); ++k)
        for (std::size_t i = 0; i < out.layers[k].timeline.size(); ++i)
            events.push_back({out.layers[k].timeline[i].time_s + offsets[k], k, i});
    std::stable_sort(events.begin(), events.end(),
                     [](const Event& a, const Event& b) { return a.t < b.t; });
    std::vector<std::optional<std::size_t>> last(out.layers.size());
    for (const Event& e : events) {
        last[e.layer] = e.index;
        TimelineSample s;
        s.time_s = e.t;
        std::vector<std::size_t> shown(out.layers.size(), 0);
        for (std::size_t k = 0; k < out.layers.size(); ++k) {
            if (!last[k]) continue;
            const TimelineSample& ks = out.layers[k].timeline[*last[k]];
            add_sample(s, ks);
            shown[k] = ks.groups;
        }
        out.frame.timeline.push_back(s);
        out.shown.push_back(std::move(shown));
    }
}

void sum_frames(SurfacesFrame& out) {
    FrameResult& f = out.frame;
    f.completed = true;
    for (const FrameResult& l : out.layers) {
        f.completed = f.completed && l.completed;
        f.rays_cast += l.rays_cast;
        f.rays_second_pass += l.rays_second_pass;
        f.group_count += l.group_count;
        f.triangles_drawn += l.triangles_drawn;
        f.workers.sum_s += l.workers.sum_s;
        f.workers.beyond_s += l.workers.beyond_s;
        f.screen_pixels = std::max(f.screen_pixels, l.screen_pixels);
        f.rays_screen = std::max(f.rays_screen, l.rays_screen);
        f.screen_rect = is_empty(f.screen_rect) ? l.screen_rect : f.screen_rect;
    }
    f.mask_level = -1;
}

}  // namespace

std::vector<float> layer_opacities(const std::vector<SurfaceLayer>& layers) {
    std::vector<float> out;
    for (const SurfaceLayer& l : layers) out.push_back(l.style.opacity);
    return out;
}

SurfacesFrame draw_surfaces(const std::vector<SurfaceLayer>& layers, const FrameView& view,
                            const std::atomic<bool>* stop,
                            const ProgressiveEngine::Progress& progress) {
    static const std::atomic<bool> never{false};
    const std::atomic<bool>& halt = stop ? *stop : never;
    Stopwatch clock;
    std::vector<LiveLayer> live(layers.size());
    for (std::size_t k = 0; k < layers.size(); ++k) {
        LiveLayer& l = live[k];
        l.view = view;
        l.view.iso = layers[k].style.iso;
        l.draw = std::make_unique<RendererSink>(*layers[k].renderer,
                                                !layers[k].engine->options().sampled_triangles);
        l.both = std::make_unique<TeeSink>(std::vector<GroupSink*>{l.draw.get(), &l.record});
        l.offset_s = clock.seconds();
        l.frame = std::make_unique<EngineFrame>(*layers[k].engine, l.view, halt);
        l.both->begin(l.view);
        l.cursor = l.frame->cursor(l.view, l.view.screen());
    }
    double last_progress = -1e9;
    for (bool more = true; more;) {
        more = false;
        for (LiveLayer& l : live) {
            if (l.cursor.done || !l.ok) continue;
            l.ok = l.frame->cast(l.view, l.cursor, FrameOutput(*l.both, l.draw.get(), nullptr), 1);
            more = more || (l.ok && !l.cursor.done);
        }
        if (progress && clock.seconds() - last_progress >= kProgressIntervalS) {
            last_progress = clock.seconds();
            TimelineSample s;
            s.time_s = last_progress;
            for (const LiveLayer& l : live) add_sample(s, l.frame->now());
            progress(s);
        }
    }
    SurfacesFrame out;
    std::vector<double> offsets;
    std::vector<const Image*> finals;
    for (std::size_t k = 0; k < live.size(); ++k) {
        LiveLayer& l = live[k];
        FrameResult r = l.frame->finish(l.ok && l.cursor.done);
        r.rays_screen =
            static_cast<std::size_t>(view.width) * static_cast<std::size_t>(view.height);
        r.screen_rect = l.cursor.rect;
        r.screen_pixels = l.cursor.pixels;
        r.groups = std::move(l.record.groups);
        r.triangles_drawn = l.draw->drawn_triangles();
        if (r.completed) l.draw->read_back(r.final_image);
        out.layers.push_back(std::move(r));
        offsets.push_back(l.offset_s);
    }
    sum_frames(out);
    out.frame.elapsed_s = clock.seconds();
    merge_timelines(out, offsets);
    if (out.frame.completed) {
        for (const FrameResult& r : out.layers) finals.push_back(&r.final_image);
        out.frame.final_image = composite_layers(finals, layer_opacities(layers));
    }
    return out;
}

void measure_surfaces(SurfacesFrame& frame, const std::vector<SurfaceLayer>& layers,
                      const FrameView& view,
                      const std::function<void(const TimelineSample&, const Image&)>& on_image) {
    const Image& final_image = frame.frame.final_image;
    if (final_image.pixel_count() == 0) return;
    // As measure_frame: without a caller that wants whole images, only the box of the pixels the
    // final picture covers is read back and composited.
    const PixelRect box = on_image ? PixelRect{0, 0, final_image.width, final_image.height}
                                   : covered_box(final_image);
    const Image against = is_empty(box) || on_image ? Image{} : crop(final_image, box);
    std::vector<std::unique_ptr<RendererSink>> replay;
    for (std::size_t k = 0; k < layers.size(); ++k) {
        replay.push_back(std::make_unique<RendererSink>(*layers[k].renderer));
        FrameView v = view;
        v.iso = layers[k].style.iso;
        replay.back()->begin(v);
    }
    const std::vector<float> opacity = layer_opacities(layers);
    std::vector<std::size_t> drawn(layers.size(), 0);
    std::vector<Image> images(layers.size());
    std::vector<const Image*> pointers;
    for (const Image& i : images) pointers.push_back(&i);
    Correctness last;
    bool any = false;
    Image picture;
    for (std::size_t i = 0; i < frame.frame.timeline.size(); ++i) {
        TimelineSample& s = frame.frame.timeline[i];
        bool changed = !any;
        for (std::size_t k = 0; k < layers.size(); ++k)
            for (; drawn[k] < frame.shown[i][k]; ++drawn[k], changed = true)
                replay[k]->add(frame.layers[k].groups[drawn[k]]);
        if (is_empty(box)) {
            s.correctness = measure_correctness(final_image, final_image);
            continue;
        }
        if (changed) {
            for (std::size_t k = 0; k < layers.size(); ++k) replay[k]->read_back(images[k], box);
            picture = composite_layers(pointers, opacity);
            last = measure_correctness(picture, on_image ? final_image : against);
            any = true;
        }
        s.correctness = last;
        if (on_image) on_image(s, picture);
    }
}

Image draw_surfaces_alone(const std::vector<SurfaceLayer>& layers, const std::vector<Mesh>& meshes,
                          const FrameView& view, int supersample) {
    FrameView big = view;
    big.width *= std::max(supersample, 1);
    big.height *= std::max(supersample, 1);
    std::vector<Image> images;
    for (std::size_t k = 0; k < layers.size(); ++k)
        images.push_back(draw_alone(*layers[k].renderer, meshes[k], big));
    std::vector<const Image*> pointers;
    for (const Image& i : images) pointers.push_back(&i);
    Image picture = composite_layers(pointers, layer_opacities(layers));
    return supersample > 1 ? box_filtered_truth(picture, supersample) : picture;
}

}  // namespace isowall
