#pragma once
// Wall scripts: one command per line, the same commands the master's console takes.
//   orbit YAW PITCH            turn the camera about the volume centre (degrees)
//   look-at EX EY EZ TX TY TZ  eye and target in object space
//   zoom F                     F > 1 moves closer
//   pan DX DY                  move the view by DX screen widths right and DY heights up
//   iso V                      new isovalue
//   iso V[:COLOUR[:OPACITY]]... several surfaces at once (`iso 40:skin:0.3 105:bone`)
//   head X Y Z                 the viewer's head moved from its nominal place (x right, y up, z
//                              towards the viewer; mm on a wall with [physical], else widths of
//                              the wall): both eyes' off-axis frusta follow
//   clip PLANE...              cut the volume (voxel indices): x<N, y>N, z<N or A,B,C<D, up to
//                              eight; `clip box X0 Y0 Z0 X1 Y1 Z1` keeps a box; `clip off`
//   wait rays N | wait done    until N rays in all (or the frame's end) | the frame's end
//   wait time S                a pause of S seconds, whether or not the frame ends first
//   wait helped N              until tiles have run N jobs of other tiles this frame (or its end)
//   time N                     show step N (from 0) of a time series (--volume 'run/t_%03d.nrrd')
//   play | play loop           the next step each time a frame is done, to the last (or round
//                              and round); `wait done` while playing waits for the last step
//   pause                      stop playing
//   snapshot NAME              write the mosaic as NAME.png
//   quit
// '#' starts a comment; blank lines are skipped. Every change of view, isovalue or clip starts a
// new frame on every tile (and interrupts the current one).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera.h"
#include "core/clip.h"
#include "core/surface_style.h"

namespace isowall {

struct OrbitCmd {
    double yaw_deg = 0, pitch_deg = 0;  // the camera reduces them modulo 360
};
struct LookAtCmd {
    glm::vec3 eye{0}, target{0};
};
struct ZoomCmd {
    float factor = 1;
};
struct PanCmd {
    float dx = 0, dy = 0;
};
struct IsoCmd {
    double iso = 0;  // the first surface's
    // Several surfaces, or one with a colour or opacity (core/surface_style.h, canonical order);
    // empty: one plain surface at `iso`.
    std::vector<SurfaceStyle> surfaces = {};
};
struct WaitCmd {
    enum class Until { rays, time, helped, done } until = Until::done;
    double amount = 0;  // rays, seconds, or jobs run by a tile other than their owner
};
struct SnapshotCmd {
    std::string name;
};
struct HeadCmd {
    glm::dvec3 offset{0};
};
struct ClipCmd {
    ClipSet clip;  // empty: clip off
};
struct QuitCmd {};
// A time series (volume/time_steps.h): show step `step` (from 0).
struct TimeCmd {
    std::uint32_t step = 0;
};
// Play the series from the step shown: the next step each time a frame is done, to the last
// (`play loop`: round and round until `pause`).
struct PlayCmd {
    bool loop = false;
};
struct PauseCmd {};

using ScriptCommand =
    std::variant<OrbitCmd, LookAtCmd, ZoomCmd, PanCmd, IsoCmd, WaitCmd, SnapshotCmd, HeadCmd,
                 ClipCmd, QuitCmd, TimeCmd, PlayCmd, PauseCmd>;

struct ScriptLine {
    int line = 0;  // 1-based, for messages
    ScriptCommand command;
};

// One command; throws InputError naming `where` (e.g. "demo.txt:3") and the command.
ScriptCommand parse_command(std::string_view text, const std::string& where);
// Moves `camera` as an orbit, look, zoom or pan command says (pan in screen sizes of `aspect`);
// false, camera untouched, for any other command. The wall and the remote client share it.
bool apply_camera_command(const ScriptCommand& cmd, Camera& camera, float aspect);
// A whole script; blank and comment lines are skipped.
std::vector<ScriptLine> parse_script(std::string_view text, const std::string& file);
// The script in `path` (a regular file of at most kMaxScriptBytes); errors name the file and
// --script, or the file, line and command.
std::vector<ScriptLine> load_script(const std::filesystem::path& path);
inline constexpr std::size_t kMaxScriptBytes = 16u << 20;

}  // namespace isowall
