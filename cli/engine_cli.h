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
    bool adaptive = false;
    int adaptive_max_level = 3;
    float adaptive_pixels = 1.0f;
    bool no_adaptive_refine = false;
    std::optional<float> adaptive_error;  // the error rule's bound; none: the size rule alone
    bool facing_only = false;
};

void add_engine_options(CLI::App& app, EngineCli& e);
// Throws InputError naming the option for a value the parser could not reject.
EngineOptions to_engine_options(const EngineCli& e);

}  // namespace isowall
