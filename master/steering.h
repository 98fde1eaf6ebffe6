#pragma once
// The wall steered while it runs: the control window (--control, master/control_window.h), the
// browser page (--http, app/wall_http.h) or both at once. Each source turns its input into script
// lines; run_steering runs every line through parse_command and WallMaster::execute, the path of
// scripts and the console, so every source drives one code path, each line is printed (the
// operator can replay it as a script) and every source hears of every line.
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "master/wall_master.h"

namespace isowall {

// A script line from a source, and who gave it: "control", "page 2".
struct SteeringLine {
    std::string text;
    std::string who;
};

// The current frame as the steering loop tracks it.
struct FrameNote {
    std::uint64_t frame = 0;  // the master's generation
    bool done = false;        // every tile has finished it
    double seconds = 0;       // wall seconds since it started; at its end, how long it took
};

class SteeringSource {
  public:
    virtual ~SteeringSource() = default;
    // Once, when the loop starts (the wall has started): a line saying where the source is.
    virtual void begin() {}
    // The lines its input gave since the last call, in order (often none). Never blocks.
    virtual std::vector<SteeringLine> take(const WallMaster& master) = 0;
    // `line` ran (from any source); `error` says why it was refused, empty when it ran.
    virtual void ran(const SteeringLine& line, const std::string& error) = 0;
    // Shows the wall as it is; `changed`: input came or the master's state or previews changed
    // since the last call. Called every turn of the loop (about every 10 ms while idle): the
    // source paces itself.
    virtual void show(const WallMaster& master, const FrameNote& frame, bool changed) = 0;
};

// Serves the wall until a source gives quit and it has run (the caller then finishes the wall).
// Prints "WHO: LINE" for every line and "PREFIX: frame N done in S s" once when every tile has
// finished a frame; a line that cannot apply (a zoom past the limits) is printed and skipped, as
// at the console. Between lines the master takes the tiles' messages.
void run_steering(WallMaster& master, const std::vector<SteeringSource*>& sources,
                  const std::string& prefix);

// The master's latest preview of each tile as images, by tile index (0x0 where none came yet).
std::vector<Image> tile_previews(const WallMaster& master);
// The same from previews by rank ([0], the master's, empty), as WallMaster::previews holds them.
std::vector<Image> tile_previews(const WallSpec& spec,
                                 const std::vector<std::optional<PreviewMsg>>& by_rank);

}  // namespace isowall
