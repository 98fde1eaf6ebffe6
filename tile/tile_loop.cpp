#include "tile/tile_loop.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/pacer.h"
#include "core/util.h"
#include "progressive/trace.h"
#include "tile/layered_jobs.h"
#include "tile/store_client.h"
#include "tile/tile_inbox.h"
#include "tile/tile_receiver.h"

namespace isowall {
namespace {

// How often the frame thread tells the master how far it is.
constexpr double kProgressIntervalS = 0.05;

class TileRank {
  public:
    TileRank(Comm& comm, TileSetup& setup)
        : comm_(comm),
          setup_(setup),
          jobs_(LayeredJobsSetup{&setup.extractor, setup.renderer, setup.help_renderer, options(),
                                 setup.make_renderer, setup.measure}) {
        for (FrameShow* f : setup.shows) shows_.push_back({f, PresentPacer(f->interval_s())});
    }

    int run() {
        if (setup_.tile_width > 0) jobs_.prepare(setup_.tile_width, setup_.tile_height);
        send_message(
            comm_, kMasterRank,
            TileHelloMsg{comm_.host(),
                         static_cast<std::uint32_t>(std::max(1, setup_.engine.threads)), true});
        Receiver receiver(comm_, inbox_, setup_.timeout_s, setup_.store_client);
        bool quit = false;
        for (;;) {
            trace_.switch_to(Stage::idle);
            show_pending();
            std::optional<Message> m = inbox_.pop();
            trace_.switch_to(Stage::comm);
            charge_io();
            charge_comm(receiver);
            if (!m) {
                // snapshot requests only: answered below
            } else if (auto* v = std::get_if<ViewMsg>(&*m)) {
                begin(*v);
            } else if (auto* j = std::get_if<JobMsg>(&*m)) {
                if (!quit) job(*j);
            } else if (auto* r = std::get_if<RegionMsg>(&*m)) {
                if (!quit) land(std::move(*r));
            } else if (auto* a = std::get_if<CurveAskMsg>(&*m)) {
                if (!quit) answer_curve(a->generation);
            } else if (std::holds_alternative<QuitMsg>(*m)) {
                raise_test_signal(setup_.fault, FaultMoment::gather);
                quit = true;
                send_result();
                send_image();
            } else if (std::holds_alternative<ReleaseMsg>(*m) && quit) {
                comm_.ending();
                raise_test_signal(setup_.fault, FaultMoment::end);
                return 0;
            } else {
                throw WireError(std::string("a tile does not take ") + to_string(tag_of(*m)) +
                                " messages" + (quit ? " after quit" : ""));
            }
            // A view first, snapshots after: a request that came with the view is about that
            // view's frame (answered from it in flight), never about the frame before it, which
            // before the first view is the renderer's 16x16 warm-up.
            if (jobs_.started()) answer_snapshots();
        }
    }

  private:
    // What the volume's pager threads spent since the last charge, into the trace's io stage.
    void charge_io() {
        if (!setup_.io_cpu_s) return;
        const double now = setup_.io_cpu_s();
        trace_.charge(Stage::io, now - io_charged_s_);
        io_charged_s_ = now;
    }

    // What the communication thread spent since the last charge, into the trace's comm stage:
    // every CPU second of the rank is counted, not only the frame thread's.
    void charge_comm(Receiver& r) {
        const double now = std::max(comm_charged_s_, r.cpu_s());
        trace_.charge(Stage::comm, now - comm_charged_s_);
        comm_charged_s_ = now;
    }

    EngineOptions options() {
        EngineOptions opt = setup_.engine;
        // Every sample point: the measurement's shots want them; progress messages go out
        // every kProgressIntervalS.
        opt.progress_interval_s = setup_.measure ? 0.0 : kProgressIntervalS;
        // A window shows the frame as often as its display refreshes, so the engine stops by
        // that often (progress messages still go out every kProgressIntervalS).
        for (const FrameShow* f : setup_.shows)
            opt.progress_interval_s = std::min(opt.progress_interval_s, f->interval_s());
        if (setup_.fault.action == FaultAction::slow) opt.progress_interval_s = 0;
        opt.trace = &trace_;
        return opt;
    }

    void begin(const ViewMsg& v) {
        if (setup_.fault.action == FaultAction::hang) inbox_.wait_closed();
        if (setup_.fault.action == FaultAction::exit) std::_Exit(3);
        if (setup_.fault.action == FaultAction::throw_error)
            throw std::runtime_error("test fault: a tile throws");
        raise_test_signal(setup_.fault, FaultMoment::frame);
        if (first_view_ != 0 && v.generation != first_view_)
            raise_test_signal(setup_.fault, FaultMoment::next);
        if (first_view_ == 0) first_view_ = v.generation;
        keep_curve();
        close_frame();
        use_step(v.step);
        // Setting up the frame (its engine frame, the tile's image cleared) is part of the frame's
        // busy CPU (TileJobs::begin), so it is render here, not comm; with compute slots it holds
        // one, as a job does (the engine frame starts its first stages), or goes on without one
        // when a newer view is already waiting.
        const SlotHold hold(setup_.slots, inbox_.stop_flag());
        trace_.switch_to(Stage::render);
        jobs_.begin(v, inbox_.stop_flag(), [&](const TimelineSample& s) {
            if (setup_.fault.action == FaultAction::slow)
                std::this_thread::sleep_for(std::chrono::duration<double>(TestFault::kSlowSampleS));
            if (setup_.measure) {
                // The measurement's copy is outside every figure: charged to setup, not to the
                // engine stage it interrupts (a whole tile's copy every 2 ms of busy CPU was 1.3 s
                // of "intersection" on a one-tile head).
                jobs_.present_own();
                const Stage left = trace_.switch_to(Stage::setup);
                jobs_.measure_point();
                trace_.switch_to(left);
            }
            changed(/*in_job=*/true);
            if (s.time_s - last_progress_s_ < kProgressIntervalS) return;
            last_progress_s_ = s.time_s;
            const Stage left = trace_.switch_to(Stage::comm);
            send_message(comm_, kMasterRank,
                         ProgressMsg{jobs_.generation(), jobs_.now().rays,
                                     thread_cpu_seconds() - cpu0_ + jobs_.workers_beyond_s()});
            answer_snapshots();
            trace_.switch_to(left);
        });
        trace_.switch_to(Stage::comm);
        last_progress_s_ = -1;
        cpu0_ = thread_cpu_seconds();
        ++result_.frames;
        land_early();
    }

    // The volume of time step `step` for the frames from now on.
    void use_step(std::uint32_t step) {
        if (step == step_) return;
        if (!setup_.step_extractor)
            throw WireError("view message: step " + std::to_string(step) +
                            ": the volume has one time step");
        jobs_.use_extractor(setup_.step_extractor(step));
        step_ = step;
    }

    // With --measure, the curve of the frame a new view ends against what the tile shows now (final
    // when the master saw the frame complete, the only ones it uses); outside every figure.
    void keep_curve() {
        if (!setup_.measure || !jobs_.started()) return;
        result_.earlier.push_back(current_curve());
    }

    // The current frame's curve against what the tile shows now; outside every figure. A frame
    // whose curve the master asked for is complete (its image changes no more until the next
    // view), so that curve is the one kept: it is measured once.
    FrameCurve current_curve() {
        if (answered_ && answered_->generation == jobs_.generation()) return *answered_;
        const Stage left = trace_.switch_to(Stage::setup);
        FrameCurve f;
        f.generation = jobs_.generation();
        f.points = jobs_.curve(f.significant);
        trace_.switch_to(left);
        return f;
    }

    // The master saw frame `generation` complete (--measure): its curve now, so the wall's
    // C = 99% is known while it runs. A tile already on another frame says nothing.
    void answer_curve(std::uint64_t generation) {
        if (!setup_.measure || !jobs_.started() || jobs_.generation() != generation) return;
        answered_ = current_curve();
        send_message(comm_, kMasterRank, CurveMsg{*answered_});
    }

    // The figures of the frame that ends (a new view or quit).
    void close_frame() {
        if (!jobs_.started()) return;
        result_.cpu_s += jobs_.busy_cpu_s();
        result_.frame_s += jobs_.frame_wall_s();
        result_.rays += jobs_.now().rays;
        result_.groups += jobs_.now().groups;
        result_.triangles = jobs_.now().triangles;
        if (interrupted_) ++result_.interrupted;
        interrupted_ = false;
    }

    void job(const JobMsg& j) {
        // Jobs of an older frame are dropped: the master no longer counts on them.
        if (!jobs_.started() || j.generation != jobs_.generation()) return;
        if (j.owner != comm_.rank()) raise_test_signal(setup_.fault, FaultMoment::migration);
        // A job starts by setting up its region (the help image and the groups that may show in
        // it: render work) before the engine's stages take over.
        LayeredJobs::Outcome out;
        {
            // With compute slots (--emulate-cores), the job runs while it holds one; a view that
            // comes while the rank waits for it ends the wait, as it would end the job.
            const SlotHold hold(setup_.slots, inbox_.stop_flag());
            trace_.switch_to(Stage::render);
            if (hold.ok()) out = jobs_.run(j, comm_.rank());
            trace_.switch_to(Stage::comm);
        }
        if (!out.completed) {
            interrupted_ = true;
            return;
        }
        if (!out.results.empty()) {
            trace_.switch_to(Stage::send);
            const double c0 = thread_cpu_seconds();
            std::vector<std::vector<std::byte>> encoded;
            for (const RegionMsg& r : out.results) {
                encoded.push_back(encode(r));
                out.done.bytes += encoded.back().size();
            }
            result_.bytes_sent += out.done.bytes;
            ++result_.jobs_helped;
            if (setup_.fault.action == FaultAction::late && j.generation == first_view_) {
                // The `late` test fault: the master learns the job is done, and its result
                // leaves only once a newer view is here, as from a helper that finished the old
                // view's job just after the change (a late result the owner must drop).
                send_message(comm_, kMasterRank, out.done);
                inbox_.wait_interrupt();
                for (auto& bytes : encoded) comm_.send(j.deliver, Tag::region, std::move(bytes));
                trace_.switch_to(Stage::comm);
                return;
            }
            for (auto& bytes : encoded) comm_.send(j.deliver, Tag::region, std::move(bytes));
            jobs_.add_busy(thread_cpu_seconds() - c0);  // sending is part of the job
            trace_.switch_to(Stage::comm);
        } else {
            ++result_.jobs_own;
        }
        send_message(comm_, kMasterRank, out.done);
        changed(/*in_job=*/false);
    }

    // A helper's result can overtake the master's view of its frame (they come from different
    // ranks): one of a newer frame waits for that view; one of an older frame is dropped.
    void land(RegionMsg r) {
        if (!jobs_.started() || r.generation > jobs_.generation()) {
            early_.push_back(std::move(r));
            return;
        }
        if (r.generation != jobs_.generation()) {
            ++result_.late_dropped;  // its view was replaced: the master no longer counts on it
            return;
        }
        const LandedMsg landed{r.generation, r.job};
        trace_.switch_to(Stage::compose);
        const bool whole = jobs_.land(std::move(r));  // every surface's result of the job
        trace_.switch_to(Stage::comm);
        if (whole) send_message(comm_, kMasterRank, landed);
        changed(/*in_job=*/false);
    }

    // What the tile shows changed: each show whose pacer allows it gets the frame now; the others
    // keep the change pending. Inside a job its CPU is left out of the job's.
    void changed(bool in_job) {
        if (shows_.empty() || !jobs_.started()) return;
        const double now = shown_clock_.seconds();
        std::vector<FrameShow*> due;
        for (Shown& s : shows_)
            if (s.pacer.changed(now)) due.push_back(s.show);
        show_to(due, in_job);
    }

    // Before the frame thread waits for work: pending changes are shown when due, so the last
    // change of a frame reaches every show even when no more work comes. What is due is shown
    // before the inbox is looked at, so messages coming faster than a refresh cannot hold it.
    void show_pending() {
        for (;;) {
            const double now = shown_clock_.seconds();
            std::vector<FrameShow*> due;
            for (Shown& s : shows_)
                if (s.pacer.due(now)) due.push_back(s.show);
            show_to(due, false);
            double wait = -1;
            for (const Shown& s : shows_)
                if (s.pacer.pending()) {
                    const double w = s.pacer.wait_s(shown_clock_.seconds());
                    wait = wait < 0 ? w : std::min(wait, w);
                }
            if (wait < 0 || inbox_.wait_for(wait)) return;
        }
    }

    void show_to(const std::vector<FrameShow*>& due, bool in_job) {
        if (due.empty()) return;
        const Stage left = trace_.switch_to(Stage::show);
        const double c0 = thread_cpu_seconds();
        const Image img = jobs_.image();
        for (FrameShow* f : due) f->show(img, jobs_.generation());
        if (in_job) jobs_.exclude_cpu(thread_cpu_seconds() - c0);
        trace_.switch_to(left);
    }

    void land_early() {
        std::vector<RegionMsg> waiting;
        waiting.swap(early_);
        for (RegionMsg& r : waiting) land(std::move(r));
    }

    void answer_snapshots() {
        for (int n = inbox_.take_snapshots(); n > 0; --n) send_image();
    }

    void send_image() {
        Image img = jobs_.started() ? jobs_.image() : Image{};
        ImageMsg m;
        m.generation = jobs_.generation();
        m.width = img.width;
        m.height = img.height;
        m.rgba = std::move(img.rgba);
        send_message(comm_, kMasterRank, m);
    }

    void send_result() {
        if (setup_.measure && jobs_.started()) {
            FrameCurve last = current_curve();
            result_.curve = std::move(last.points);
            result_.significant = last.significant;
        }
        close_frame();
        result_.host = comm_.host();
        result_.rss_mib = current_rss_mib();
        trace_.close();
        result_.spans = trace_.spans();
        send_message(comm_, kMasterRank, result_);
    }

    Comm& comm_;
    TileSetup& setup_;
    TraceRecorder trace_;
    LayeredJobs jobs_;
    TileInbox inbox_;
    TileResultMsg result_;
    std::optional<FrameCurve> answered_;  // the curve sent for a complete frame (--measure)
    std::vector<RegionMsg> early_;        // helpers' results that came before their frame's view
    struct Shown {
        FrameShow* show;
        PresentPacer pacer;
    };
    std::vector<Shown> shows_;
    Stopwatch shown_clock_;
    double cpu0_ = 0, last_progress_s_ = -1;
    std::uint64_t first_view_ = 0;  // the generation of the first view (the `late` test fault)
    std::uint32_t step_ = 0;        // the time step whose volume the frames draw
    double io_charged_s_ = 0, comm_charged_s_ = 0;
    bool interrupted_ = false;
};

}  // namespace

int run_tile(Comm& comm, TileSetup& setup) {
    return TileRank(comm, setup).run();
}

}  // namespace isowall
