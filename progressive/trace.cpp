#include "progressive/trace.h"

#include <time.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <stdexcept>

namespace isowall {

double wall_now_s() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
        .count();
}

double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

TraceRecorder::TraceRecorder() {
    switch_to(Stage::setup);
}

void TraceRecorder::charge(Stage stage, double cpu_s) {
    if (cpu_s > 0) spans_.push_back({static_cast<std::uint8_t>(stage), wall_now_s(), 0.0, cpu_s});
}

Stage TraceRecorder::switch_to(Stage stage) {
    const Stage left = current_;
    const double wall = wall_now_s(), cpu = thread_cpu_seconds();
    if (open_) {
        // Consecutive spans of one stage merge, so a chatty boundary does not grow the list.
        if (!spans_.empty() && spans_.back().stage == static_cast<std::uint8_t>(current_) &&
            spans_.back().start_s + spans_.back().wall_s >= wall0_ - 1e-9) {
            spans_.back().wall_s = wall - spans_.back().start_s;
            spans_.back().cpu_s += cpu - cpu0_;
        } else {
            spans_.push_back(
                {static_cast<std::uint8_t>(current_), wall0_, wall - wall0_, cpu - cpu0_});
        }
    }
    current_ = stage;
    open_ = true;
    wall0_ = wall;
    cpu0_ = cpu;
    return left;
}

void TraceRecorder::close() {
    switch_to(current_);
    open_ = false;
}

namespace {

// Opens `temporary` (staged for `path`, which errors name), lets `body` write, checks the stream.
void write_text(const std::filesystem::path& path, const std::filesystem::path& temporary,
                const std::function<void(std::ostream&)>& body) {
    std::ofstream out(temporary);
    if (!out) throw std::runtime_error(path.string() + ": cannot open for writing");
    body(out);
    out.close();
    if (!out) throw std::runtime_error(path.string() + ": write failed");
}

void chrome_trace(std::ostream& out, const std::vector<RankTrace>& ranks,
                  const std::vector<TraceFlow>& flows) {
    double t0 = 0;
    bool first_span = true;
    for (const RankTrace& r : ranks)
        for (const TraceSpan& s : r.spans)
            if (first_span || s.start_s < t0) {
                t0 = s.start_s;
                first_span = false;
            }
    out << "{\"displayTimeUnit\": \"ms\", \"traceEvents\": [\n";
    bool first = true;
    char line[512];
    for (const RankTrace& r : ranks) {
        std::snprintf(line, sizeof(line),
                      "%s{\"name\": \"process_name\", \"ph\": \"M\", \"pid\": %d, \"tid\": 0, "
                      "\"args\": {\"name\": \"rank %d (%s)\"}}",
                      first ? "" : ",\n", r.rank, r.rank, r.label.c_str());
        out << line;
        first = false;
        for (const TraceSpan& s : r.spans) {
            std::snprintf(
                line, sizeof(line),
                ",\n{\"name\": \"%s\", \"ph\": \"X\", \"pid\": %d, \"tid\": 0, \"ts\": %.1f, "
                "\"dur\": %.1f, \"args\": {\"cpu_ms\": %.3f}}",
                kTraceStages[s.stage], r.rank, (s.start_s - t0) * 1e6, s.wall_s * 1e6,
                s.cpu_s * 1e3);
            out << line;
        }
    }
    // Flow events bind to the slice that encloses them on each track ("bp": "e" at the end).
    for (std::size_t i = 0; i < flows.size(); ++i) {
        const TraceFlow& f = flows[i];
        std::snprintf(line, sizeof(line),
                      ",\n{\"name\": \"%s\", \"cat\": \"job\", \"ph\": \"s\", \"id\": %zu, "
                      "\"pid\": %d, \"tid\": 0, \"ts\": %.1f, \"args\": {\"bytes\": %llu}}"
                      ",\n{\"name\": \"%s\", \"cat\": \"job\", \"ph\": \"f\", \"bp\": \"e\", "
                      "\"id\": %zu, \"pid\": %d, \"tid\": 0, \"ts\": %.1f}",
                      f.name.c_str(), i, f.from_rank, (f.start_s - t0) * 1e6,
                      (unsigned long long)f.bytes, f.name.c_str(), i, f.to_rank,
                      (f.end_s - t0) * 1e6);
        out << line;
    }
    out << "\n]}\n";
}

void trace_csv(std::ostream& out, const std::vector<RankTrace>& ranks) {
    out << "rank,label,stage,start_s,wall_s,cpu_s\n";
    char line[256];
    for (const RankTrace& r : ranks)
        for (const TraceSpan& s : r.spans) {
            std::snprintf(line, sizeof(line), "%d,%s,%s,%.6f,%.6f,%.6f\n", r.rank, r.label.c_str(),
                          kTraceStages[s.stage], s.start_s, s.wall_s, s.cpu_s);
            out << line;
        }
}

}  // namespace

void write_chrome_trace(OutputFiles& batch, const std::filesystem::path& path,
                        const std::vector<RankTrace>& ranks, const std::vector<TraceFlow>& flows) {
    write_text(path, batch.stage(path), [&](std::ostream& o) { chrome_trace(o, ranks, flows); });
}

void write_chrome_trace(const std::filesystem::path& path, const std::vector<RankTrace>& ranks,
                        const std::vector<TraceFlow>& flows) {
    OutputFiles batch;
    write_chrome_trace(batch, path, ranks, flows);
    batch.commit();
}

void write_trace_csv(OutputFiles& batch, const std::filesystem::path& path,
                     const std::vector<RankTrace>& ranks) {
    write_text(path, batch.stage(path), [&](std::ostream& o) { trace_csv(o, ranks); });
}

void write_trace_csv(const std::filesystem::path& path, const std::vector<RankTrace>& ranks) {
    OutputFiles batch;
    write_trace_csv(batch, path, ranks);
    batch.commit();
}

}  // namespace isowall
