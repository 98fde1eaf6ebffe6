#pragma once
// Per-rank timing by stage: a thread's time is cut into consecutive spans, each named for the stage
// it was in (intersection, propagation, render, comm, idle, ...), with wall time and the thread's
// CPU time (CLOCK_THREAD_CPUTIME_ID). With more ranks than cores, wall time says nothing about
// parallel speed; CPU time does. Spans change only at stage boundaries (per propagation pass, per
// message), never per ray, so recording costs two clock reads per boundary.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "files/output_files.h"

namespace isowall {

struct TraceSpan {
    std::uint8_t stage = 0;  // index into kTraceStages
    double start_s = 0;      // wall clock, seconds since the Unix epoch (aligned across ranks)
    double wall_s = 0;
    double cpu_s = 0;
};

// show: presenting the frame in a window or as a preview as it builds (not part of the emulated
// busy time). io: a store's pager threads reading bricks for this rank (store/
// paged_voxels.h); charged as CPU without wall time, since they run beside the frame. send: a
// helper encoding and sending a region result to its owner (communication, and part of the job:
// the owner shows nothing of it before). comm: every other message, the communication thread's
// CPU included (charged like io).
inline constexpr const char* kTraceStages[] = {"intersection", "propagation", "render", "comm",
                                               "idle",         "compose",     "setup",  "show",
                                               "send",         "io"};
enum class Stage : std::uint8_t {
    intersection,
    propagation,
    render,
    comm,
    idle,
    compose,
    setup,
    show,
    send,
    io
};

double thread_cpu_seconds();
// Wall clock, seconds since the Unix epoch: the time base of spans (aligned across ranks).
double wall_now_s();

class TraceRecorder {
  public:
    TraceRecorder();
    // Ends the current span and starts one in `stage`; returns the stage it left.
    Stage switch_to(Stage stage);
    // Ends the current span (the recorder can go on with switch_to).
    void close();
    // Records CPU seconds spent by threads beside this one in `stage` (a store's pager: io) as a
    // span of no wall time at now, without touching the open span.
    void charge(Stage stage, double cpu_s);
    // Charges CPU seconds of the rank's other threads (the engine's workers) to the open span, so
    // that a span's cpu_s is the CPU the rank spent in it, on every thread.
    void add_cpu(double cpu_s) {
        if (open_) cpu0_ -= cpu_s;
    }
    const std::vector<TraceSpan>& spans() const { return spans_; }

  private:
    std::vector<TraceSpan> spans_;
    Stage current_ = Stage::setup;
    bool open_ = false;
    double wall0_ = 0, cpu0_ = 0;
};

struct RankTrace {
    int rank = 0;
    std::string label;  // e.g. "master" or "tile 3"
    std::vector<TraceSpan> spans;
};

// An arrow between two ranks' tracks (a screen-region job migrated from its owner to a helper, or
// its result going back), drawn from (from_rank, at start_s) to (to_rank, at end_s).
struct TraceFlow {
    int from_rank = 0, to_rank = 0;
    double start_s = 0, end_s = 0;  // wall clock, the spans' time base
    std::string name;
    std::uint64_t bytes = 0;
};

// Chrome trace-event JSON (opens in Perfetto / chrome://tracing): one process per rank, one
// complete event per span, with its CPU milliseconds in args, and one flow event pair per flow.
void write_chrome_trace(const std::filesystem::path& path, const std::vector<RankTrace>& ranks,
                        const std::vector<TraceFlow>& flows = {});
// rank,label,stage,start_s,wall_s,cpu_s
void write_trace_csv(const std::filesystem::path& path, const std::vector<RankTrace>& ranks);
// The same two, staged in a command's batch: the files appear at batch.commit().
void write_chrome_trace(OutputFiles& batch, const std::filesystem::path& path,
                        const std::vector<RankTrace>& ranks,
                        const std::vector<TraceFlow>& flows = {});
void write_trace_csv(OutputFiles& batch, const std::filesystem::path& path,
                     const std::vector<RankTrace>& ranks);

}  // namespace isowall
