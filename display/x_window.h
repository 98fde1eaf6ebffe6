#pragma once
// A window on an X display that images are presented to (tile windows, the control window).
// Drawing stays off screen (render/renderer.h); a window only shows a finished RGBA8 image, through
// MIT-SHM where the server shares memory with us (same host), else XPutImage. Works on Xvfb and
// on any X server; no GL, so it does not care which driver renders. No Xlib header leaks from
// here: callers see only value types.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/pacer.h"  // PresentPacer, for callers that present

namespace isowall {

// Every window failure. The message names the display, e.g.
// "cannot open X display \":7\" (is an X server running there, and may we connect?)".
class DisplayError : public std::runtime_error {
  public:
    explicit DisplayError(const std::string& message) : std::runtime_error(message) {}
};

struct WindowOptions {
    std::string display;  // e.g. ":0.1"; empty: $DISPLAY
    std::string title = "isowall";
    // Borderless and covering its screen (override-redirect, at 0,0, the screen's size): a tile
    // of a wall. Otherwise an ordinary window of width x height the window manager places.
    bool fullscreen = false;
    int width = 640, height = 480;
    bool input = false;  // deliver mouse and key events to poll()
    // Try MIT-SHM first (off: always XPutImage, as with a display on another host).
    bool shared_memory = true;
    // Fullscreen only: the part of the screen the window covers (a stereo eye's half).
    enum class Part { whole, left_half, right_half, top_half, bottom_half } part = Part::whole;
};

// One input event in window pixels (x right, y down).
struct WindowEvent {
    enum class Kind { press, release, motion, key, close };
    Kind kind = Kind::motion;
    int x = 0, y = 0;
    int button = 0;   // press/release: 1 left, 2 middle, 3 right, 4 wheel up, 5 wheel down
    std::string key;  // key: the X keysym name ("Escape", "plus", "Up", "s")
};

class XWindow {
  public:
    // Opens the display and maps the window; returns once it is viewable. Throws DisplayError.
    explicit XWindow(const WindowOptions& options);
    ~XWindow();
    XWindow(const XWindow&) = delete;
    XWindow& operator=(const XWindow&) = delete;

    int width() const;  // the window's size now
    int height() const;
    // Shows `image` with its top-left at (x, y) of the window, clipped to it; waits until the X
    // server has taken the pixels (so a capture right after sees them).
    void present(const Image& image, int x = 0, int y = 0);
    // Input events that came since the last call (never waits).
    std::vector<WindowEvent> poll();
    std::uint64_t id() const;  // the X window id (xdotool, xwd)
    const std::string& display_name() const;
    bool shared_memory() const;  // the last present went through MIT-SHM

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The display a window opens when WindowOptions::display is `name`: `name`, else $DISPLAY, else
// empty (which XWindow refuses with a DisplayError naming $DISPLAY).
std::string resolve_display(const std::string& name);

// For tests and tools: the pixels of window `id` on `display` (XGetImage), as RGBA8 (alpha 255,
// depth empty); and the id of the first mapped window whose title is `title` (0 when none).
Image capture_window(const std::string& display, std::uint64_t id);
std::uint64_t find_window(const std::string& display, const std::string& title);

}  // namespace isowall
