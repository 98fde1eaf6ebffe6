#pragma once
// Every file a wall run may write, checked on the master before any frame starts: the mosaic,
// the per-tile images, the trace pair and each snapshot the script names. A pure function of the
// options, the wall and the script, so the failure path calls it once and tests call it directly.
#include <vector>

#include "app/wall_run.h"
#include "cli/cli_checks.h"
#include "wall_spec/script.h"
#include "wall_spec/wall.h"

namespace isowall {

// The outputs of a wall run, each with the option (or script line) that names it.
std::vector<OutputPath> wall_outputs(const WallOptions& o, const WallSpec& spec,
                                     const std::vector<ScriptLine>& script);

// InputError naming the first that cannot be written (check_outputs).
void check_wall_outputs(const WallOptions& o, const WallSpec& spec,
                        const std::vector<ScriptLine>& script);

}  // namespace isowall
