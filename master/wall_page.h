#pragma once
// The browser page of `isowall wall --http` (app/wall_http.h), its pure parts: what a page may
// say, who steers, and what the master tells the pages. No network here: tested as values.
//
// A page sends JSON text messages of at most kMaxPageMessage bytes:
//   {"hello": "TOKEN"}        first, always ("" when the wall has no --token)
//   {"run": "orbit -30 0"}    a script line: orbit, look-at, zoom, pan, iso or quit
//   {"snapshot": true}        the mosaic at full size as page-NNN.png beside --out
//   {"take": true}            take the steering from whoever has it
// The master sends JSON text ({"type": "welcome" | "state" | "ran" | "error", ...}) and the
// mosaic as binary messages (encode_mosaic).
//
// Steering: one page at a time. A page that runs a command when nobody steers takes the seat;
// while another page holds it, its commands are refused and it may take over; the seat is free
// again when its page leaves.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/colour_map.h"
#include "core/image.h"
#include "master/wall_master.h"
#include "wall_spec/control_layout.h"

namespace isowall {

inline constexpr std::size_t kMaxPageMessage = 4096;

struct PageMessage {
    enum class Kind { hello, run, snapshot, take } kind = Kind::hello;
    std::string text;  // the token (hello) or the script line (run)
};

// One message from page `who` ("page 2"); throws InputError naming `who` and the field for
// anything else: not JSON, not one of the four, a line that does not parse as a script command,
// or a command a page may not give (wait would stall the wall for every page; snapshot names are
// the master's to choose).
PageMessage parse_page_message(std::string_view bytes, const std::string& who);

class SteeringSeat {
  public:
    // Whether page `id` may run a command now; when nobody steers, it takes the seat.
    bool claim(std::uint64_t id);
    void take(std::uint64_t id) { holder_ = id; }
    // The page left; the seat is free if it held it.
    void leave(std::uint64_t id);
    std::optional<std::uint64_t> holder() const { return holder_; }

  private:
    std::optional<std::uint64_t> holder_;
};

// What a page is told when it has said hello: its name and the wall's layout in the mosaic.
std::string welcome_json(const std::string& you, const ControlLayout& layout,
                         const std::string& wall_name);

// The wall's state, for every page.
struct PageState {
    double iso = 0, value_min = 0, value_max = 0;
    std::uint64_t frame = 0;
    bool done = false;
    double frame_s = 0;  // wall seconds: so far, or at the frame's end
    FrameFigures figures;
    std::string steering;            // the page that steers, or empty
    std::vector<std::string> pages;  // every page that said hello, in order of arrival
    // Tile screens whose rank is lost (WallMaster::dark_screens): the others draw them.
    std::vector<std::string> dark;
    std::string clip;  // the view's clip planes as a script writes them ("x<99"), or empty
    // The surfaces drawn together, each as `iso` takes it ("40:#b17a65:0.3"); one plain one: its
    // isovalue alone.
    std::vector<std::string> surfaces;
    // A time series: its steps (0: none), the step shown, whether it plays.
    std::uint64_t steps = 0, step = 0;
    bool playing = false;
    glm::ivec3 dims{0};  // the volume's voxels: the range of the page's clip slider
    // A surface coloured by a second field: the legend's title and scale (no map: none).
    std::string legend_label;
    ColourScale legend{};
};
std::string state_json(const PageState& s);
// A line ran (error empty) or was refused.
std::string ran_json(const std::string& who, const std::string& line, const std::string& error);
// Something only this page hears (a command refused before it ran, a wrong token).
std::string error_json(const std::string& text);

// The mosaic as a binary message: "IWM1", width and height (u32), the frame (u64), all
// little-endian, then the RGB pixels (row 0 at the top) as one zstd frame. Pages decode it with
// zstddec (web/src/wall/mosaic.js).
std::string encode_mosaic(const Image& mosaic, std::uint64_t frame);
// The inverse, for tests; throws WireError on anything malformed.
Image decode_mosaic(std::string_view bytes, std::uint64_t* frame = nullptr);

}  // namespace isowall
