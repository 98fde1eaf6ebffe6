#include "engine/frame_run.h"

#include <algorithm>

#include <glm/matrix.hpp>

namespace isowall {

using frame_run::kPollS;
using frame_run::kRefreshS;

FrameRun::FrameRun(SurfaceExtractor& ex, const EngineOptions& opt, const FrameView& view,
                   const std::atomic<bool>& stop, const ProgressiveEngine::Progress& progress)
    : ex_(ex), opt_(opt), stop_(stop), progress_(progress) {
    begin(view);
}

RegionCursor FrameRun::cursor(const FrameView& view, const PixelRect& region) const {
    return region_cursor(view, region,
                         opt_.screen_box ? std::optional(ex_.volume().bounds()) : std::nullopt,
                         masked() ? &active_.boxes : nullptr);
}

bool FrameRun::cast(const FrameView& view, RegionCursor& c, const FrameOutput& out,
                    std::size_t ray_limit) {
    settle(true);  // a present in flight belongs to the sink of the last cast
    // The region's rays are intersection until a group, a coverage read or a present says
    // otherwise (the caller may have been in any stage: a wall job starts in render).
    stage(Stage::intersection);
    view_ = &view;
    sink_ = &out.groups;
    shown_ = out.shown;
    seen_ = out.seen;
    view_m_ = view.camera.view();
    view_inv_ = glm::inverse(view_m_);
    rect_ = c.rect;
    cursor_ = &c;
    params_ = opt_.propagation;
    params_.keep_frontier = opt_.frontier_seeds && shown_ != nullptr;
    params_.cut = in_object_space(view.clip, ex_.volume().spacing());
    if (opt_.region_clip) params_.clip = region_clip(view, c.rect, ex_.volume().spacing());
    refine_params_ = opt_.propagation;
    refine_params_.cut = params_.cut;
    if (opt_.sampled_triangles)
        params_.samples = refine_params_.samples = sample_grid(view, ex_.volume().spacing());
    if (footprint_) {  // (footprint units come with sampled_triangles only)
        // Only a frame with footprint units takes samples: the others keep no depths.
        const SampleGrid& g = params_.samples;
        if (g.clip_from_voxel != depths_clip_ || g.width != depths_width_ ||
            g.height != depths_height_) {
            depths_.reset(g.width, g.height);
            depths_clip_ = g.clip_from_voxel;
            depths_width_ = g.width;
            depths_height_ = g.height;
        }
        params_.samples.depths = refine_params_.samples.depths = &depths_;
    }
    // Saturating: a fine band's limit is SIZE_MAX, and c.rays + SIZE_MAX would wrap to below
    // c.rays, so a region's second band would cast nothing.
    const std::size_t limit = ray_limit > SIZE_MAX - c.rays ? SIZE_MAX : c.rays + ray_limit;
    while (!c.done && c.rays < limit) {
        if (!c.order) begin_order(c, opt_.order);
        const std::size_t before = now_.rays;
        const bool level = c.order->next_level(pixels_);
        if (level && !cast_level(*c.order, c.pass == 1)) {
            c.rays += now_.rays - before;
            return false;
        }
        c.rays += now_.rays - before;
        if (level) continue;
        // Approximate seeds can miss a pixel whose first active cell's triangles do not cover
        // it (Figure 2.2): a second, exact pass over every pixel restores the guarantee
        // (section 3.1.1).
        c.order.reset();
        if (c.pass == 0 && opt_.intersect == IntersectMode::approximate)
            c.pass = 1;
        else
            c.done = true;
    }
    if (c.done && !seed_beside()) return false;
    // A sample at every job's end, but no present (groups show at the next refresh: a
    // present flushes the renderer, which llvmpipe pays per call, not per triangle), unless
    // the last level's present was put off (see cast_level).
    record(true, present_due_);
    present_due_ = false;
    return true;
}

FrameResult FrameRun::finish(bool completed) {
    frame_.completed = completed;
    record(true);
    settle(true);
    frame_.rays_cast = now_.rays;
    frame_.elapsed_s = since(start_);
    return std::move(frame_);
}

void FrameRun::begin(const FrameView& view) {
    stage(Stage::setup);
    start_ = Clock::now();
    const ResolutionLevels levels =
        frame_levels(opt_, view, ex_.volume().spacing(), ex_.volume().bounds());
    footprint_ = levels.footprint;
    if (opt_.begin_extractor_frame) ex_.begin_frame(view.iso, levels);
    if (masked()) {
        active_ = screen_mask_nodes(ex_, view.iso, levels);
        frame_.mask_level = active_.level;
        frame_.mask_nodes = active_.boxes.size();
    }
    frame_.group_count = 0;
    extra_ = opt_.sample_at_rays;
    std::sort(extra_.begin(), extra_.end());
    stage(Stage::intersection);
}

int FrameRun::workers() const {
    const int have = ex_.threads();
    return std::max(1, opt_.threads <= 0 ? have : std::min(opt_.threads, have));
}

bool FrameRun::cast_level(RayOrder& order, bool second_pass) {
    const IntersectMode mode = second_pass ? IntersectMode::exact : opt_.intersect;
    const int n = workers();
    const bool parallel = n > 1 && pixels_.size() > 1;
    if (parallel) {
        if (!cast_level_parallel(n, mode, second_pass, order.level())) return false;
    } else {
        begin_level(order.level());
        for (const glm::ivec2 px : pixels_) {
            if (stopped()) return false;
            if (!cast_ray(px + glm::ivec2(rect_.x, rect_.y), mode, second_pass)) return false;
            record(false);
        }
    }
    if (order.wants_coverage() && give_coverage(order) && !seed_frontier()) return false;
    // After a level on several threads, its sample (and present, which waits for the
    // rasteriser) waits until the next level's other threads cast, or the job's end.
    present_due_ = parallel;
    if (!parallel) record(true);
    return true;
}

bool FrameRun::cast_ray(glm::ivec2 px, IntersectMode mode, bool second_pass) {
    // A pixel whose ray the clip planes cut away whole casts none; the others start at the cut.
    const auto clipped = clip_ray(
        params_.cut, pixel_ray(view_inv_, view_->frustum, view_->width, view_->height, px));
    if (!clipped) return true;
    const Ray& ray = clipped->ray;
    const auto t0 = Clock::now();
    const RayHit hit = ex_.cast(ray, mode, clipped->t_max);
    now_.t_intersect_s += since(t0);
    ++now_.rays;
    if (second_pass) ++frame_.rays_second_pass;
    // A meta-cell whose triangles miss this pixel's surface gets its full-resolution triangles
    // drawn over (adaptive resolution only); any other unvisited hit seeds a pass.
    if (hit.found) ++cursor_->hits;
    if (!hit.found) return true;
    if (!hit.refine && ex_.visited(hit.cell)) {
        if (seen_) seen_->seen(ex_.group_of(hit.cell));
        note_beside(ex_, hit, ray, px, mode == IntersectMode::exact, cursor_->beside);
        return true;
    }
    return seed(hit, ray);
}

bool FrameRun::seed_beside() {
    stage(Stage::render);
    const std::vector<BesideSeed> todo = take_still_empty(cursor_->beside, shown_, rect_, covered_);
    stage(Stage::intersection);
    return seed_all(todo);
}

bool FrameRun::seed_frontier() {
    if (!opt_.frontier_seeds) return true;
    // The cells beside hits (pinholes) go too: the fill level would reach their pixels late.
    std::vector<BesideSeed> todo = take_still_empty(cursor_->beside, rect_, covered_);
    const std::vector<BesideSeed> frontier =
        take_frontier_still_empty(cursor_->frontier, ex_, *view_, view_inv_, rect_, covered_);
    todo.insert(todo.end(), frontier.begin(), frontier.end());
    return seed_all(todo);
}

bool FrameRun::seed_all(const std::vector<BesideSeed>& todo) {
    const int n = workers();
    if (n > 1 && todo.size() > 1)
        return cast_level_parallel(n, opt_.intersect, false, now_.level, &todo);
    for (const BesideSeed& b : todo)
        if (!ex_.visited(b.cell) && (stopped() || !seed({true, b.cell}, b.ray))) return false;
    return true;
}

void FrameRun::begin_level(int level) {
    if (present_due_) record(true);
    present_due_ = false;
    now_.level = level;
}

// One level over `n` threads (engine/parallel_level.h); false when the frame was stopped.
// With `seeds`, the level is those seeds instead of the order's pixels (seed_frontier).
bool FrameRun::cast_level_parallel(int n, IntersectMode mode, bool second_pass, int level,
                                   const std::vector<BesideSeed>* seeds) {
    const std::size_t rays_before = now_.rays;
    bool begun = false;
    LevelJob job{ex_,  pixels_, {rect_.x, rect_.y}, *view_,       view_inv_,
                 mode, params_, refine_params_,     interrupted_, opt_.first_group_id + ids_used_,
                 seeds};
    job.want_seen = seen_ != nullptr;
    const double own0 = thread_cpu_seconds();
    const LevelTally t = isowall::cast_level_parallel(
        job, n, [this](FoundGroup& f) { add_found(f); },
        [this, rays_before, level, &begun](std::size_t rays) {
            now_.rays = rays_before + rays;
            if (!begun) begin_level(level);
            begun = true;
            record(false);
        });
    frame_.workers.sum_s += t.workers_cpu_s;
    frame_.workers.beyond_s +=
        std::max(0.0, t.busiest_worker_cpu_s - (thread_cpu_seconds() - own0));
    if (opt_.trace) opt_.trace->add_cpu(t.workers_cpu_s);
    ids_used_ = t.next_id - opt_.first_group_id;
    cursor_->beside.insert(cursor_->beside.end(), t.beside.begin(), t.beside.end());
    // After the level's rays and before its coverage is read (cast_level), as the sink allows.
    if (seen_)
        for (const std::uint32_t id : t.seen) seen_->seen(id);
    now_.t_intersect_s += t.intersect_s;
    cursor_->hits += t.hits;
    if (second_pass) frame_.rays_second_pass += t.rays;
    now_.rays = rays_before + t.rays;
    return !stopped();
}

bool FrameRun::add_found(FoundGroup& f) {
    Group& g = f.group;
    keep_frontier(*cursor_, g.frontier, ex_);
    now_.t_extract_s += f.extract_s;
    now_.t_propagate_s += f.pass_s - f.extract_s;
    if (g.refinement ? g.mesh.indices.empty() : g.cells.empty()) return false;
    stage(Stage::render);
    const auto t1 = Clock::now();
    if (cursor_->sizing) add_drawn(*cursor_, g.mesh, view_m_, *view_);
    if (opt_.colour) opt_.colour(g.mesh);
    sink_->add(g);
    now_.t_render_s += since(t1);
    dirty_ = true;
    now_.triangles += g.mesh.triangle_count();
    ++frame_.group_count;
    stage(Stage::intersection);
    return true;
}

bool FrameRun::seed(const RayHit& hit, const Ray& ray) {
    stage(Stage::propagation);
    const auto t0 = Clock::now();
    const auto id = opt_.first_group_id + ids_used_;
    FoundGroup f;
    f.group = hit.refine ? ex_.refine(hit.cell, hit.level, id, opt_.propagation)
                         : ex_.propagate(hit.cell, id, params_, ray, interrupted_);
    f.pass_s = since(t0);
    // Extraction is timed on 1 unit in 16 and scaled: the estimate may overshoot a short pass.
    f.extract_s = std::min(ex_.last_extract_s(), f.pass_s);
    if (stopped()) {
        now_.t_extract_s += f.extract_s;
        now_.t_propagate_s += f.pass_s - f.extract_s;
        return false;
    }
    ids_used_ += add_found(f) ? 1 : 0;
    stage(Stage::intersection);
    return true;
}

bool FrameRun::give_coverage(RayOrder& order) {
    // Before any ray of the region has met the surface, what shows there is at most the edge
    // of a group found elsewhere: the order is left searching, which saves a read-back (a
    // renderer flush) and a screen-sized copy per level in every region of background.
    if (cursor_->hits == 0) return false;
    stage(Stage::render);
    const auto t0 = Clock::now();
    const bool read = give_order_coverage(order, *cursor_, shown_, covered_);
    now_.t_render_s += since(t0);
    stage(Stage::intersection);
    return read;
}

// A timeline sample, after ray counts growing by a factor and at least every interval.
void FrameRun::record(bool force, bool present_now) {
    if (pending_ && since(start_) - last_poll_s_ >= kPollS) settle(false);
    now_.time_s = since(start_);  // after a sample settle() kept
    while (next_extra_ < extra_.size() && extra_[next_extra_] < now_.rays) ++next_extra_;
    if (next_extra_ < extra_.size() && extra_[next_extra_] == now_.rays) force = true;
    if (!force && now_.rays < next_sample_rays_ &&
        now_.time_s - last_sample_s_ < opt_.sample_interval_s)
        return;
    // A sample waiting for its groups to show goes first: no later one passes it.
    if (pending_ && !force) return;
    if (settle(true)) now_.time_s = since(start_);
    // The sample shows what is on screen: queued groups are presented as a display would at
    // its next refresh (paced by this thread's CPU clock, a rank's wall clock on a core of
    // its own), so between refreshes a sample may count groups in flight. A sink presenting
    // without waiting (a fence) lets this thread cast on: the sample waits in pending_
    // until its groups show, which is then its time.
    const double cpu = thread_cpu_seconds();
    bool in_flight = false;
    if (dirty_ && sink_ && ((force && present_now) || cpu - last_present_cpu_s_ >= kRefreshS)) {
        stage(Stage::render);
        const auto t0 = Clock::now();
        in_flight = sink_->present_async();
        now_.t_render_s += in_flight ? since(t0) : sink_->present();
        stage(Stage::intersection);
        now_.time_s = since(start_);
        last_present_cpu_s_ = thread_cpu_seconds();
        dirty_ = false;
    }
    now_.cells_visited = ex_.visited_count();
    now_.groups = frame_.group_count;
    last_sample_s_ = last_poll_s_ = now_.time_s;
    while (next_sample_rays_ <= now_.rays)
        next_sample_rays_ =
            std::max(next_sample_rays_ + 1,
                     static_cast<std::size_t>(double(next_sample_rays_) * opt_.sample_ray_factor));
    if (in_flight)
        pending_ = now_;
    else
        push(now_);
}

// The sample of a present in flight, timed and kept once its groups show (`wait`: now);
// true when it was kept.
bool FrameRun::settle(bool wait) {
    if (!pending_) return false;
    last_poll_s_ = since(start_);
    if (!sink_->presented(wait)) return false;
    pending_->time_s = since(start_);
    push(*pending_);
    pending_.reset();
    return true;
}

void FrameRun::push(const TimelineSample& s) {
    frame_.timeline.push_back(s);
    if (progress_ && s.time_s - last_progress_s_ >= opt_.progress_interval_s) {
        last_progress_s_ = s.time_s;
        progress_(s);
    }
}

}  // namespace isowall
