#include "master/wall_master.h"

#include "master/legend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/number.h"
#include "files/image_io.h"
#include "master/wall_report.h"
#include "wall_spec/eyes.h"

namespace isowall {
namespace {

// How long one receive waits before wait_until looks at its predicate and the silence again.
constexpr double kReceiveSliceS = 0.05;

}  // namespace

WallMaster::WallMaster(const MasterOptions& o, Comm& comm, const WallSpec& spec, const Box3& bounds,
                       double iso, double value_min, double value_max)
    : o_(o),
      comm_(comm),
      spec_(spec),
      bounds_(bounds),
      iso_(iso),
      lo_(value_min),
      hi_(value_max),
      order_(comm.size(), o.dispatch) {
    planner_ = RegionPlanner(o.work_boxes);
    const PixelSize vs = virtual_screen_size(spec);
    aspect_ = float(vs.width) / float(vs.height);
    camera_ = front_full_view(bounds, o.front_axes, aspect_);
    camera_ = orbit(camera_, o.orbit.first, o.orbit.second);
    camera_ = zoom(camera_, o.zoom);
    camera_ = pan(camera_, o.pan.first, o.pan.second, aspect_);
    clip_ = o.clip;
    step_ = o.first_step;
    surfaces_ = o.surfaces.empty() ? std::vector<SurfaceStyle>{SurfaceStyle{iso}} : o.surfaces;
    if (std::string p = camera_problem(camera_); !p.empty())
        throw InputError("--orbit/--zoom/--pan", "value", p);
    if (std::string p = head_problem(camera_, aspect_, spec_, head_); !p.empty())
        throw InputError(o.wall_name, "stereo", p);
    tiles_.resize(static_cast<std::size_t>(comm.size()));
    previews_.resize(tiles_.size());
}

void WallMaster::handle(const Envelope& e) {
    const Stage left = trace_.switch_to(Stage::comm);
    if (e.from < 1 || e.from >= comm_.size())
        throw std::runtime_error("a message from unknown rank " + std::to_string(e.from));
    TileState& t = tiles_[static_cast<std::size_t>(e.from)];
    if (t.lost) {  // a stopped rank let go after the wall gave up on it: it is not heard
        trace_.switch_to(left);
        return;
    }
    Message m;
    try {
        m = decode_message(e.tag, e.bytes);
    } catch (const WireError& err) {
        throw WireError(rank_label(spec_, e.from) + ": " + err.what());
    }
    t.heard.restart();
    if (auto* h = std::get_if<TileHelloMsg>(&m)) {
        t.host = h->host;
        t.threads = h->threads;
        (h->loaded ? t.hello : t.joined) = true;
    } else if (std::holds_alternative<AliveMsg>(m)) {  // its loop runs: heard is all it tells
    } else if (auto* f = std::get_if<FailedMsg>(&m)) {
        throw TileFailed(e.from, f->input, f->what);
    } else if (auto* p = std::get_if<ProgressMsg>(&m)) {
        if (p->generation == generation_ && board_) {  // older: frames that were interrupted
            t.rays = std::max(t.rays, p->rays);
            t.on_view = true;
            if (switch_s_ < 0 && generation_ > 1 &&
                all_tiles([](const TileState& s) { return s.on_view; })) {
                switch_s_ = frame_start_.seconds();
                switches_s_.push_back(switch_s_);
            }
            order_.clock(e.from, p->cpu_s);
            dispatch();
        }
    } else if (auto* reg = std::get_if<RegionMsg>(&m)) {
        land_for_lost(e.from, std::move(*reg));
    } else if (std::holds_alternative<JobDoneMsg>(m) || std::holds_alternative<LandedMsg>(m)) {
        handle_job(e.from, m);
    } else if (auto* img = std::get_if<ImageMsg>(&m)) {
        const PixelRect r = eye_rect(spec_, tile_of_rank(spec_, e.from));
        if (img->width != r.width || img->height != r.height)
            throw std::runtime_error(
                rank_label(spec_, e.from) + ": tile image of the wrong size (" +
                std::to_string(img->width) + "x" + std::to_string(img->height) + ", expected " +
                std::to_string(r.width) + "x" + std::to_string(r.height) + ")");
        t.image = std::move(*img);
    } else if (auto* pv = std::get_if<PreviewMsg>(&m)) {
        if (pv->generation == generation_) {  // an older one shows a view the wall has left
            previews_[static_cast<std::size_t>(e.from)] = std::move(*pv);
            ++previews_taken_;
        }
    } else if (auto* ask = std::get_if<StoreAskMsg>(&m)) {
        store_sent_.add(e.from, answer_store_ask(*ask, o_.store.get(), o_.store_octree), comm_);
    } else if (auto* res = std::get_if<TileResultMsg>(&m)) {
        raise_test_signal(o_.fault, FaultMoment::gather);
        t.result = std::move(*res);
    } else if (auto* c = std::get_if<CurveMsg>(&m)) {
        if (c->curve.generation == generation_ && curves_asked_) {
            TileResultMsg& r = frame_curves_.at(static_cast<std::size_t>(e.from));
            r.significant = c->curve.significant;
            r.curve = std::move(c->curve.points);
            r.frames = 1;  // came
        }
    } else {
        throw WireError(rank_label(spec_, e.from) + " sent a " + to_string(e.tag) +
                        " message, which only the master sends");
    }
    trace_.switch_to(left);
}

void WallMaster::wait_until(const std::function<bool()>& done, double timeout_s) {
    const Stage left = trace_.switch_to(Stage::idle);
    silent_.restart();  // since the last message other than alive (or a rank lost)
    while (!done()) {
        keep_alive();
        if (auto e = comm_.receive(-1, kReceiveSliceS)) {
            const bool alive = e->tag == Tag::alive;
            handle(*e);
            if (!alive) silent_.restart();
        } else if (silent_.seconds() > timeout_s + (comm_.survives_rank_loss() ? 1.0 : 0.0)) {
            // (A wall that survives a lost rank gives check_tiles, in keep_alive, a second to
            // lose a silent rank first: its alive messages may have come after the last other
            // message, and losing it restarts this clock.)
            char msg[96];
            std::snprintf(msg, sizeof(msg), "no tile rank has answered for %g s", timeout_s);
            throw std::runtime_error(std::string(msg) + " (waiting on " + waiting_on() +
                                     "); ending the job");
        }
    }
    trace_.switch_to(left);
}

void WallMaster::wait_for_tiles(const std::function<bool(const TileState&)>& pred,
                                double timeout_s) {
    awaited_ = pred;
    wait_until([&] { return all_tiles(pred); }, timeout_s);
    awaited_ = nullptr;
}

void WallMaster::keep_alive() {
    // Called every few tens of milliseconds while the master waits; a far longer gap means the
    // master itself was stopped (SIGSTOP, a debugger) and has just been let go, and the tiles'
    // silence meanwhile is not theirs: their clocks start again.
    if (alive_checked_.seconds() > o_.timeout_s / 2)
        for (TileState& t : tiles_) t.heard.restart();
    alive_checked_.restart();
    check_tiles();
    if (alive_sent_.seconds() < kAliveIntervalS) return;
    alive_sent_.restart();
    for (int rank = 1; rank < comm_.size(); ++rank) {
        const TileState& t = tiles_[static_cast<std::size_t>(rank)];
        if (t.joined && !t.lost) send_message(comm_, rank, AliveMsg{});
    }
}

void WallMaster::check_tiles() {
    for (int rank = 1; rank < comm_.size(); ++rank) {
        const TileState& t = tiles_[static_cast<std::size_t>(rank)];
        if (!t.hello || t.lost) continue;  // not yet taking views, or given up on
        // A wall that survives a lost rank sees one on its own host go at once; elsewhere its
        // silence gives it away.
        if (comm_.survives_rank_loss() && comm_.peer_gone(rank)) {
            lose(rank, "its process has ended");
            continue;
        }
        if (t.heard.seconds() > o_.timeout_s) {
            char why[120];
            std::snprintf(why, sizeof(why),
                          "has sent nothing for %g s (--timeout): it has stopped, or its host "
                          "cannot be reached",
                          o_.timeout_s);
            if (comm_.survives_rank_loss() && !gathering_) {
                lose(rank, why);
                continue;
            }
            throw std::runtime_error(rank_label(spec_, rank) + " on " + t.host + " " + why +
                                     "; ending the job");
        }
    }
}

void WallMaster::idle() {
    keep_alive();
    while (auto e = comm_.receive(-1, 0)) handle(*e);
    play_on();
}

void WallMaster::print_switches() const {
    if (switches_s_.empty()) return;
    std::vector<double> s = switches_s_;
    std::sort(s.begin(), s.end());
    std::printf(
        "view changes: %zu; every tile had cast a ray of the new view %.1f ms after the change "
        "(median), %.1f ms at most\n",
        s.size(), 1e3 * s[(s.size() - 1) / 2], 1e3 * s.back());
}

void WallMaster::play_on() {
    if (!playing_ || !frame_done() || (o_.measure && !curves_in())) return;
    const FrameFigures f = frame_figures();
    std::printf("time %u: frame %llu done in %.3f s, emulated %.3f s", step_,
                static_cast<unsigned long long>(generation_), frame_start_.seconds(), f.emulated_s);
    if (f.c99_s >= 0) std::printf(", C = 99%% at %.3f s", f.c99_s);
    if (switch_s_ >= 0) std::printf("; every tile on it %.1f ms after the change", 1e3 * switch_s_);
    std::printf("\n");
    std::fflush(stdout);
    if (step_ + 1 < o_.steps) {
        ++step_;
    } else if (loop_) {
        step_ = 0;
    } else {
        playing_ = false;
        return;
    }
    send_views();
}

bool WallMaster::all_tiles(const std::function<bool(const TileState&)>& pred) const {
    for (std::size_t rank = 1; rank < tiles_.size(); ++rank)
        if (!tiles_[rank].lost && !pred(tiles_[rank])) return false;
    return true;
}

std::string WallMaster::whole_again(const TileState& t) {
    if (t.whole_after_s < 0) return "no frame was complete after it";
    char text[64];
    std::snprintf(text, sizeof(text), "a frame was complete %.2f s after it", t.whole_after_s);
    return text;
}

void WallMaster::preview_lost(int rank) {
    if (o_.preview_side <= 0) return;
    const TileState& t = tiles_[static_cast<std::size_t>(rank)];
    previews_[static_cast<std::size_t>(rank)] =
        PreviewMsg{make_preview(t.stand_in, generation_, o_.preview_side)};
    ++previews_taken_;
}

std::vector<std::string> WallMaster::dark_screens() const {
    std::vector<std::string> out;
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (!living(rank)) {
            const TileState& t = tiles_[static_cast<std::size_t>(rank)];
            out.push_back(tile_name(spec_, rank) + " (rank " + std::to_string(rank) + " on " +
                          t.host + "): " + t.lost_why);
        }
    return out;
}

int WallMaster::lost_count() const {
    return static_cast<int>(
        std::count_if(tiles_.begin(), tiles_.end(), [](const TileState& t) { return t.lost; }));
}

void WallMaster::lose(int rank, const std::string& why) {
    TileState& t = tiles_[static_cast<std::size_t>(rank)];
    if (gathering_)
        throw std::runtime_error(rank_label(spec_, rank) + " on " + t.host + ": " + why +
                                 ", while the outputs were gathered; ending the job");
    t.lost = true;
    t.lost_why = why;
    t.lost_at_s = run_clock_.seconds();
    t.image.reset();
    comm_.forget(rank);
    comm_.end_peer(rank);  // stopped on this host: ended, so that mpirun does not wait for it
    for (int r = 1; r < comm_.size(); ++r)
        if (living(r)) send_message(comm_, r, LostMsg{rank});
    std::fflush(stdout);
    std::fprintf(stderr,
                 "isowall: warning: %s on %s is lost (%s); the other ranks draw its screen\n",
                 rank_label(spec_, rank).c_str(), t.host.c_str(), why.c_str());
    std::fflush(stderr);
    silent_.restart();
    if (living_tiles() == 0) throw std::runtime_error("every tile rank is lost; ending the job");
    if (board_) send_views();  // the frame again, its screen as jobs of the others
}

int WallMaster::living_tiles() const {
    int n = 0;
    for (int rank = 1; rank < comm_.size(); ++rank) n += living(rank) ? 1 : 0;
    return n;
}

void WallMaster::land_for_lost(int from, RegionMsg r) {
    if (r.generation != generation_ || !board_) return;  // an interrupted frame's
    if (r.job >= board_->size())
        throw WireError(rank_label(spec_, from) + ": no job " + std::to_string(r.job) +
                        " in this frame");
    const BoardJob& j = board_->job(r.job);
    TileState& owner = tiles_[static_cast<std::size_t>(j.owner)];
    if (!owner.lost || j.worker != from || j.state == BoardJob::State::queued)
        throw WireError(rank_label(spec_, from) + " sent the master a region message for job " +
                        std::to_string(r.job) + ", whose owner is not lost");
    const Stage left = trace_.switch_to(Stage::compose);
    const PixelRect rect = r.rect;
    const std::uint8_t layer = r.layer;
    Image img;
    try {
        img = region_image(std::move(r), owner.stand_in.width, owner.stand_in.height);
    } catch (const WireError& e) {
        throw WireError(rank_label(spec_, from) + ": " + e.what());
    }
    // Each surface's result into its layer, the layers blended (core/surface_style.h); the job
    // has landed once every surface's result is in.
    if (layer >= owner.stand_in_layers.size())
        throw WireError(rank_label(spec_, from) + ": region message: layer " +
                        std::to_string(layer) + ": the view has " +
                        std::to_string(owner.stand_in_layers.size()) + " surface(s)");
    composite_by_depth(owner.stand_in_layers[layer], img, rect);
    std::vector<const Image*> layers;
    std::vector<float> opacity;
    for (std::size_t k = 0; k < owner.stand_in_layers.size(); ++k) {
        layers.push_back(&owner.stand_in_layers[k]);
        opacity.push_back(surfaces_[k].opacity);
    }
    owner.stand_in =
        layers.size() == 1 ? owner.stand_in_layers[0] : composite_layers(layers, opacity);
    std::uint32_t& in = owner.layers_in[r.job];
    in |= 1u << layer;
    if (in == (1u << layers.size()) - 1) board_->landed(r.job);
    preview_lost(j.owner);
    trace_.switch_to(left);
    ask_curves();
}

std::string WallMaster::waiting_on() const {
    std::string list;
    for (int rank = 1; rank < comm_.size(); ++rank) {
        const TileState& t = tiles_[static_cast<std::size_t>(rank)];
        if (t.lost) continue;
        const bool busy = board_ && !board_->complete() && board_->in_hand(rank) > 0;
        if (awaited_ ? !awaited_(t) : busy)
            list += (list.empty() ? "" : ", ") + rank_label(spec_, rank);
    }
    return list.empty() ? "all tiles" : list;
}

void WallMaster::start() {
    // Tiles load the volume and build their renderer before their hello: a start-up of its own
    // length, so a short --timeout for a running wall does not cut a slow load short.
    wait_for_tiles([](const TileState& t) { return t.joined; }, o_.startup_timeout_s);
    for (int rank = 1; rank < comm_.size(); ++rank) send_message(comm_, rank, StartMsg{});
    wait_for_tiles([](const TileState& t) { return t.hello; }, o_.startup_timeout_s);
    print_map();
    send_views();
    raise_test_signal(o_.fault, FaultMoment::frame);
    if (o_.fault.action == FaultAction::throw_error)
        throw std::runtime_error("test fault: the master throws");
}

void WallMaster::print_map() const {
    const PixelSize vs = virtual_screen_size(spec_);
    std::printf(
        "wall: %s: %dx%d tiles of %dx%d, virtual screen %dx%d, %d tile ranks, master on %s\n",
        o_.wall_name.c_str(), spec_.columns, spec_.rows, spec_.tile_width_px, spec_.tile_height_px,
        vs.width, vs.height, comm_.size() - 1, comm_.host().c_str());
    if (spec_.stereo)
        std::printf("stereo: %s, a rank per eye, eye separation %g %s, convergence %g\n",
                    to_string(spec_.stereo->mode).c_str(), spec_.stereo->separation,
                    spec_.physical ? "mm" : "of the wall's width", spec_.stereo->convergence);
    for (int rank = 1; rank < comm_.size(); ++rank) {
        const int tile = tile_of_rank(spec_, rank);
        const PixelRect r = tile_rect(spec_, tile);
        const PixelRect e = eye_rect(spec_, tile);
        const Eye eye = eye_of_rank(spec_, rank);
        const std::string eye_part = eye == Eye::centre ? ""
                                                        : ", " + to_string(eye) + " eye " +
                                                              std::to_string(e.width) + "x" +
                                                              std::to_string(e.height);
        const TileState& t = tiles_[static_cast<std::size_t>(rank)];
        std::printf(
            "  rank %2d on %-12s -> tile %2d (column %d, row %d) viewport x=%d y=%d %dx%d%s, %u "
            "thread%s\n",
            rank, t.host.c_str(), tile, tile % spec_.columns, tile / spec_.columns, r.x, r.y,
            r.width, r.height, eye_part.c_str(), t.threads, t.threads == 1 ? "" : "s");
    }
    std::fflush(stdout);
}

// A new frame on every tile: bumps the generation, so progress and results of older frames are
// ignored, cuts the screen into jobs and hands every rank its first ones.
void WallMaster::send_views() {
    const Stage left = trace_.switch_to(Stage::comm);
    if (board_ && board_->complete()) completed_.push_back(generation_);
    ++generation_;
    for (int rank = 1; rank < comm_.size(); ++rank) {
        const int tile = tile_of_rank(spec_, rank);
        const EyeView eye =
            eye_view(camera_, aspect_, spec_, eye_of_rank(spec_, rank), head_, bounds_);
        // An eye's frame may be squeezed (side-by-side, top-bottom): the tile's whole frustum
        // on eye_rect's pixels.
        const PixelRect r = eye_rect(spec_, tile);
        ViewMsg v;
        v.generation = generation_;
        v.view = {eye.camera, tile_frustum(eye.wall, spec_, tile), r.width, r.height, iso_, clip_};
        v.surfaces = surfaces_;
        v.step = step_;
        TileState& t = tiles_[static_cast<std::size_t>(rank)];
        t.rays = 0;
        t.on_view = false;
        t.view = v.view;
        if (t.lost) {
            // Its screen, drawn by the others: the background, then their results by depth.
            t.stand_in.resize(r.width, r.height);
            for (std::size_t i = 0; i < t.stand_in.pixel_count(); ++i)
                t.stand_in.rgba[4 * i + 3] = 255;
            t.stand_in.depth.assign(t.stand_in.pixel_count(), 1.0f);
            t.stand_in_layers.assign(surfaces_.size(), t.stand_in);
            t.layers_in.clear();
            preview_lost(rank);
            continue;
        }
        send_message(comm_, rank, v);
    }
    std::vector<FrameView> views;  // by rank: the master's is empty (width 0)
    for (const TileState& t : tiles_) views.push_back(t.view);
    const FramePlan plan =
        o_.balance && o_.regions_from_work
            ? planner_.next(views, iso_, board_ ? &*board_ : nullptr, bounds_, o_.screen_box)
            : grid_plan(views, o_.balance ? o_.region_w : 0, o_.balance ? o_.region_h : 0, bounds_,
                        o_.screen_box);
    // By rank: each eye's ranks help only each other, unless every rank of an eye is lost (its
    // screens are then drawn by the other eye's ranks rather than never).
    std::vector<int> pools;
    std::vector<int> living_in(3, 0);
    for (int rank = 0; rank < comm_.size(); ++rank) {
        pools.push_back(static_cast<int>(eye_of_rank(spec_, rank)));
        if (rank != kMasterRank && living(rank))
            ++living_in[static_cast<std::size_t>(pools.back())];
    }
    for (int& p : pools)
        if (living_in[static_cast<std::size_t>(p)] == 0) p = living_in[1] > 0 ? 1 : 2;
    board_.emplace(plan.regions, plan.work, o_.balance, 1, std::move(pools));
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (!living(rank)) board_->orphan(rank);
    migrations_.clear();
    frame_busy_s_.assign(tiles_.size(), 0.0);
    frame_clock_s_.assign(tiles_.size(), 0.0);
    curves_asked_ = false;
    frame_curves_.assign(tiles_.size(), TileResultMsg{});
    order_.begin_frame();
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (living(rank)) order_.ask(rank);
    dispatch();
    ask_curves();  // a frame with no job (nothing of the volume on the wall) is complete at once
    frame_start_ = Stopwatch();
    switch_s_ = -1;
    trace_.switch_to(left);
}

bool WallMaster::execute(const ScriptCommand& cmd, const std::string& where) {
    // A command that would leave the view degenerate (a run of zooms or pans past float
    // precision) is refused naming its line, and the view stays as it was.
    const Camera before = camera_;
    const glm::dvec3 head_before = head_;
    const bool moved = change_view(cmd, where);
    if (std::string p = camera_problem(camera_); !p.empty()) {
        camera_ = before;
        throw InputError(where, "view", p);
    }
    if (std::string p = head_problem(camera_, aspect_, spec_, head_); !p.empty()) {
        camera_ = before;
        head_ = head_before;
        throw InputError(where, std::holds_alternative<HeadCmd>(cmd) ? "head" : "view", p);
    }
    if (moved) send_views();
    return !std::holds_alternative<QuitCmd>(cmd);
}

bool WallMaster::change_view(const ScriptCommand& cmd, const std::string& where) {
    if (apply_camera_command(cmd, camera_, aspect_)) {
    } else if (const auto* c = std::get_if<IsoCmd>(&cmd)) {
        std::vector<SurfaceStyle> s =
            c->surfaces.empty() ? std::vector<SurfaceStyle>{SurfaceStyle{c->iso}} : c->surfaces;
        for (SurfaceStyle& one : s) one.iso = checked_isovalue(one.iso, lo_, hi_, where, "iso");
        if (o_.measure && !one_opaque_surface(s))
            throw InputError(where, "iso",
                             "--measure studies one opaque surface; this wall measures its frames");
        surfaces_ = std::move(s);
        iso_ = surfaces_[0].iso;
    } else if (const auto* c = std::get_if<HeadCmd>(&cmd)) {
        head_ = c->offset;
    } else if (const auto* c = std::get_if<TimeCmd>(&cmd)) {
        if (o_.steps == 0) throw InputError(where, "time", "the volume is not a time series");
        if (c->step >= o_.steps)
            throw InputError(where, "time",
                             "step " + std::to_string(c->step) + ": the series has " +
                                 std::to_string(o_.steps) + " steps (0 to " +
                                 std::to_string(o_.steps - 1) + ")");
        step_ = c->step;
    } else if (const auto* c = std::get_if<PlayCmd>(&cmd)) {
        if (o_.steps == 0) throw InputError(where, "play", "the volume is not a time series");
        playing_ = true;
        loop_ = c->loop;
        play_on();
        return false;
    } else if (std::holds_alternative<PauseCmd>(cmd)) {
        playing_ = false;
        return false;
    } else if (const auto* c = std::get_if<ClipCmd>(&cmd)) {
        if (!keeps_some_voxel(c->clip, o_.dims))
            throw InputError(where, "clip", "the planes keep nothing of the volume's voxels");
        clip_ = c->clip;
    } else if (const auto* c = std::get_if<WaitCmd>(&cmd)) {
        wait(*c);
        return false;
    } else if (const auto* c = std::get_if<SnapshotCmd>(&cmd)) {
        const auto path = std::filesystem::path(o_.out).parent_path() / (c->name + ".png");
        write_mosaics(path, gather_snapshot());
        std::printf("snapshot: %s (frame %llu, %.3f s into it, %llu rays)\n", path.c_str(),
                    (unsigned long long)generation_, frame_start_.seconds(),
                    (unsigned long long)total_rays());
        return false;
    } else if (std::holds_alternative<QuitCmd>(cmd)) {
        return false;
    }
    return true;
}

void WallMaster::wait(const WaitCmd& w) {
    Stopwatch t;
    if (w.until == WaitCmd::Until::time) {
        // A pause: it lasts its seconds even when the frame ends first (a script holding a
        // finished frame on the wall). The tiles are quiet then, so only their alive messages
        // (keep_alive) tell that they still run.
        wait_until([&] { return t.seconds() >= w.amount; }, HUGE_VAL);
        return;
    }
    auto done = [&] {
        // A wait for rays also ends when the frame is complete on every tile. When measuring, a
        // frame is done once its curves are in: the tiles measure it when it completes, and a
        // next view sent meanwhile would find some tiles still measuring (late on 2 cores) and
        // hand their regions to others: the measurement would change the next frame's figures.
        if (frame_done() && (!o_.measure || curves_in())) {
            // Playing (to the last step, not round and round): the next step's frame.
            if (!playing_ || loop_) return true;
            play_on();
            return !playing_;
        }
        if (w.until == WaitCmd::Until::helped) return double(migrations_.size()) >= w.amount;
        return w.until == WaitCmd::Until::rays && double(total_rays()) >= w.amount;
    };
    wait_until(done, o_.timeout_s);
}

std::vector<Mosaic> WallMaster::gather_snapshot() {
    for (TileState& t : tiles_) t.image.reset();
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (living(rank)) send_message(comm_, rank, SnapshotMsg{});
    wait_for_tiles([](const TileState& t) { return t.image.has_value(); }, o_.timeout_s);
    return compose();
}

std::vector<Mosaic> WallMaster::compose(OutputFiles* batch) {
    const Stage left = trace_.switch_to(Stage::compose);
    const PixelSize es = eye_screen_size(spec_);
    std::vector<Mosaic> mosaics;
    for (int e = 0; e < eyes_per_tile(spec_); ++e)
        mosaics.push_back(empty_mosaic(es.width, es.height));
    for (int rank = 1; rank < comm_.size(); ++rank) {
        const int tile = tile_of_rank(spec_, rank);
        const Eye eye = eye_of_rank(spec_, rank);
        TileState& t = tiles_[static_cast<std::size_t>(rank)];
        Image img;
        if (t.lost) {
            img = Image{t.stand_in.width, t.stand_in.height, t.stand_in.rgba, {}};
        } else {
            ImageMsg& m = *t.image;
            img = Image{m.width, m.height, std::move(m.rgba), {}};
        }
        paste(mosaics[eye == Eye::right ? 1 : 0], img, eye_rect(spec_, tile));
        std::string suffix;  // appended, not concatenated: GCC 12 warns of a false overlap
        if (eye != Eye::centre) suffix.append("-").append(to_string(eye));
        if (batch && !o_.tiles_out.empty())
            write_image(*batch,
                        std::filesystem::path(o_.tiles_out) /
                            ("tile_" + std::to_string(tile) + suffix + ".png"),
                        img);
    }
    trace_.switch_to(left);
    return mosaics;
}

void WallMaster::write_mosaics(const std::filesystem::path& path, std::vector<Mosaic> mosaics,
                               OutputFiles* batch) const {
    const PixelSize vs = virtual_screen_size(spec_);
    for (auto& [file, image] : mosaic_files(path, std::move(mosaics), vs.width, vs.height)) {
        if (o_.legend) draw_legend(image, *o_.legend, o_.legend_label);
        if (batch)
            write_image(*batch, file, image);
        else
            write_image(file, image);
    }
}

int WallMaster::finish() {
    comm_.ending();
    gathering_ = true;
    for (TileState& t : tiles_) t.image.reset();
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (living(rank)) send_message(comm_, rank, QuitMsg{});
    wait_for_tiles([](const TileState& t) { return t.result && t.image; }, o_.timeout_s);
    // The run's outputs (per-tile images, the mosaic, the traces) are one batch, committed after
    // everything that can fail: all of them or none, and the last line says which. They are
    // written before the tiles are let go: a tile that dies once released ends the job, and what
    // was finished must be on disk by then (the first image written also loads OpenImageIO,
    // half a second).
    OutputFiles batch;
    std::vector<Mosaic> mosaics = compose(&batch);
    trace_.switch_to(Stage::compose);
    write_mosaics(o_.out, std::move(mosaics), &batch);
    report(batch);
    batch.commit();
    if (!o_.trace.empty())
        std::printf("wrote %s.json (Chrome trace: open in Perfetto) and %s.csv\n", o_.trace.c_str(),
                    o_.trace.c_str());
    if (!o_.tiles_out.empty()) std::printf("wrote the tiles' images in %s\n", o_.tiles_out.c_str());
    if (spec_.stereo)
        std::printf("wrote %s (anaglyph: red left, cyan right) and the eyes' mosaics beside it\n",
                    o_.out.c_str());
    else
        std::printf("wrote %s\n", o_.out.c_str());
    std::fflush(stdout);
    // Every rank has stopped working, so no helper's result is on its way any more.
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (living(rank)) send_message(comm_, rank, ReleaseMsg{});
    raise_test_signal(o_.fault, FaultMoment::end);
    if (lost_count() == 0) return 0;
    std::fflush(stdout);
    std::fprintf(stderr,
                 "isowall: the wall lost %d tile rank%s (listed above); the outputs show every "
                 "screen, drawn by the others (exit status %d)\n",
                 lost_count(), lost_count() == 1 ? "" : "s", kLostRankExit);
    return kLostRankExit;
}

void WallMaster::report(OutputFiles& batch) {
    std::vector<TileResultMsg> results(tiles_.size());
    for (std::size_t rank = 1; rank < tiles_.size(); ++rank) {
        const TileState& t = tiles_[rank];
        if (t.lost)
            results[rank].host = t.host;  // nothing came: zeros in the tables
        else
            results[rank] = *t.result;
    }
    print_rank_table(stdout, spec_, results);
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (!living(rank)) {
            const TileState& t = tiles_[static_cast<std::size_t>(rank)];
            std::printf(
                "lost: %s on %s, %.1f s into the run: %s; its screen was drawn by the "
                "other ranks (its row above: zeros); %s\n",
                rank_label(spec_, rank).c_str(), t.host.c_str(), t.lost_at_s, t.lost_why.c_str(),
                whole_again(t).c_str());
        }
    print_scheduler(stdout, o_.balance, frame_done(), *board_, order_, migrations_, results);
    print_earlier_frames(stdout, results, completed_);
    print_switches();
    if (o_.results_out) *o_.results_out = results;
    trace_.close();
    print_stage_table(stdout, trace_.spans(), results);
    print_store_sent(stdout, store_sent_);
    if (!o_.trace.empty())
        write_wall_traces(batch, o_.trace, spec_, trace_.spans(), results, migrations_);
}

// ---- the screen-region scheduler: handing out jobs (master/job_board.h) in the dispatch order
// (master/dispatch_order.h) and taking their ends and landings ----------------------------------

void WallMaster::fill(int rank) {
    while (auto id = board_->next_for(rank)) {
        const BoardJob& j = board_->job(*id);
        JobMsg m;
        m.generation = generation_;
        m.job = *id;
        m.owner = j.owner;
        m.deliver = living(j.owner) ? j.owner : kMasterRank;
        m.band = j.band;
        m.view = tiles_[static_cast<std::size_t>(j.owner)].view;
        m.rect = j.rect;
        send_message(comm_, rank, m);
        if (j.owner != rank) raise_test_signal(o_.fault, FaultMoment::migration);
    }
}

void WallMaster::dispatch() {
    while (auto rank = order_.next()) {
        fill(*rank);
        order_.served(*rank, board_->in_hand(*rank) > 0);
    }
}

void WallMaster::handle_job(int from, const Message& m) {
    const std::uint64_t generation = std::visit(
        [](const auto& msg) -> std::uint64_t {
            if constexpr (requires { msg.generation; }) return msg.generation;
            return 0;
        },
        m);
    if (generation != generation_ || !board_) return;  // an interrupted frame's
    const std::uint32_t id = std::holds_alternative<JobDoneMsg>(m) ? std::get<JobDoneMsg>(m).job
                                                                   : std::get<LandedMsg>(m).job;
    if (id >= board_->size())
        throw WireError(rank_label(spec_, from) + ": no job " + std::to_string(id) +
                        " in this frame");
    const BoardJob& j = board_->job(id);
    if (auto* d = std::get_if<JobDoneMsg>(&m)) {
        if (j.worker != from || j.state != BoardJob::State::running)
            throw WireError(rank_label(spec_, from) + ": job " + std::to_string(id) +
                            " was not running on it");
        board_->done(id, d->cpu_s);
        if (j.owner != from) migrations_.push_back({j.owner, from, d->start_s, d->end_s, d->bytes});
        order_.clock(from, d->cpu_end_s);
        const auto r = static_cast<std::size_t>(from);
        frame_busy_s_.at(r) += d->cpu_s;
        frame_clock_s_.at(r) = std::max(frame_clock_s_.at(r), d->cpu_end_s);
        order_.ask(from);
        dispatch();
    } else {
        if (j.owner != from || j.worker == from || j.arrived || j.state == BoardJob::State::queued)
            throw WireError(rank_label(spec_, from) + ": landed job " + std::to_string(id) +
                            ", which no helper ran for it");
        board_->landed(id);
    }
    ask_curves();
}

void WallMaster::ask_curves() {
    if (board_ && board_->complete())
        for (TileState& t : tiles_)
            if (t.lost && t.whole_after_s < 0) t.whole_after_s = run_clock_.seconds() - t.lost_at_s;
    if (!o_.measure || curves_asked_ || !board_ || !board_->complete()) return;
    curves_asked_ = true;
    for (int rank = 1; rank < comm_.size(); ++rank)
        if (living(rank)) send_message(comm_, rank, CurveAskMsg{generation_});
}

FrameFigures WallMaster::frame_figures() const {
    FrameFigures f;
    if (!board_) return f;
    f.jobs = board_->size();
    for (std::uint32_t id = 0; id < board_->size(); ++id)
        if (board_->job(id).state == BoardJob::State::done) ++f.jobs_done;
    f.migrated = migrations_.size();
    double sum = 0, most = 0;
    for (std::size_t r = 1; r < frame_busy_s_.size(); ++r) {
        sum += frame_busy_s_[r];
        most = std::max(most, frame_busy_s_[r]);
        f.emulated_s = std::max(f.emulated_s, frame_clock_s_[r]);
    }
    const std::size_t ranks = frame_busy_s_.size() > 1 ? frame_busy_s_.size() - 1 : 1;
    if (most > 0) f.balance = sum / static_cast<double>(ranks) / most;
    if (curves_in()) f.c99_s = time_to(wall_curve(frame_curves_), 0.99, false);
    return f;
}

bool WallMaster::curves_in() const {
    bool all = curves_asked_;
    for (std::size_t r = 1; r < frame_curves_.size(); ++r)
        all = all && (frame_curves_[r].frames || tiles_[r].lost);
    return all;
}

}  // namespace isowall
