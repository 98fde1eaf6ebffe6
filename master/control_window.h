#pragma once
// The control window (isowall wall --control): the master's window on the operator's display. It
// shows the wall as a live mosaic of the tiles' previews, and turns mouse and keys into script
// lines (master/control_input.h) that run through parse_command and WallMaster::execute, the
// path of scripts and the console, so every change interrupts every tile at once.
#include <memory>
#include <string>

#include "common/core/util.h"
#include "common/wall/control_layout.h"
#include "display/x_window.h"
#include "master/control_input.h"
#include "master/wall_master.h"

namespace isowall {

inline constexpr const char* kControlTitle = "isowall control";

class ControlWindow {
  public:
    // Opens the window on `display` (empty: $DISPLAY); throws DisplayError naming the display.
    // Snapshots go beside `out` (--out), numbered from the first free control-NNN.png.
    ControlWindow(const WallSpec& spec, const std::string& display, const std::string& out);

    // Serves the wall until the window says quit (Escape, closing it): events become commands,
    // one line printed per command ("control: orbit -30 0"), and a line when a frame is done
    // ("control: frame 3 done in 1.25 s"); between them the master takes the tiles' messages.
    // A command that cannot apply (a zoom past the limits) is printed and skipped, as at the
    // console. Returns when quit has been executed (the caller then finishes the wall).
    void run(WallMaster& master);

  private:
    void present(const WallMaster& master);
    void note_frame(const WallMaster& master);

    const WallSpec& spec_;
    ControlLayout layout_;
    XWindow window_;
    ControlInput input_;
    std::string last_;  // the last command taken, for the status bar
    std::uint64_t frame_ = 0;
    bool frame_reported_ = false;
    Stopwatch frame_clock_;
};

}  // namespace isowall
