#pragma once
// What the master prints and writes at the end of a wall run: the per-rank table, the makespan
// line, CPU seconds by stage, and the traces (Chrome trace-event JSON and CSV).
#include <cstdio>
#include <string>
#include <vector>

#include "files/output_files.h"
#include "master/dispatch_order.h"
#include "master/job_board.h"
#include "progressive/trace.h"
#include "wall_protocol/protocol.h"
#include "wall_spec/wall.h"

namespace isowall {

// A job a helper ran for another tile: a flow from owner to helper in the trace.
struct Migration {
    int owner = 0, helper = 0;
    double start_s = 0, end_s = 0;  // wall clock (trace time base)
    std::uint64_t bytes = 0;        // the region result sent back
};

// Wall-wide correctness against emulated time, merged from the tiles' curves: at each time, the
// share of the wall's significant pixels with their final colour and C = 1 - E over the wall.
struct WallCurvePoint {
    double emulated_s = 0;
    double final_pixels = 0;
    double c = 0;
};
std::vector<WallCurvePoint> wall_curve(const std::vector<TileResultMsg>& results);
// The first emulated time at which `level` is reached (final pixels or C); negative if never.
double time_to(const std::vector<WallCurvePoint>& curve, double level, bool final_pixels);

struct WallFigures {
    double makespan_s = 0;  // the largest CPU time of any tile's frame thread
    double total_s = 0;
    double balance = 0;  // mean / max
    // Every thread of each tile rank: its busy CPU plus what its communication (the frame
    // thread's message handling and the communication thread), its idle waits and the volume's
    // pager spent (the trace's comm, idle and io stages).
    double all_makespan_s = 0, all_total_s = 0;
    double comm_s = 0;          // the comm stage, all tile ranks
    double send_s = 0;          // the send stage (region results; part of busy), all tile ranks
    double comm_share_max = 0;  // the largest comm / busy CPU of a tile rank that worked
    std::size_t comm_rank = 0;  // that rank
};

// results[rank] for ranks 1..T (index 0, the master, is unused).
WallFigures wall_figures(const std::vector<TileResultMsg>& results);

// The table of tiles, then `makespan X s (CPU), total Y s, balance Z (mean/max)`.
void print_rank_table(std::FILE* out, const WallSpec& spec,
                      const std::vector<TileResultMsg>& results);
// The scheduler's figures: jobs, migrations, bytes moved, and with curves the emulated time to
// wall-wide C = 90/99/100%.
// "rank R (tile T)", for the lines that name a rank.
std::string rank_label(const WallSpec& spec, int rank);

void print_scheduler(std::FILE* out, bool balance, bool complete, const JobBoard& board,
                     const DispatchOrder& order, const std::vector<Migration>& migrations,
                     const std::vector<TileResultMsg>& results);
// With curves of earlier frames (--measure over several views): for each frame in `completed`
// (generations whose every job landed), the emulated time to wall-wide C = 90/99/100% of that
// frame, one line each: `frame G: emulated C = 90/99/100%: A / B / C s`.
void print_earlier_frames(std::FILE* out, const std::vector<TileResultMsg>& results,
                          const std::vector<std::uint64_t>& completed);
// CPU seconds by stage, one row per rank (the master's first).
void print_stage_table(std::FILE* out, const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results);
// PREFIX.json and PREFIX.csv, staged in `batch` (committed by the caller with the run's other
// outputs).
void write_wall_traces(OutputFiles& batch, const std::string& prefix, const WallSpec& spec,
                       const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results,
                       const std::vector<Migration>& migrations = {});

}  // namespace isowall
