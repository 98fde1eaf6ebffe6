#include "master/wall_report.h"

#include <algorithm>

namespace isowall {

WallFigures wall_figures(const std::vector<TileResultMsg>& results) {
    WallFigures f;
    std::size_t tiles = 0;
    for (std::size_t rank = 1; rank < results.size(); ++rank, ++tiles) {
        f.makespan_s = std::max(f.makespan_s, results[rank].cpu_s);
        f.total_s += results[rank].cpu_s;
    }
    f.balance = tiles ? f.total_s / double(tiles) / std::max(f.makespan_s, 1e-9) : 0;
    return f;
}

void print_rank_table(std::FILE* out, const WallSpec& spec,
                      const std::vector<TileResultMsg>& results) {
    std::fprintf(out,
                 "per rank (CPU seconds of each tile's frame thread, all frames; makespan = the "
                 "largest):\n");
    std::fprintf(out, "  %4s %-12s %4s %8s %8s %7s %6s %10s %7s %10s %8s\n", "rank", "host", "tile",
                 "cpu s", "frame s", "frames", "intr", "rays", "groups", "triangles", "RSS MiB");
    for (std::size_t rank = 1; rank < results.size(); ++rank) {
        const TileResultMsg& s = results[rank];
        std::fprintf(out, "  %4zu %-12s %4d %8.3f %8.3f %7llu %6llu %10llu %7llu %10llu %8.1f\n",
                     rank, s.host.c_str(), tile_of_rank(spec, static_cast<int>(rank)), s.cpu_s,
                     s.frame_s, (unsigned long long)s.frames, (unsigned long long)s.interrupted,
                     (unsigned long long)s.rays, (unsigned long long)s.groups,
                     (unsigned long long)s.triangles, s.rss_mib);
    }
    const WallFigures f = wall_figures(results);
    std::fprintf(out, "makespan %.3f s (CPU), total %.3f s, balance %.2f (mean/max)\n",
                 f.makespan_s, f.total_s, f.balance);
}

void print_stage_table(std::FILE* out, const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results) {
    std::fprintf(
        out, "CPU seconds by stage (thread CPU time; propagation includes marching cubes):\n  %4s",
        "rank");
    for (const char* name : kTraceStages) std::fprintf(out, " %12s", name);
    std::fprintf(out, "\n");
    auto row = [&](std::size_t rank, const std::vector<TraceSpan>& spans) {
        std::vector<double> sum(std::size(kTraceStages), 0.0);
        for (const TraceSpan& sp : spans) sum[sp.stage] += sp.cpu_s;
        std::fprintf(out, "  %4zu", rank);
        for (double v : sum) std::fprintf(out, " %12.3f", v);
        std::fprintf(out, "\n");
    };
    row(kMasterRank, master);
    for (std::size_t rank = 1; rank < results.size(); ++rank) row(rank, results[rank].spans);
}

void write_wall_traces(const std::string& prefix, const WallSpec& spec,
                       const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results) {
    std::vector<RankTrace> ranks{{kMasterRank, "master", master}};
    for (std::size_t rank = 1; rank < results.size(); ++rank)
        ranks.push_back({static_cast<int>(rank),
                         "tile " + std::to_string(tile_of_rank(spec, static_cast<int>(rank))),
                         results[rank].spans});
    write_chrome_trace(prefix + ".json", ranks);
    write_trace_csv(prefix + ".csv", ranks);
}

}  // namespace isowall
