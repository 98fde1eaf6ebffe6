#include "master/wall_report.h"

#include <algorithm>
#include <cmath>

namespace isowall {
namespace {

// The rank table's tile column: "3", with stereo "3L" or "3R".
std::string tile_column(const WallSpec& spec, int rank) {
    const Eye eye = eye_of_rank(spec, rank);
    return std::to_string(tile_of_rank(spec, rank)) + (eye == Eye::left    ? "L"
                                                       : eye == Eye::right ? "R"
                                                                           : "");
}

}  // namespace

WallFigures wall_figures(const std::vector<TileResultMsg>& results) {
    WallFigures f;
    std::size_t tiles = 0;
    std::vector<double> comm_of(results.size(), 0.0);
    for (std::size_t rank = 1; rank < results.size(); ++rank, ++tiles) {
        const TileResultMsg& r = results[rank];
        f.makespan_s = std::max(f.makespan_s, r.cpu_s);
        f.total_s += r.cpu_s;
        double comm = 0, other = 0;
        for (const TraceSpan& sp : r.spans) {
            const auto stage = static_cast<Stage>(sp.stage);
            if (stage == Stage::comm) comm += sp.cpu_s;
            if (stage == Stage::send) f.send_s += sp.cpu_s;
            if (stage == Stage::idle || stage == Stage::io) other += sp.cpu_s;
        }
        const double all = r.cpu_s + comm + other;
        f.all_makespan_s = std::max(f.all_makespan_s, all);
        f.all_total_s += all;
        f.comm_s += comm;
        comm_of[rank] = comm;
    }
    // The share of communication in a rank's busy CPU, over the ranks that did work (a tenth of
    // the makespan or more: a rank with nothing to do has nothing to compare its waits with).
    for (std::size_t rank = 1; rank < results.size(); ++rank) {
        const TileResultMsg& r = results[rank];
        if (r.cpu_s < 0.1 * f.makespan_s || r.cpu_s <= 0) continue;
        if (comm_of[rank] / r.cpu_s > f.comm_share_max)
            f.comm_share_max = comm_of[rank] / r.cpu_s, f.comm_rank = rank;
    }
    f.balance = tiles ? f.total_s / double(tiles) / std::max(f.makespan_s, 1e-9) : 0;
    return f;
}

void print_rank_table(std::FILE* out, const WallSpec& spec,
                      const std::vector<TileResultMsg>& results) {
    std::fprintf(
        out,
        "per rank (CPU seconds of each tile's frame thread, plus what its engine workers ran "
        "past it; all frames; makespan = the largest):\n");
    std::fprintf(out, "  %4s %-12s %5s %8s %8s %7s %6s %10s %7s %10s %8s %5s %6s %8s\n", "rank",
                 "host", "tile", "cpu s", "frame s", "frames", "intr", "rays", "groups",
                 "triangles", "RSS MiB", "jobs", "helped", "MB sent");
    for (std::size_t rank = 1; rank < results.size(); ++rank) {
        const TileResultMsg& s = results[rank];
        std::fprintf(out,
                     "  %4zu %-12s %5s %8.3f %8.3f %7llu %6llu %10llu %7llu %10llu %8.1f %5llu "
                     "%6llu %8.2f\n",
                     rank, s.host.c_str(), tile_column(spec, static_cast<int>(rank)).c_str(),
                     s.cpu_s, s.frame_s, (unsigned long long)s.frames,
                     (unsigned long long)s.interrupted, (unsigned long long)s.rays,
                     (unsigned long long)s.groups, (unsigned long long)s.triangles, s.rss_mib,
                     (unsigned long long)(s.jobs_own + s.jobs_helped),
                     (unsigned long long)s.jobs_helped, double(s.bytes_sent) / 1e6);
    }
    const WallFigures f = wall_figures(results);
    std::fprintf(out, "makespan %.3f s (CPU), total %.3f s, balance %.2f (mean/max)\n",
                 f.makespan_s, f.total_s, f.balance);
    std::fprintf(out,
                 "every thread (busy, communication, idle waits, pager): makespan %.3f s, total "
                 "%.3f s; communication %.3f s, at most %.0f%% of a rank's busy CPU (rank %zu); "
                 "region results sent (in busy) %.3f s\n",
                 f.all_makespan_s, f.all_total_s, f.comm_s, 100.0 * f.comm_share_max, f.comm_rank,
                 f.send_s);
}

std::vector<WallCurvePoint> wall_curve(const std::vector<TileResultMsg>& results) {
    std::vector<double> times;
    double significant = 0;
    for (std::size_t rank = 1; rank < results.size(); ++rank) {
        significant += double(results[rank].significant);
        for (const CurvePoint& p : results[rank].curve) times.push_back(p.emulated_s);
    }
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    std::vector<WallCurvePoint> out;
    if (significant <= 0) return out;
    for (double t : times) {
        double final_px = 0, squared = 0;
        for (std::size_t rank = 1; rank < results.size(); ++rank) {
            const TileResultMsg& r = results[rank];
            // Before a tile's first point nothing of it shows: every significant pixel is wrong.
            double tile_px = 0, tile_sq = double(r.significant);
            for (const CurvePoint& p : r.curve)
                if (p.emulated_s <= t) tile_px = double(p.final_px), tile_sq = p.squared_error;
            final_px += tile_px;
            squared += tile_sq;
        }
        out.push_back({t, final_px / significant, 1.0 - std::sqrt(squared / significant)});
    }
    return out;
}

double time_to(const std::vector<WallCurvePoint>& curve, double level, bool final_pixels) {
    for (const WallCurvePoint& p : curve)
        if ((final_pixels ? p.final_pixels : p.c) >= level - 1e-12) return p.emulated_s;
    return -1;
}

void print_earlier_frames(std::FILE* out, const std::vector<TileResultMsg>& results,
                          const std::vector<std::uint64_t>& completed) {
    for (const std::uint64_t g : completed) {
        // The frame's curves, as if they were the last frame's: wall_curve merges them.
        std::vector<TileResultMsg> frame(results.size());
        bool all = true;
        for (std::size_t rank = 1; rank < results.size(); ++rank) {
            const auto& e = results[rank].earlier;
            const auto it = std::find_if(e.begin(), e.end(),
                                         [&](const FrameCurve& f) { return f.generation == g; });
            if (it == e.end()) {
                all = false;
                break;
            }
            frame[rank].significant = it->significant;
            frame[rank].curve = it->points;
        }
        const auto curve = all ? wall_curve(frame) : std::vector<WallCurvePoint>{};
        if (curve.empty()) continue;
        std::fprintf(out, "frame %llu: emulated C = 90/99/100%%: %.3f / %.3f / %.3f s\n",
                     (unsigned long long)g, time_to(curve, 0.9, false), time_to(curve, 0.99, false),
                     time_to(curve, 1.0, false));
    }
}

std::string rank_label(const WallSpec& spec, int rank) {
    return "rank " + std::to_string(rank) + " (" + tile_name(spec, rank) + ")";
}

void print_scheduler(std::FILE* out, bool balance, bool complete, const JobBoard& board,
                     const DispatchOrder& order, const std::vector<Migration>& migrations,
                     const std::vector<TileResultMsg>& results) {
    std::uint64_t bytes = 0;
    for (const Migration& m : migrations) bytes += m.bytes;
    std::fprintf(out,
                 "scheduler: balancing %s, last frame %s: %zu jobs, %zu migrated, %.2f MB of "
                 "region results moved; dispatch %s",
                 balance ? "on" : "off", complete ? "complete" : "interrupted", board.size(),
                 board.migrated(), double(bytes) / 1e6,
                 order.order() == Dispatch::emulated ? "in emulated-time order" : "on arrival");
    if (order.order() == Dispatch::emulated)
        std::fprintf(out, " (%d requests held for a rank with an earlier clock)", order.holds());
    std::fputc('\n', out);
    const auto curve = wall_curve(results);
    if (curve.empty()) return;
    auto at = [&](double level, bool px) {
        const double t = time_to(curve, level, px);
        char buf[32];
        std::snprintf(buf, sizeof(buf), t < 0 ? "never" : "%.3f", t);
        return std::string(buf);
    };
    std::fprintf(out,
                 "emulated time (each rank on cores of its own, CPU-derived) to wall-wide C = "
                 "90/99/100%%: %s / %s / %s s; final pixels 90/99/100%%: %s / %s / %s s\n",
                 at(0.90, false).c_str(), at(0.99, false).c_str(), at(1.0, false).c_str(),
                 at(0.90, true).c_str(), at(0.99, true).c_str(), at(1.0, true).c_str());
}

void print_stage_table(std::FILE* out, const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results) {
    std::fprintf(out,
                 "CPU seconds by stage (thread CPU time, engine workers' included; propagation "
                 "includes marching cubes):\n  %4s",
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

void write_wall_traces(OutputFiles& batch, const std::string& prefix, const WallSpec& spec,
                       const std::vector<TraceSpan>& master,
                       const std::vector<TileResultMsg>& results,
                       const std::vector<Migration>& migrations) {
    std::vector<RankTrace> ranks{{kMasterRank, "master", master}};
    for (std::size_t rank = 1; rank < results.size(); ++rank)
        ranks.push_back(
            {static_cast<int>(rank), tile_name(spec, static_cast<int>(rank)), results[rank].spans});
    std::vector<TraceFlow> flows;
    for (const Migration& m : migrations) {
        flows.push_back({m.owner, m.helper, m.start_s, m.start_s, "job", 0});
        flows.push_back({m.helper, m.owner, m.end_s, m.end_s, "region result", m.bytes});
    }
    write_chrome_trace(batch, prefix + ".json", ranks, flows);
    write_trace_csv(batch, prefix + ".csv", ranks);
}

}  // namespace isowall
