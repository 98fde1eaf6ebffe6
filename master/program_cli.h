#pragma once
// The isowall program's command line: every subcommand and option with its checks, built apart
// from main() so that tests parse argument lists in process.
#include <CLI/CLI.hpp>

#include "master/commands.h"
#include "master/wall_run.h"
#include "remote/remote_commands.h"

namespace isowall {

struct ProgramCli {
    ProgramCli();
    ProgramCli(const ProgramCli&) = delete;  // the options are bound to these members
    ProgramCli& operator=(const ProgramCli&) = delete;

    CLI::App app{"isowall: isosurfaces of large volumes on tiled display walls"};
    InfoOptions info;
    ExtractOptions ex;
    RenderOptions re;
    WallOptions wall;
    ServeCommand serve;
    ViewCommand view;
    bool ranks_needed = false;
    CLI::App* info_cmd = nullptr;
    CLI::App* ex_cmd = nullptr;
    CLI::App* re_cmd = nullptr;
    CLI::App* wall_cmd = nullptr;
    CLI::App* serve_cmd = nullptr;
    CLI::App* view_cmd = nullptr;
};

}  // namespace isowall
