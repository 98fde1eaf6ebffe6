#include "master/steering.h"

#include <chrono>
#include <cstdio>
#include <thread>

#include "core/error.h"
#include "core/preview.h"
#include "core/util.h"

namespace isowall {
namespace {

// How long the loop sleeps when no input came: the master costs no CPU while the wall is idle,
// and input is taken within a frame of a 60 Hz display.
constexpr auto kIdleSlice = std::chrono::milliseconds(10);

// Runs one line; false when it was quit.
bool run_line(WallMaster& master, const std::vector<SteeringSource*>& sources,
              const SteeringLine& line) {
    std::printf("%s: %s\n", line.who.c_str(), line.text.c_str());
    std::fflush(stdout);
    std::string error;
    bool go_on = true;
    try {
        go_on = master.execute(parse_command(line.text, line.who), line.who);
    } catch (const InputError& e) {
        error = e.what();
        std::printf("isowall: %s\n", e.what());
        std::fflush(stdout);
    }
    for (SteeringSource* s : sources) s->ran(line, error);
    return go_on;
}

}  // namespace

void run_steering(WallMaster& master, const std::vector<SteeringSource*>& sources,
                  const std::string& prefix) {
    for (SteeringSource* s : sources) s->begin();
    FrameNote note{master.generation(), false, 0};
    bool reported = false;
    Stopwatch frame_clock;
    std::uint64_t previews_seen = ~std::uint64_t{0};
    bool done_seen = false;
    for (;;) {
        bool input = false;
        for (SteeringSource* s : sources)
            for (const SteeringLine& line : s->take(master)) {
                input = true;
                if (!run_line(master, sources, line)) return;
            }
        master.idle();
        if (master.generation() != note.frame) {
            note = {master.generation(), false, 0};
            reported = false;
            frame_clock.restart();
        }
        note.done = master.frame_done();
        if (!reported) note.seconds = frame_clock.seconds();
        if (!reported && note.done) {
            reported = true;
            // The line a test or an operator's tooling waits for: the wall shows the frame whole.
            std::printf("%s: frame %llu done in %.2f s\n", prefix.c_str(),
                        static_cast<unsigned long long>(note.frame), note.seconds);
            std::fflush(stdout);
        }
        const bool changed =
            input || master.previews_taken() != previews_seen || note.done != done_seen;
        previews_seen = master.previews_taken();
        done_seen = note.done;
        for (SteeringSource* s : sources) s->show(master, note, changed);
        if (!input) std::this_thread::sleep_for(kIdleSlice);
    }
}

std::vector<Image> tile_previews(const WallMaster& master) {
    return tile_previews(master.spec(), master.previews());
}

std::vector<Image> tile_previews(const WallSpec& spec,
                                 const std::vector<std::optional<PreviewMsg>>& by_rank) {
    std::vector<Image> previews(static_cast<std::size_t>(tile_count(spec)));
    for (std::size_t rank = 1; rank < by_rank.size(); ++rank)
        // With stereo the left eye stands for its tile.
        if (by_rank[rank] && eye_of_rank(spec, static_cast<int>(rank)) != Eye::right) {
            const int tile = tile_of_rank(spec, static_cast<int>(rank));
            previews.at(static_cast<std::size_t>(tile)) = preview_image(*by_rank[rank]);
        }
    return previews;
}

}  // namespace isowall
