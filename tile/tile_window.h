#pragma once
// `isowall wall --windows`: each tile rank shows its frame as it builds in a borderless window
// covering its screen (the wall file's display for the tile, else $DISPLAY), at most once per
// display refresh, and the final frame when its work runs out. Drawing stays off screen; the
// window is only presented to (display/x_window.h), so it works on Xvfb and on any driver.
#include <memory>
#include <string>

#include "display/x_window.h"
#include "tile/frame_show.h"
#include "wall_spec/wall.h"

namespace isowall {

// A display refresh: the most often a window is presented to.
inline constexpr double kWindowRefreshHz = 60;

class TileWindow final : public FrameShow {
  public:
    // Opens the window; a display that cannot be used throws a runtime_error naming `host` and
    // the display (the caller's failure path adds the rank and tile).
    // `part`: the screen's half a stereo eye shows on (side-by-side, top-bottom), else whole;
    // `eye` names the window of a stereo eye ("isowall tile 3 left").
    TileWindow(const std::string& display, int tile, const std::string& host,
               WindowOptions::Part part = WindowOptions::Part::whole, Eye eye = Eye::centre);
    double interval_s() const override { return 1.0 / kWindowRefreshHz; }
    void show(const Image& tile, std::uint64_t generation) override;
    int presents() const { return presents_; }

  private:
    std::unique_ptr<XWindow> window_;
    int presents_ = 0;
};

// The title of tile `tile`'s window (tests and operators find it by this name).
std::string tile_window_title(int tile, Eye eye = Eye::centre);

}  // namespace isowall
