#include "engine/parallel_level.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

#include "core/ray.h"
#include "engine/beside_seeds.h"
#include "progressive/trace.h"

namespace isowall {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// One thread's share of a level, written by that thread only; cache lines of its own, so one
// thread's counts do not evict the other's at every ray.
struct alignas(64) WorkerTally {
    std::size_t rays = 0, hits = 0;
    double intersect_s = 0, cpu_s = 0;
    std::size_t next = 0, end = 0;  // the pixels claimed and not cast yet
    std::vector<BesideSeed> beside;
    std::vector<std::uint32_t> seen;  // LevelJob::want_seen
    // `rays` as of the thread's last claim, for the caller's samples: a line the caller reads at
    // every one of its rays, which this thread writes once per claim, not once per ray.
    alignas(64) std::atomic<std::size_t> published{0};
};

// The most pixels a thread claims at once. Claiming one pixel per ray bounced one counter's cache
// line between the cores at every ray (about a microsecond each); claims shrink towards the end
// of a level, so no thread is left with a long tail.
constexpr std::size_t kMaxClaim = 32;

// The state the threads of one level share.
class LevelCast {
  public:
    LevelCast(const LevelJob& job, int threads)
        : job_(job),
          threads_(static_cast<std::size_t>(threads)),
          next_id_(job.first_id),
          next_drawn_(job.first_id),
          running_(threads - 1),
          tally_(static_cast<std::size_t>(threads)) {}

    // Casts the next pixel's ray on worker w (and propagates); false when the level has no more.
    bool step(int w) {
        WorkerTally& t = tally_[static_cast<std::size_t>(w)];
        if (t.next == t.end) {
            t.published.store(t.rays, std::memory_order_relaxed);
            if (!claim(t)) return false;
        }
        if (failed_.load(std::memory_order_relaxed) || job_.stopped()) return false;
        const std::size_t i = t.next++;
        RayHit hit;
        Ray ray;
        if (job_.seeds) {
            const BesideSeed& s = (*job_.seeds)[i];
            if (job_.ex.visited(s.cell)) return true;  // an earlier seed's pass took it
            hit = {true, s.cell};
            ray = s.ray;
        } else {
            const glm::ivec2 px = job_.pixels[i] + job_.origin;
            // As FrameRun::cast_ray: no ray where the clip planes cut it away whole.
            const auto clipped =
                clip_ray(job_.params.cut, pixel_ray(job_.view_inverse, job_.view.frustum,
                                                    job_.view.width, job_.view.height, px));
            if (!clipped) return true;
            ray = clipped->ray;
            const auto t0 = Clock::now();
            hit = job_.ex.cast_on(w, ray, job_.mode, clipped->t_max);
            t.intersect_s += since(t0);
            ++t.rays;
            if (!hit.found) return true;
            ++t.hits;
            if (!hit.refine && job_.ex.visited(hit.cell)) {
                if (job_.want_seen) t.seen.push_back(job_.ex.group_of(hit.cell));
                note_beside(job_.ex, hit, ray, px, job_.mode == IntersectMode::exact, t.beside);
                return true;
            }
        }
        const std::uint32_t id = next_id_.fetch_add(1, std::memory_order_relaxed);
        FoundGroup f;
        const auto t1 = Clock::now();
        f.group = hit.refine
                      ? job_.ex.refine_on(w, hit.cell, hit.level, id, job_.refine_params)
                      : job_.ex.propagate_on(w, hit.cell, id, job_.params, ray, job_.stopped);
        f.pass_s = since(t1);
        f.extract_s = std::min(job_.ex.last_extract_s_on(w), f.pass_s);  // sampled: see engine
        {
            const std::lock_guard<std::mutex> hold(lock_);
            ready_.emplace(id, std::move(f));
        }
        found_.fetch_add(1, std::memory_order_release);
        wake_.notify_all();
        return true;
    }

    // Draws the groups whose turn has come; with `all`, waits for the other workers first and
    // draws everything left.
    void draw_ready(const std::function<void(FoundGroup&)>& draw, bool all) {
        // Only an arrival makes a group drawable: with none since the last look, the caller (at
        // every one of its rays) takes no lock.
        const std::size_t found = found_.load(std::memory_order_acquire);
        if (!all && found == looked_) return;
        looked_ = found;
        std::unique_lock<std::mutex> hold(lock_);
        if (all) wake_.wait(hold, [&] { return running_ == 0; });
        while (!ready_.empty() && (all || ready_.begin()->first == next_drawn_)) {
            FoundGroup f = std::move(ready_.begin()->second);
            next_drawn_ = ready_.begin()->first + 1;
            ready_.erase(ready_.begin());
            hold.unlock();
            draw(f);
            hold.lock();
        }
    }

    void fail(std::exception_ptr e) {
        const std::lock_guard<std::mutex> hold(lock_);
        if (!failure_) failure_ = e;
        failed_.store(true);  // the others stop at their next pixel
    }

    void worker_done(int w, double cpu_s) {
        tally_[static_cast<std::size_t>(w)].cpu_s = cpu_s;
        {
            const std::lock_guard<std::mutex> hold(lock_);
            --running_;
        }
        wake_.notify_all();
    }

    // The rays cast so far: the caller's own, and the others' as of their last claims (at most
    // kMaxClaim each behind). Called on the caller's thread only.
    std::size_t rays() const {
        std::size_t n = tally_[0].rays;
        for (std::size_t w = 1; w < tally_.size(); ++w)
            n += tally_[w].published.load(std::memory_order_relaxed);
        return n;
    }

    LevelTally finish() {
        if (failure_) std::rethrow_exception(failure_);
        LevelTally sum;
        for (WorkerTally& t : tally_) {
            sum.beside.insert(sum.beside.end(), t.beside.begin(), t.beside.end());
            sum.seen.insert(sum.seen.end(), t.seen.begin(), t.seen.end());
            sum.rays += t.rays;
            sum.hits += t.hits;
            sum.intersect_s += t.intersect_s;
            sum.workers_cpu_s += t.cpu_s;
            sum.busiest_worker_cpu_s = std::max(sum.busiest_worker_cpu_s, t.cpu_s);
        }
        sum.next_id = next_id_.load();
        return sum;
    }

  private:
    // Takes the next pixels of the level for `t`: an eighth of each thread's share of what is
    // left, 1 to kMaxClaim. False when none is left.
    bool claim(WorkerTally& t) {
        const std::size_t n = job_.size();
        std::size_t i = next_pixel_.load(std::memory_order_relaxed);
        for (;;) {
            if (i >= n) return false;
            const std::size_t take =
                std::clamp<std::size_t>((n - i) / (8 * threads_), 1, kMaxClaim);
            if (next_pixel_.compare_exchange_weak(i, i + take, std::memory_order_relaxed)) {
                t.next = i;
                t.end = i + take;
                return true;
            }
        }
    }

    // Read at every ray: a cache line that no thread writes while the level goes well.
    const LevelJob& job_;
    const std::size_t threads_;
    std::atomic<bool> failed_{false};
    // Written once per claim.
    alignas(64) std::atomic<std::size_t> next_pixel_{0};
    // Written once per pass: ids handed out and groups found; looked_ is the caller's.
    alignas(64) std::atomic<std::uint32_t> next_id_;
    std::atomic<std::size_t> found_{0};
    std::size_t looked_ = 0;
    alignas(64) std::uint32_t next_drawn_;  // under lock_
    std::mutex lock_;
    std::condition_variable wake_;
    std::map<std::uint32_t, FoundGroup> ready_;  // by id, under lock_
    int running_;                                // other threads still casting, under lock_
    std::exception_ptr failure_;                 // under lock_
    std::vector<WorkerTally> tally_;             // one per thread, each written by its own
};

}  // namespace

LevelTally cast_level_parallel(const LevelJob& job, int threads,
                               const std::function<void(FoundGroup&)>& draw,
                               const std::function<void(std::size_t)>& between_rays) {
    LevelCast level(job, threads);
    std::vector<std::thread> others;
    others.reserve(static_cast<std::size_t>(threads - 1));
    for (int w = 1; w < threads; ++w)
        others.emplace_back([&level, w] {
            const double c0 = thread_cpu_seconds();
            try {
                while (level.step(w)) {
                }
            } catch (...) {
                level.fail(std::current_exception());
            }
            level.worker_done(w, thread_cpu_seconds() - c0);
        });
    try {
        between_rays(level.rays());
        for (;;) {
            const bool more = level.step(0);
            level.draw_ready(draw, false);
            if (!more) break;
            between_rays(level.rays());
        }
    } catch (...) {
        level.fail(std::current_exception());
    }
    for (std::thread& t : others) t.join();
    level.draw_ready(draw, true);
    return level.finish();
}

}  // namespace isowall
