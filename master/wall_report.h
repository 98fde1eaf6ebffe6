#pragma once
// What the master prints and writes at the end of a wall run: the per-rank table, the makespan
// line, CPU seconds by stage, and the traces (Chrome trace-event JSON and CSV).
#include <cstdio>
#include <string>
#include <vector>

#include "comm/protocol.h"
#include "common/progressive/trace.h"
#include "common/wall/wall.h"

namespace isowall {

struct WallFigures {
    double makespan_s = 0;  // the largest CPU time of any tile's frame thread
    double total_s = 0;
    double balance = 0;  // mean / max
};

// results[rank] for ranks 1..T (index 0, the master, is unused).
WallFigures wall_figures(const std::vector<TileResultMsg>& results);

// The table of tiles, then `makespan X s (CPU), total Y s, balance Z (mean/max)`.
void print_rank_table(std::FILE* out, const WallSpec& spec,
                      const std::vector<TileResultMsg>& results);
// CPU seconds by stage, one row per rank (the master's first).
void print_stage_table(std::FILE* out, const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results);
// PREFIX.json and PREFIX.csv.
void write_wall_traces(const std::string& prefix, const WallSpec& spec,
                       const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results);

}  // namespace isowall
