#pragma once
// The volume options every subcommand shares, and opening the volume they describe.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/volume/volume.h"

namespace isowall {

struct VolumeOptions {
    std::string path;  // empty: the built-in phantom
    std::vector<int> dims;
    std::string type;
    std::vector<float> spacing;
    std::string endian = "little";
    std::size_t header_bytes = 0;
    std::string cache_dir;
    bool no_cache = false;
};

void add_volume_options(CLI::App& app, VolumeOptions& opts);

struct OpenedVolume {
    Volume volume;
    std::optional<std::filesystem::path> file;  // nullopt for the phantom
    std::filesystem::path cache_dir;            // empty: no octree cache
    double load_s = 0;
};

// Loads the file (or generates the phantom) and prints one line about it.
OpenedVolume open_volume(const VolumeOptions& opts, bool quiet = false);

}  // namespace isowall
