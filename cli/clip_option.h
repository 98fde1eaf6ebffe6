#pragma once
// --clip and --clip-box: the clip planes of every subcommand that draws or exports a surface
// (render, extract, wall), over voxel indices (core/clip.h).
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/clip.h"

namespace isowall {

struct ClipOptions {
    std::vector<std::string> planes;  // --clip, once per plane
    std::string box;                  // --clip-box X0,Y0,Z0,X1,Y1,Z1
};

void add_clip_options(CLI::App& cmd, ClipOptions& clip);

// The planes the options give; throws an InputError naming the option and the bad text, or when
// there are more than kMaxClipPlanes.
ClipSet checked_clip(const ClipOptions& clip);

// Throws an InputError naming `where` and `field` when `clip` (voxel indices) keeps no part of a
// volume of `dims` voxels: its picture would be empty.
void check_clip_keeps(const ClipSet& clip, glm::ivec3 dims, const std::string& where,
                      const std::string& field);

}  // namespace isowall
