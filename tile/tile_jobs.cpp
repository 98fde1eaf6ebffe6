#include "tile/tile_jobs.h"

#include <algorithm>
#include <cmath>

#include "core/image_ops.h"
#include "core/pixel_rect_ops.h"
#include "core/ray.h"
#include "progressive/correctness.h"
#include "progressive/trace.h"
#include "wire/wire.h"

namespace isowall {

FrameView region_view(const FrameView& owner, const PixelRect& rect) {
    FrameView v = owner;
    v.frustum = sub_frustum(owner.frustum, owner.width, owner.height, rect);
    v.width = rect.width;
    v.height = rect.height;
    return v;
}

// Where a job's groups go: every group is kept (a later job may need it), drawn into the help
// image when the job is for another tile, and drawn into the rank's own tile when it may show
// there (a group whose bounds project outside the tile cannot be what a later ray of the tile
// hits, so leaving it out loses nothing). In a help job, the earlier groups whose cells its rays
// meet are drawn before the engine reads the help image's coverage or the job's result is read.
class TileJobs::JobSink final : public GroupSink, public ShownPixels, public SeenGroups {
  public:
    JobSink(TileJobs& jobs, RendererSink* help) : jobs_(jobs), help_(help) {}
    // A help job is told of the earlier groups its rays meet; a job of the rank's own tile draws
    // every group there already.
    FrameOutput output() { return FrameOutput(*this, this, help_ ? this : nullptr); }
    void add(const Group& group) override {
        Box3 b;
        for (const glm::vec3& p : group.mesh.positions) b.merge(p);
        if (help_) help_->add(group);
        if (jobs_.shows(b, jobs_.own_)) jobs_.tile_sink_.add(group);
        jobs_.group_index_[group.id] = jobs_.groups_.size();
        jobs_.groups_.push_back({group, b, jobs_.job_key_, help_ ? jobs_.help_job_ : 0});
    }
    double present() override {
        if (help_) jobs_.draw_seen_groups();
        return (help_ ? help_->present() : 0.0) + jobs_.tile_sink_.present();
    }
    void coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) override {
        if (help_)
            jobs_.help_coverage(covered, rect);
        else
            jobs_.tile_sink_.coverage(covered, rect);
    }
    void seen(std::uint32_t group_id) override { jobs_.seen_.push_back(group_id); }

  private:
    TileJobs& jobs_;
    RendererSink* help_;
};

bool TileJobs::shows(const Box3& bounds, const FrameView& view) {
    if (bounds.empty()) return false;
    const PixelRect on =
        screen_box(bounds, view.camera.view(), view.frustum, view.width, view.height);
    return on.width > 0 && on.height > 0;
}

TileJobs::TileJobs(ProgressiveEngine& engine, Renderer& tile, Renderer& help, bool measure)
    : engine_(engine),
      tile_sink_(tile, !engine.options().sampled_triangles),
      help_sink_(help, !engine.options().sampled_triangles),
      measure_(measure) {
    warm_up(tile);
    warm_up(help);
}

void TileJobs::prepare(int width, int height) {
    tile_sink_.begin(FrameView{Camera{}, Frustum{}, width, height, 0.0, {}});
    tile_sink_.present();
    landed_.resize(width, height);
}

void TileJobs::begin(const ViewMsg& v, const std::atomic<bool>& stop,
                     const ProgressiveEngine::Progress& progress) {
    const double c0 = thread_cpu_seconds();
    wall0_ = wall_now_s();
    wall_end_ = wall0_;
    frame_.reset();
    generation_ = v.generation;
    own_ = v.view;
    groups_.clear();
    group_index_.clear();
    seen_.clear();
    band_cover_.clear();
    cursors_.clear();
    shots_.clear();
    last_draw_s_ = 0;
    last_shot_s_ = -1;
    if (landed_any_ || landed_.width != own_.width || landed_.height != own_.height)
        landed_.resize(own_.width, own_.height);
    landed_any_ = false;
    frame_ = std::make_unique<EngineFrame>(engine_, own_, stop, progress);
    tile_sink_.begin(own_);
    busy_cpu_s_ = thread_cpu_seconds() - c0;
}

void TileJobs::present_own() {
    if (measure_ && in_own_job_) tile_sink_.present();
}

void TileJobs::measure_point() {
    if (!measure_ || !in_own_job_) return;
    const double now = thread_cpu_seconds();
    const double busy_now = busy_cpu_s_ + job_cpu_s(now);
    if (busy_now - last_shot_s_ < kShotIntervalS) return;
    Image img;
    tile_sink_.read_back(img, job_rect_);
    shots_.push_back({busy_now, job_rect_, std::move(img), true});
    last_shot_s_ = busy_now;
    job_measure_cpu_ += thread_cpu_seconds() - now;
}

double TileJobs::job_cpu_s(double now) const {
    return now - job_c0_ - job_measure_cpu_ + (frame_->workers().beyond_s - job_beyond0_);
}

void TileJobs::draw_seen_groups() {
    for (const std::uint32_t id : seen_) {
        const auto it = group_index_.find(id);
        if (it == group_index_.end()) continue;  // kFree: nothing took the cell
        Recorded& r = groups_[it->second];
        if (r.drawn_in == help_job_ || r.found_by == job_key_) continue;
        r.drawn_in = help_job_;
        help_sink_.add(r.group);
    }
    seen_.clear();
}

void TileJobs::help_coverage(std::vector<std::uint8_t>& covered, const PixelRect& rect) {
    draw_seen_groups();
    help_sink_.coverage(covered, rect);
    if (!earlier_cover_) return;
    for (int y = 0; y < rect.height; ++y)
        for (int x = 0; x < rect.width; ++x) {
            const auto from = static_cast<std::size_t>((rect.y + y) * help_width_ + rect.x + x);
            covered[static_cast<std::size_t>(y * rect.width + x)] |= (*earlier_cover_)[from];
        }
}

TileJobs::Outcome TileJobs::run(const JobMsg& job, int rank) {
    const double c0 = thread_cpu_seconds();
    job_c0_ = c0;
    job_measure_cpu_ = 0;
    job_beyond0_ = frame_->workers().beyond_s;
    job_rect_ = job.rect;
    Outcome out;
    out.done.generation = job.generation;
    out.done.job = job.job;
    out.done.start_s = wall_now_s();
    const bool own = job.owner == rank;
    const FrameView view = own ? own_ : region_view(job.view, job.rect);
    const PixelRect region = own ? job.rect : view.screen();
    const RegionKey key = std::make_tuple(job.owner, job.rect.x, job.rect.y);
    job_key_ = key;
    auto it = cursors_.find(key);
    if (it == cursors_.end()) it = cursors_.emplace(key, frame_->cursor(view, region)).first;
    RegionCursor& cursor = it->second;

    if (!own) {
        ++help_job_;
        seen_.clear();
        help_sink_.begin(view);
        const auto earlier = band_cover_.find(key);
        earlier_cover_ = earlier == band_cover_.end() ? nullptr : &earlier->second;
        help_width_ = view.width;
    }
    JobSink sink(*this, own ? nullptr : &help_sink_);
    in_own_job_ = own;
    // The coarse band is a share of the rays the region will cast (its masked pixels).
    const std::size_t limit =
        job.band == Band::coarse ? std::max<std::size_t>(1, cursor.pixels / 16) : SIZE_MAX;
    const TimelineSample before = frame_->now();
    out.completed = frame_->cast(view, cursor, sink.output(), limit);
    in_own_job_ = false;
    const TimelineSample& after = frame_->now();
    out.done.rays = after.rays - before.rays;
    out.done.groups = after.groups - before.groups;
    out.done.triangles = after.triangles - before.triangles;
    if (out.completed && !own) out.result = help_result(job, key);
    // The emulated clock of a rank is its busy CPU: what it would have spent on a core of its own.
    out.done.cpu_s = job_cpu_s(thread_cpu_seconds());
    busy_cpu_s_ += out.done.cpu_s;
    out.done.cpu_end_s = busy_cpu_s_;
    if (out.result) out.result->cpu_end_s = busy_cpu_s_;
    out.done.end_s = wall_now_s();
    wall_end_ = out.done.end_s;
    last_draw_s_ = busy_cpu_s_;
    // The measurement's read-back is not part of the job (nor of the emulated clock).
    if (out.completed && own && measure_) {
        if (TraceRecorder* t = engine_.options().trace) t->switch_to(Stage::setup);
        Image img;
        tile_sink_.read_back(img, job.rect);
        shots_.push_back({busy_cpu_s_, job.rect, std::move(img), true});
    }
    return out;
}

RegionMsg TileJobs::help_result(const JobMsg& job, const RegionKey& key) {
    // The engine leaves its trace in intersection: the result's drawing and read-back are
    // render.
    if (TraceRecorder* t = engine_.options().trace) t->switch_to(Stage::render);
    draw_seen_groups();
    Image img;
    help_sink_.read_back(img);
    if (job.band == Band::coarse) {
        std::vector<std::uint8_t>& cover = band_cover_[key];
        cover.resize(img.depth.size());
        for (std::size_t i = 0; i < cover.size(); ++i) cover[i] = img.depth[i] < 1.0f;
    }
    // Only what the job drew goes to the owner: the box of the pixels it covers (one
    // background pixel when it covers none, as a region message is never empty). Pixels
    // outside it are background, which compositing by depth leaves as they are.
    PixelRect box = covered_box(img);
    if (box.width <= 0 || box.height <= 0) box = {0, 0, 1, 1};
    if (box.width != img.width || box.height != img.height) img = crop(img, box);
    RegionMsg r;
    r.generation = job.generation;
    r.job = job.job;
    r.rect = {job.rect.x + box.x, job.rect.y + box.y, box.width, box.height};
    r.rgba = std::move(img.rgba);
    r.depth = std::move(img.depth);
    return r;
}

void TileJobs::land(RegionMsg m) {
    const double c0 = thread_cpu_seconds();
    const PixelRect rect = m.rect;
    const double cpu_end_s = m.cpu_end_s;
    Image img = region_image(std::move(m), own_.width, own_.height);
    composite_by_depth(landed_, img, rect);
    landed_any_ = true;
    busy_cpu_s_ += thread_cpu_seconds() - c0;
    if (measure_) shots_.push_back({cpu_end_s, rect, std::move(img), false});
}

Image TileJobs::image() {
    Image img;
    tile_sink_.read_back(img);
    if (landed_any_) composite_by_depth(img, landed_, own_.screen());
    return img;
}

std::vector<CurvePoint> TileJobs::curve(std::uint64_t& significant) {
    std::stable_sort(shots_.begin(), shots_.end(),
                     [](const Shot& a, const Shot& b) { return a.emulated_s < b.emulated_s; });
    Image own;
    own.resize(own_.width, own_.height);
    Image helped = own, shown = own;
    // Each shot changes its rect only: the measure follows it there (CorrectnessTracker).
    CorrectnessTracker tracker(image());
    std::vector<CurvePoint> out;
    significant = tracker.now().significant;
    for (const Shot& s : shots_) {
        if (s.own)
            place(own, s.image, s.rect);
        else
            composite_by_depth(helped, s.image, s.rect);
        // What the tile shows over the shot's rect: its own drawing with the landed results
        // over it by depth, as image() composites them.
        const PixelRect r = intersect(s.rect, own_.screen());
        Image part = crop(own, r);
        composite_by_depth(part, crop(helped, r), {0, 0, r.width, r.height});
        place(shown, part, r);
        tracker.update(shown, r);
        const Correctness c = tracker.now();
        const double n = static_cast<double>(c.significant);
        out.push_back({s.emulated_s, static_cast<std::uint64_t>(std::llround(c.final_pixels * n)),
                       tracker.error_squared_sum()});
    }
    // The crops above miss what later jobs drew outside their own regions; once this rank's last
    // job and the last helper's result are in, the tile shows its final image.
    double end_s = last_draw_s_;
    for (const Shot& s : shots_) end_s = std::max(end_s, s.emulated_s);
    out.push_back({end_s, significant, 0.0});
    return out;
}

}  // namespace isowall
