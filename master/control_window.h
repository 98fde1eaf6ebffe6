#pragma once
// The control window (isowall wall --control): the master's window on the operator's display. It
// shows the wall as a live mosaic of the tiles' previews, and turns mouse and keys into script
// lines (master/control_input.h) that run through parse_command and WallMaster::execute, the
// path of scripts and the console, so every change interrupts every tile at once.
#include <memory>
#include <string>

#include "core/pacer.h"
#include "core/util.h"
#include "display/x_window.h"
#include "master/control_input.h"
#include "master/steering.h"
#include "master/wall_master.h"
#include "wall_spec/control_layout.h"

namespace isowall {

inline constexpr const char* kControlTitle = "isowall control";

class ControlWindow : public SteeringSource {
  public:
    // Opens the window on `display` (empty: $DISPLAY); throws DisplayError naming the display.
    // Snapshots go beside `out` (--out), numbered from the first free control-NNN.png.
    ControlWindow(const WallSpec& spec, const std::string& display, const std::string& out);

    // Serves the wall until the window says quit (Escape, closing it): events become commands,
    // one line printed per command ("control: orbit -30 0"), and a line when a frame is done
    // ("control: frame 3 done in 1.25 s"); between them the master takes the tiles' messages.
    // A command that cannot apply (a zoom past the limits) is printed and skipped, as at the
    // console. Returns when quit has been executed (the caller then finishes the wall).
    // The same as run_steering(master, {this}, "control").
    void run(WallMaster& master);

    // As a source of run_steering (master/steering.h), beside the browser page.
    void begin() override;
    std::vector<SteeringLine> take(const WallMaster& master) override;
    void ran(const SteeringLine& line, const std::string& error) override;
    void show(const WallMaster& master, const FrameNote& frame, bool changed) override;

  private:
    void present(const WallMaster& master);

    ControlLayout layout_;
    XWindow window_;
    ControlInput input_;
    std::string last_;  // the last command taken (from any source), for the status bar
    PresentPacer pacer_;
    Stopwatch clock_, since_present_;
};

}  // namespace isowall
