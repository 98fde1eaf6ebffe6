// isowall: progressive view-dependent isosurfaces for display walls.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <tuple>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/program_cli.h"
#include "app/wall_run.h"
#include "core/error.h"
#include "core/util.h"
#include "files/output_files.h"

namespace {

using namespace isowall;

// Every error line goes out once, bounded and with control bytes escaped (core/error.h):
// CLI11 quotes the offending argument whole.
void print_error(std::string_view message, const char* tail = "") {
    std::fflush(stdout);
    std::fprintf(stderr, "isowall: error: %s%s\n", clip(message, 800).c_str(), tail);
}

}  // namespace

int main(int argc, char** argv) {
    using namespace isowall;
    install_output_cleanup();  // a SIGINT or SIGTERM leaves no temporary file behind
    keep_freed_memory();       // frames reuse what the frame before freed
    ProgramCli cli;
    CLI::App& app = cli.app;
    if (const std::string unknown = unknown_subcommand(app, argc, argv); !unknown.empty()) {
        print_error(unknown, " (see isowall --help)");
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line, then a pointer to --help (CLI11's own output spans several lines).
        print_error(e.what(), " (see isowall --help)");
        return 2;
    }

    try {
        if (cli.info_cmd->parsed()) return run_info(cli.info);
        if (cli.ex_cmd->parsed()) return run_extract(cli.ex);
        if (cli.re_cmd->parsed()) return run_render(cli.re);
        if (cli.serve_cmd->parsed()) return run_serve(cli.serve);
        if (cli.view_cmd->parsed()) return run_view(cli.view);
        if (cli.import_cmd->parsed()) {
            cli.import.fault = parse_test_fault(std::getenv("ISOWALL_TEST_FAULT"));
            return run_import(cli.import);
        }
        if (cli.wall_cmd->parsed() && cli.ranks_needed) {
            std::printf("%d\n", rank_count(load_wall(cli.wall.wall)));
            return 0;
        }
        if (cli.wall_cmd->parsed()) {
            WallOptions& wall = cli.wall;
            wall.fault = parse_test_fault(std::getenv("ISOWALL_TEST_FAULT"));
            const char* env_rank = std::getenv("OMPI_COMM_WORLD_RANK");
            if (env_rank && std::atoi(env_rank) == wall.fault.rank)
                raise_test_signal(wall.fault, FaultMoment::init);
            auto comm = make_mpi_comm(argc, argv, {wall.startup_timeout_s, wall.timeout_s});
            const int status = run_wall(wall, *comm);
            // A wall that lost a rank ends without MPI_Finalize, which may wait for it for ever.
            if (comm->forgot_any()) comm->leave(status);
            return status;
        }
    } catch (const std::exception& e) {
        print_error(e.what());
        return 1;
    }
    return 0;
}
