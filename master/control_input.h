#pragma once
// The control window's input as script lines: every mouse drag, wheel step and key becomes the
// text of a command (orbit, pan, zoom, iso, snapshot, quit) that goes through parse_command and
// WallMaster::execute like a line of a script or of the console, so the three drive one code
// path and the operator can replay what the window printed as a script. Pure: no display.
//
//   left drag      orbit: kOrbitDegPerPx degrees per pixel (drag right turns the surface right,
//                  drag down tilts its top towards the viewer)
//   right drag     pan: the picture follows the pointer
//   wheel up/down  zoom kZoomStep / 1/kZoomStep
//   Up, plus       iso + kIsoStep of the value range (Down, minus: -); Page_Up/Page_Down: x10;
//                  clamped to the range
//   Left/Right     the viewer's head kHeadStepMm (a wall with [physical]) or kHeadStepWidths
//                  (of the wall's width) left or right: both eyes' frusta follow; Home: back to
//                  its nominal place
//   c              clip planes: none -> x < middle -> y < middle -> z < middle -> none (a
//                  sagittal, coronal or axial cut on most scans)
//   [ ]            move an axis clip plane by kClipStep of the volume's side, back or on
//   s              snapshot control-NNN (beside --out)
//   Escape, close  quit
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/clip.h"

#include "display/x_window.h"

namespace isowall {

inline constexpr double kOrbitDegPerPx = 0.5;
inline constexpr double kZoomStep = 1.25;
inline constexpr double kIsoStep = 0.01;  // of the volume's value range, per key
inline constexpr double kHeadStepMm = 50;
inline constexpr double kHeadStepWidths = 0.01;
inline constexpr double kClipStep = 0.02;  // of the volume's side along the plane's axis, per key

// What the mapping needs to know of the wall when the events are taken.
struct ControlState {
    double iso = 0, value_min = 0, value_max = 0;
    int mosaic_width = 1, mosaic_height = 1;  // the wall in the window (pan is in screen sizes)
    glm::dvec3 head{0};                       // the viewer's head now (head command)
    double head_step = 0;                     // per Left/Right key; 0: the keys do nothing
    ClipSet clip{};                           // the view's clip planes now
    glm::ivec3 dims{0};                       // the volume's voxels; 0: the clip keys do nothing
    // A time series: its steps (0: none, the time keys do nothing), the step shown, and whether
    // it plays.
    std::uint32_t steps = 0, step = 0;
    bool playing = false;
};

// "control-001" ...: the name of snapshot n.
std::string snapshot_name(int n, std::string_view prefix = "control");
// The first n from `from` up with no PREFIX-NNN.png beside `out` (--out), so a second session
// does not overwrite the first one's snapshots (the control window's and the page's).
int first_free_snapshot(const std::string& out, int from = 1, std::string_view prefix = "control");

// "iso V" with V written so that it reads back as itself inside [lo, hi] (six significant
// digits when that suffices, so the line stays readable).
std::string iso_line(double iso, double lo, double hi);
// "head X Y Z".
std::string head_line(const glm::dvec3& head);
// The clip the c key steps to from `now`: "clip x<M" (M the middle of x), then y, then z, then
// "clip off"; any other set of planes: "clip off".
std::string clip_cycle_line(const ClipSet& now, glm::ivec3 dims);
// `now`, one plane across an axis, moved by `steps` of kClipStep of the volume's side along it
// and kept within the volume; "" when `now` is not one such plane or it would not move.
std::string clip_move_line(const ClipSet& now, glm::ivec3 dims, int steps);

// The line a time key gives (comma: the step before, period: the step after, p: play round and
// round or pause), or "" when it changes nothing (the first or last step, or no series).
std::string time_key_line(const std::string& key, const ControlState& state);

class ControlInput {
  public:
    // Snapshots are numbered from `first_snapshot` (the first name not taken beside --out).
    explicit ControlInput(int first_snapshot = 1) : next_snapshot_(first_snapshot) {}

    // The script lines for the events of one poll, in order. Consecutive events of one kind
    // merge into one command: a drag's motions into one orbit (or pan), wheel steps into one
    // zoom, isovalue keys into one iso, so a burst of input starts one frame, not dozens.
    // Nothing follows quit. Keys and buttons it does not know are ignored.
    std::vector<std::string> commands(const std::vector<WindowEvent>& events,
                                      const ControlState& state);

  private:
    enum class Pending { none, orbit, pan, zoom, iso, head, clip };
    void accumulate(Pending kind, std::vector<std::string>& out);
    void flush(std::vector<std::string>& out);
    void drag_to(int x, int y);
    void key(const std::string& name, std::vector<std::string>& out);
    // Adds a clip line to `out` and takes its planes as the state's for the poll's next keys.
    void add_clip(const std::string& line, std::vector<std::string>& out);

    int next_snapshot_;
    bool left_down_ = false, right_down_ = false;  // drags last across polls
    int last_x_ = 0, last_y_ = 0;
    // Within one call:
    ControlState state_;
    Pending pending_ = Pending::none;
    double drag_x_ = 0, drag_y_ = 0;  // pixels
    int zoom_steps_ = 0;
    double iso_steps_ = 0;  // in kIsoStep of the range
    int head_steps_ = 0;    // of head_step, right
    int clip_steps_ = 0;    // of kClipStep, on along the plane's axis
    bool quit_ = false;
};

}  // namespace isowall
