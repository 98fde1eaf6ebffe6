#include "engine/frame_run.h"

namespace isowall {

using frame_run::kPollS;
using frame_run::kRefreshS;

// One level over `n` threads (engine/parallel_level.h); false when the frame was stopped.
// With `seeds`, the level is those seeds instead of the order's pixels (seed_frontier).
bool FrameRun::cast_level_parallel(int n, IntersectMode mode, bool second_pass, int level,
                                   const std::vector<BesideSeed>* seeds) {
    const std::size_t rays_before = now_.rays;
    bool begun = false;
    LevelJob job{ex_,  pixels_, {rect_.x, rect_.y}, *view_,       view_inv_,
                 mode, params_, opt_.propagation,   interrupted_, opt_.first_group_id + ids_used_,
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
