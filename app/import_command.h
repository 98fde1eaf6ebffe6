#pragma once
// `isowall import SOURCE --out STORE`: any volume isowall reads, as a chunked,
// compressed store that `--volume STORE` then reads on first touch under a memory limit.
#include <string>

#include <CLI/CLI.hpp>

#include "cli/volume_options.h"
#include "core/test_fault.h"

namespace isowall {

struct ImportCommand {
    VolumeOptions volume;  // the source: --volume, or the positional SOURCE
    std::string source;
    std::string out;
    bool force = false;
    int level = 1;
    int levels = 0;  // 0: down to one brick a side (store::levels_for)
    bool quiet = false;
    TestFault fault;  // the fault tests' hook (core/test_fault.h): term@slab:0 stops it mid-way
};

CLI::App* add_import_command(CLI::App& app, ImportCommand& o);
int run_import(const ImportCommand& o);

}  // namespace isowall
