#pragma once
// The master's side of a wall run, as one state machine: every message from any tile goes
// through handle(), the one handler, and every wait is wait_until(), the one loop that receives,
// so no message is dropped unread and a silent wall is noticed wherever the master waits.
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "comm/comm.h"
#include "core/colour_map.h"
#include "core/test_fault.h"
#include "core/util.h"
#include "core/view.h"
#include "files/output_files.h"
#include "master/dispatch_order.h"
#include "master/job_board.h"
#include "master/mosaic.h"
#include "master/region_plan.h"
#include "master/store_server.h"
#include "master/wall_report.h"
#include "progressive/trace.h"
#include "wall_spec/script.h"
#include "wall_spec/wall.h"

namespace isowall {

// A tile rank's failure as its failed message told the master (handle() throws it): the wall's
// failure path prints it as the job's one error line, under the tile's name.
class TileFailed : public std::runtime_error {
  public:
    TileFailed(int rank, bool input, const std::string& what)
        : std::runtime_error(what), rank_(rank), input_(input) {}
    int rank() const { return rank_; }
    bool input() const { return input_; }

  private:
    int rank_;
    bool input_;
};

// The exit status of a wall that finished with a tile rank lost: the outputs are complete (the
// other ranks drew its screen), and the status says the wall was not whole.
inline constexpr int kLostRankExit = 3;

struct MasterOptions {
    std::string wall_name;  // for the start-up line
    std::string out = "mosaic.png";
    std::string tiles_out;           // folder for per-tile images, or empty
    std::string trace;               // PREFIX for PREFIX.json and PREFIX.csv, or empty
    double timeout_s = 120;          // the wall silent this long ends the job
    double startup_timeout_s = 600;  // the same, while the tiles start (load, say hello)
    TestFault fault;                 // the fault tests' hook (core/test_fault.h); none by default
    // The screen-region scheduler: off, every tile casts its own screen (one job per band);
    // on, tiles are cut into regions of region_w x region_h and idle ranks take others' regions.
    // The first view: the front full view turned, zoomed and panned by these.
    std::pair<float, float> orbit{0, 0}, pan{0, 0};
    float zoom = 1;
    ClipSet clip;  // the first view's clip planes (voxel indices)
    // The first view's surfaces (core/surface_style.h, canonical order); empty: one plain surface
    // at the isovalue the master is made with.
    std::vector<SurfaceStyle> surfaces;
    // The steps of a time series (volume/time_steps.h); 0: the volume does not change.
    std::size_t steps = 0;
    std::uint32_t first_step = 0;  // the step the first view shows (--time)
    // A surface coloured by a second field (--color-by): the legend the mosaics carry.
    std::optional<ColourScale> legend;
    std::string legend_label;
    glm::ivec3 dims{0};  // the volume's voxels: a `clip` that keeps none of them is refused
    // The volume's axes in patient space (volume/volume.h: Orientation), so that the
    // front view is the patient's front whatever the acquisition.
    glm::mat3 front_axes{1.0f};
    bool balance = true;
    // With balancing: regions planned from the work (master/region_plan.h), the default; or, for
    // studies, a fixed grid of region_w x region_h (0 x 0: one region per tile).
    bool regions_from_work = true;
    int region_w = 0, region_h = 0;
    // Which asking rank gets the next job (master/dispatch_order.h): the first to ask, or, for
    // emulation on fewer cores than ranks, the one with the earliest CPU clock.
    Dispatch dispatch = Dispatch::arrival;
    // The active octree nodes at an isovalue (where the surface may be), for the work estimate;
    // unset, the volume's box alone (a uniform estimate over its screen box).
    std::function<std::vector<Box3>(double iso)> work_boxes;
    bool screen_box = true;  // the engine casts no ray outside the volume's screen box
    bool measure = false;    // tiles report emulated correctness curves
    // The tiles send previews (--control, --http): a lost tile's screen gets one from what the
    // others drew of it, of this largest side (0: none).
    int preview_side = 0;
    std::vector<TileResultMsg>* results_out = nullptr;  // also leave the tiles' figures here
    // The volume when it is a store (null otherwise), and its octree file: sent to a tile rank
    // that asks because its host cannot see them (tile/store_client.h).
    std::shared_ptr<const store::StoreReader> store;
    std::filesystem::path store_octree;
};

// The current frame as the master has seen it so far, from its jobs' ends (JobDoneMsg): what
// the browser page (wall --http) shows while the wall runs.
struct FrameFigures {
    std::size_t jobs = 0, jobs_done = 0;
    std::size_t migrated = 0;  // jobs done by a rank other than their tile's
    // Emulated time (master/dispatch_order.h: a rank's frame-thread CPU clock is its time): the
    // latest a rank's clock read when one of its jobs ended. At the frame's end, its makespan.
    double emulated_s = 0;
    // Mean over max of the tile ranks' busy CPU (the jobs' CPU seconds) so far; 1 with no work.
    double balance = 1;
    // With --measure, once the frame is complete and every tile has sent its curve: the emulated
    // time to wall-wide C = 99% (master/wall_report.h: wall_curve); negative until then.
    double c99_s = -1;
};

class WallMaster {
  public:
    WallMaster(const MasterOptions& o, Comm& comm, const WallSpec& spec, const Box3& bounds,
               double iso, double value_min, double value_max);

    // Waits for every tile to join, lets them load (start), waits until each has loaded, prints
    // the rank -> host -> tile map and sends the first views. Each stage may take the start-up
    // limit; past it the job ends naming the tiles not heard from.
    void start();
    // Between commands at the console: takes the messages that came (so a frame goes on while
    // the operator types), tells the tiles the master is alive, and checks that they are.
    void idle();
    // Runs one command; false for quit. Throws InputError for a command that cannot apply
    // (isovalue out of range, a view left degenerate: camera_problem), naming `where`; the view
    // is then as it was.
    bool execute(const ScriptCommand& cmd, const std::string& where);
    // Quit: every tile's figures and final image; writes the mosaic, prints the tables.
    int finish();

    std::uint64_t generation() const { return generation_; }
    std::uint64_t total_rays() const {
        std::uint64_t n = 0;
        for (const TileState& t : tiles_) n += t.rays;
        return n;
    }
    // Every tile has finished the current frame.
    bool frame_done() const { return board_ && board_->complete(); }
    // With --measure, every tile's curve of the finished frame has come in (ask_curves).
    bool curves_in() const;
    double iso() const { return iso_; }
    // The surfaces the tiles draw (one plain one at iso() unless several were asked for).
    const std::vector<SurfaceStyle>& surfaces() const { return surfaces_; }
    std::uint32_t step() const { return step_; }
    bool playing() const { return playing_; }
    const glm::dvec3& head() const { return head_; }
    const ClipSet& clip() const { return clip_; }
    glm::ivec3 dims() const { return o_.dims; }
    const MasterOptions& options() const { return o_; }
    double value_min() const { return lo_; }
    double value_max() const { return hi_; }
    // For the control window (--control): the latest preview of each tile rank ([0], the
    // master's, stays empty). A preview of an older frame than the current one is dropped when it
    // comes; one already kept stays until its tile sends one of the new frame, so the window
    // keeps a picture while a frame starts. previews_taken() grows with every preview kept.
    const std::vector<std::optional<PreviewMsg>>& previews() const { return previews_; }
    std::uint64_t previews_taken() const { return previews_taken_; }
    const StoreSent& store_sent() const { return store_sent_; }
    FrameFigures frame_figures() const;
    const WallSpec& spec() const { return spec_; }
    // Tile ranks lost so far (TileState::lost); finish() then returns kLostRankExit.
    int lost_count() const;
    // Each lost tile rank as the page names its dark screen: "tile 8 (rank 9 on node3): its
    // process has ended".
    std::vector<std::string> dark_screens() const;

  private:
    struct TileState {
        std::string host;
        std::uint32_t threads = 1;  // its engine threads (its thread budget, from its hellos)
        bool joined = false;        // said hello before loading
        bool hello = false;         // said hello after loading: takes views, sends alive messages
        Stopwatch heard;            // since its last message of any kind
        std::uint64_t rays = 0;     // of the current generation
        bool on_view = false;       // it has cast a ray of the current generation
        FrameView view;             // of the current generation
        std::optional<ImageMsg> image;  // the answer to the pending image request
        std::optional<TileResultMsg> result;
        // Lost: its process ended, or it was silent past --timeout, on a wall that survives a
        // lost rank (Comm::survives_rank_loss). The other ranks draw its screen as jobs whose
        // results come to the master, composed by depth into `stand_in`.
        bool lost = false;
        std::string lost_why;
        double lost_at_s = 0;       // seconds into the run
        double whole_after_s = -1;  // from then until a frame was complete again
        Image stand_in;
        // With several surfaces, each surface's layer of `stand_in` (which blends them), and
        // the layers landed of each job, a bit a layer: the job has landed once all are in.
        std::vector<Image> stand_in_layers;
        std::unordered_map<std::uint32_t, std::uint32_t> layers_in;
    };
    // Gives up on `rank` and starts the frame again without it (see TileState::lost).
    void lose(int rank, const std::string& why);
    // Loses every tile rank that is gone or silent past --timeout on a wall that survives a lost
    // rank (else a silent one ends the job).
    void check_tiles();
    // A helper's result for a lost rank's screen.
    void land_for_lost(int from, RegionMsg r);
    // The lost rank's preview from its stand-in, with MasterOptions::preview_side.
    void preview_lost(int rank);
    bool living(int rank) const { return !tiles_[static_cast<std::size_t>(rank)].lost; }
    int living_tiles() const;
    // "a frame was complete 0.41 s after it" (or that none was), for the report's lost line.
    static std::string whole_again(const TileState& t);

    void handle(const Envelope& e);
    void handle_job(int from, const Message& m);
    // With --measure, once every job of the frame has landed: asks each tile for its curve.
    void ask_curves();
    // Hands `rank` jobs until it holds as many as the board allows.
    void fill(int rank);
    // Serves the asking ranks the dispatch order lets through now.
    void dispatch();
    // Receives and handles messages until done() holds. A wall silent for timeout_s throws,
    // naming the tiles still awaited.
    void wait_until(const std::function<bool()>& done, double timeout_s);
    // wait_until every tile holds `pred`; on a timeout the tiles that do not are named.
    void wait_for_tiles(const std::function<bool(const TileState&)>& pred, double timeout_s);
    bool all_tiles(const std::function<bool(const TileState&)>& pred) const;
    std::string waiting_on() const;
    // Every kAliveIntervalS: an alive message to each tile; throws naming a loaded tile that has
    // sent nothing for the timeout.
    void keep_alive();

    void send_views();
    void wait(const WaitCmd& w);
    // Applies `cmd` (waits, snapshots); true when it changed the view or isovalue.
    bool change_view(const ScriptCommand& cmd, const std::string& where);
    // Asks every tile for its image (snapshot) and composes the mosaics.
    std::vector<Mosaic> gather_snapshot();
    // The mosaics to `path` (mosaic_files: with stereo, the anaglyph and both eyes), staged in
    // `batch` when given, else written at once.
    void write_mosaics(const std::filesystem::path& path, std::vector<Mosaic> mosaics,
                       OutputFiles* batch = nullptr) const;
    // One mosaic per eye (one without stereo). With `batch`, also stages each tile's image in
    // --tiles-out (the run's end, not snapshots).
    std::vector<Mosaic> compose(OutputFiles* batch = nullptr);
    void print_map() const;
    void report(OutputFiles& batch);

    const MasterOptions& o_;
    Comm& comm_;
    const WallSpec& spec_;
    Box3 bounds_;
    double iso_, lo_, hi_;
    float aspect_ = 1;
    Camera camera_;
    glm::dvec3 head_{0};                  // the viewer's head from its nominal place (HeadCmd)
    ClipSet clip_;                        // the view's clip planes, voxel indices (ClipCmd)
    std::vector<SurfaceStyle> surfaces_;  // the view's surfaces; surfaces_[0].iso is iso_
    std::uint32_t step_ = 0;              // the time step shown
    // How long after each change of view (the first aside) every tile had cast its first ray of
    // the new one: the time a change takes to interrupt the wall; -1 until then.
    double switch_s_ = -1;
    std::vector<double> switches_s_;
    // The report's line of the changes' switches (none when the view never changed).
    void print_switches() const;
    bool playing_ = false, loop_ = false;  // PlayCmd
    // Playing: once the frame is done (and measured, with --measure), its step's line, then the
    // next step's frame; at the last step playing stops, or starts again at 0 with `play loop`.
    void play_on();
    std::uint64_t generation_ = 0;
    std::vector<TileState> tiles_;  // by rank; [0] is the master
    Stopwatch frame_start_;
    TraceRecorder trace_;
    std::optional<JobBoard> board_;      // the current generation's jobs
    std::vector<Migration> migrations_;  // of the current generation
    // Of the current generation, by rank: CPU seconds of its jobs, and its clock at its last job.
    std::vector<double> frame_busy_s_, frame_clock_s_;
    // With --measure: whether the tiles were asked for the complete frame's curves, and those
    // that came (by rank; results' significant and curve fields, for wall_curve).
    bool curves_asked_ = false;
    std::vector<TileResultMsg> frame_curves_;
    std::vector<std::uint64_t> completed_;  // generations before the current one that completed
    RegionPlanner planner_;  // the regions of each frame, from the work (regions_from_work)
    DispatchOrder order_;    // which asking rank is served next
    Stopwatch alive_sent_, alive_checked_;
    Stopwatch run_clock_;     // since the master was made
    Stopwatch silent_;        // since the last message other than alive (wait_until)
    bool gathering_ = false;  // finish() waits for the tiles' outputs
    std::function<bool(const TileState&)> awaited_;    // set by wait_for_tiles, for waiting_on
    std::vector<std::optional<PreviewMsg>> previews_;  // by rank
    std::uint64_t previews_taken_ = 0;
    StoreSent store_sent_;  // what tiles that cannot see the store were sent
};

}  // namespace isowall
