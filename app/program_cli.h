#pragma once
// The isowall program's command line: every subcommand and option with its checks, built apart
// from main() so that tests parse argument lists in process.
#include <string>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/import_command.h"
#include "app/remote_commands.h"
#include "app/wall_run.h"

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
    ImportCommand import;
    bool ranks_needed = false;
    CLI::App* info_cmd = nullptr;
    CLI::App* ex_cmd = nullptr;
    CLI::App* re_cmd = nullptr;
    CLI::App* wall_cmd = nullptr;
    CLI::App* serve_cmd = nullptr;
    CLI::App* view_cmd = nullptr;
    CLI::App* import_cmd = nullptr;
};

// The first argument when it is a word that names no subcommand ("isowall frobnicate"): the
// error line, naming the word and the subcommands there are; empty otherwise (an option, a known
// subcommand, or no argument: CLI11 says what is wrong with those).
std::string unknown_subcommand(const CLI::App& app, int argc, const char* const* argv);

}  // namespace isowall
