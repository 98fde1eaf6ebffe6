#include "tile/layered_jobs.h"

#include <stdexcept>
#include <string>

#include "core/image_ops.h"
#include "core/util.h"
#include "wire/wire.h"

namespace isowall {

struct LayeredJobs::Layer {
    SurfaceStyle style;
    std::unique_ptr<SurfaceExtractor> extractor;  // null for the first layer (the setup's)
    std::unique_ptr<Renderer> tile, help;         // null for the first layer
    std::unique_ptr<ProgressiveEngine> engine;
    std::unique_ptr<TileJobs> jobs;
};

LayeredJobs::LayeredJobs(LayeredJobsSetup setup) : setup_(std::move(setup)) {
    layer(0, SurfaceStyle{});
}

LayeredJobs::~LayeredJobs() = default;

LayeredJobs::Layer& LayeredJobs::layer(std::size_t k, const SurfaceStyle& style) {
    if (k >= layers_.size()) layers_.resize(k + 1);
    std::unique_ptr<Layer>& l = layers_[k];
    const bool same_colour =
        l && l->jobs && l->style.coloured == style.coloured && l->style.colour == style.colour;
    if (same_colour) {
        l->style = style;
        return *l;
    }
    if (!l) {
        l = std::make_unique<Layer>();
        if (k > 0) {
            if (!setup_.make_renderer)
                throw std::logic_error("a tile without a renderer factory draws one surface");
            l->extractor = setup_.extractor->share();
            l->tile = setup_.make_renderer();
            l->help = setup_.make_renderer();
        }
    }
    l->style = style;
    l->jobs.reset();  // before the engine it refers to
    EngineOptions options = setup_.engine;
    options.colour = surface_colour_hook(style, setup_.engine.colour);
    l->engine = std::make_unique<ProgressiveEngine>(
        l->extractor ? *l->extractor : *setup_.extractor, options);
    l->jobs = std::make_unique<TileJobs>(*l->engine, l->tile ? *l->tile : setup_.tile,
                                         l->help ? *l->help : setup_.help, setup_.measure);
    return *l;
}

void LayeredJobs::use_extractor(SurfaceExtractor& extractor) {
    setup_.extractor = &extractor;
    for (std::size_t k = 0; k < layers_.size(); ++k) {
        Layer& l = *layers_[k];
        l.jobs.reset();  // made again by layer(), before the engine it refers to goes
        l.engine.reset();
        if (k > 0) l.extractor = extractor.share();
    }
}

void LayeredJobs::prepare(int width, int height) {
    for (auto& l : layers_)
        if (l->jobs) l->jobs->prepare(width, height);
}

void LayeredJobs::begin(const ViewMsg& v, const std::atomic<bool>& stop,
                        const ProgressiveEngine::Progress& progress) {
    wall0_ = wall_end_ = wall_now_s();
    std::vector<SurfaceStyle> styles = v.surfaces;
    if (styles.empty()) styles.push_back(SurfaceStyle{v.view.iso});
    for (std::size_t k = 0; k < styles.size(); ++k) {
        Layer& l = layer(k, styles[k]);
        ViewMsg one = v;
        one.view.iso = styles[k].iso;
        one.surfaces.clear();
        l.jobs->begin(one, stop, progress);
    }
    active_ = styles.size();
    running_ = 0;
    landed_.clear();
}

bool LayeredJobs::started() const {
    return layers_[0]->jobs && layers_[0]->jobs->started();
}

std::uint64_t LayeredJobs::generation() const {
    return layers_[0]->jobs ? layers_[0]->jobs->generation() : 0;
}

LayeredJobs::Outcome LayeredJobs::run(const JobMsg& job, int rank) {
    Outcome out;
    out.done.generation = job.generation;
    out.done.job = job.job;
    out.done.start_s = wall_now_s();
    for (std::size_t k = 0; k < active_; ++k) {
        running_ = k;
        JobMsg one = job;
        one.view.iso = layers_[k]->style.iso;
        TileJobs::Outcome o = layers_[k]->jobs->run(one, rank);
        out.done.rays += o.done.rays;
        out.done.groups += o.done.groups;
        out.done.triangles += o.done.triangles;
        out.done.cpu_s += o.done.cpu_s;
        if (!o.completed) return out;
        if (o.result) {
            o.result->layer = static_cast<std::uint8_t>(k);
            out.results.push_back(std::move(*o.result));
        }
    }
    running_ = 0;
    out.completed = true;
    out.done.cpu_end_s = busy_cpu_s();
    for (RegionMsg& r : out.results) r.cpu_end_s = out.done.cpu_end_s;
    out.done.end_s = wall_end_ = wall_now_s();
    return out;
}

void LayeredJobs::measure_point() {
    layers_[running_]->jobs->measure_point();
}

void LayeredJobs::present_own() {
    layers_[running_]->jobs->present_own();
}

void LayeredJobs::exclude_cpu(double cpu_s) {
    layers_[running_]->jobs->exclude_cpu(cpu_s);
}

bool LayeredJobs::land(RegionMsg m) {
    if (m.layer >= active_)
        throw WireError("region message: layer " + std::to_string(m.layer) + ": the view has " +
                        std::to_string(active_) + " surface(s)");
    std::uint32_t& in = landed_[m.job];
    const std::uint32_t bit = 1u << m.layer;
    if (in & bit)
        throw WireError("region message: job " + std::to_string(m.job) + " layer " +
                        std::to_string(m.layer) + " came twice");
    in |= bit;
    layers_[m.layer]->jobs->land(std::move(m));
    return in == (1u << active_) - 1;
}

Image LayeredJobs::image() {
    if (active_ == 1) return layers_[0]->jobs->image();
    std::vector<Image> images;
    std::vector<float> opacity;
    for (std::size_t k = 0; k < active_; ++k) {
        images.push_back(layers_[k]->jobs->image());
        opacity.push_back(layers_[k]->style.opacity);
    }
    std::vector<const Image*> layers;
    for (const Image& i : images) layers.push_back(&i);
    return composite_layers(layers, opacity);
}

double LayeredJobs::busy_cpu_s() const {
    double s = 0;
    for (std::size_t k = 0; k < active_; ++k) s += layers_[k]->jobs->busy_cpu_s();
    return s;
}

void LayeredJobs::add_busy(double cpu_s) {
    layers_[0]->jobs->add_busy(cpu_s);
}

TimelineSample LayeredJobs::now() const {
    TimelineSample s;
    for (std::size_t k = 0; k < active_; ++k) add_sample(s, layers_[k]->jobs->now());
    return s;
}

double LayeredJobs::workers_beyond_s() const {
    double s = 0;
    for (std::size_t k = 0; k < active_; ++k) s += layers_[k]->jobs->workers_beyond_s();
    return s;
}

std::vector<CurvePoint> LayeredJobs::curve(std::uint64_t& significant) {
    if (active_ != 1) throw std::logic_error("the correctness curve of several surfaces");
    return layers_[0]->jobs->curve(significant);
}

}  // namespace isowall
