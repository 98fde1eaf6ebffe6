#pragma once
// The progressive engine's options on the command line, shared by `render` and `wall`.
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "engine/progressive_engine.h"

namespace isowall {

// Every default here is the engine's own (EngineOptions, PropagationParams): the defaults are
// chosen once, there (CliEngineDefaults.AreTheEnginesOwn checks each).
struct EngineCli {
    std::string order = "dynamic";
    std::string intersect = "exact";
    std::string propagation = "count";
    int max_count = PropagationParams{}.max_count;
    float cutoff_deg = 2.0f;
    float foldback_deg = 0.5f;
    bool no_interpolant_cache = false;
    bool no_screen_box = false;
    bool no_screen_mask = false;
    bool no_frontier_seeds = !EngineOptions{}.frontier_seeds;
    bool adaptive = false;
    int adaptive_max_level = 3;
    float adaptive_pixels = 1.0f;
    bool no_adaptive_refine = false;
    std::optional<float> adaptive_error;  // the error rule's bound; none: the size rule alone
    bool facing_only = false;
    bool every_triangle = !EngineOptions{}.sampled_triangles;
    float footprint_pixels = EngineOptions{}.footprint_pixels;
};

// `serve`'s max count: a default chosen, like the engine's, over several volumes by the smallest
// worst ratio to each case's best, but on what remote viewing pays for, the bytes a client needs
// to reach C = 99% with cached groups (remote study case 5, turned view), on the resampled CT
// head, engine, mrhead_t1 and heptane: 1000 scores 1.93 (1.84x the bytes of 2000 on the head),
// 2000 1.19, 4000 1.20 (docs/benchmarks.md, "The remote-viewing study").
inline constexpr int kServeMaxCount = 2000;

// The engine's defaults with `serve`'s max count.
inline EngineCli serve_engine_defaults() {
    EngineCli e;
    e.max_count = kServeMaxCount;
    return e;
}

void add_engine_options(CLI::App& app, EngineCli& e);
// Throws InputError naming the option for a value the parser could not reject.
EngineOptions to_engine_options(const EngineCli& e);

}  // namespace isowall
