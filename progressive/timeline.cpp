#include "progressive/timeline.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace isowall {

void add_sample(TimelineSample& to, const TimelineSample& s) {
    to.rays += s.rays;
    to.cells_visited += s.cells_visited;
    to.triangles += s.triangles;
    to.groups += s.groups;
    to.t_intersect_s += s.t_intersect_s;
    to.t_propagate_s += s.t_propagate_s;
    to.t_extract_s += s.t_extract_s;
    to.t_render_s += s.t_render_s;
    to.level = std::max(to.level, s.level);
}

namespace {

void encode_timeline(const std::filesystem::path& path, const std::filesystem::path& temporary,
                     const std::vector<TimelineSample>& samples, std::size_t rays_screen) {
    std::ofstream out(temporary);
    if (!out) throw std::runtime_error(path.string() + ": cannot open for writing");
    out << "time_s,rays,rays_share,cells_visited,triangles,groups,final_pixels,c,"
           "t_intersect_s,t_propagate_s,t_extract_s,t_render_s,level\n";
    char line[512];
    for (const auto& s : samples) {
        std::snprintf(
            line, sizeof(line), "%.6f,%zu,%.8f,%zu,%zu,%zu,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d\n",
            s.time_s, s.rays, rays_screen ? double(s.rays) / double(rays_screen) : 0.0,
            s.cells_visited, s.triangles, s.groups, s.correctness.final_pixels, s.correctness.c,
            s.t_intersect_s, s.t_propagate_s, s.t_extract_s, s.t_render_s, s.level);
        out << line;
    }
    out.close();
    if (!out) throw std::runtime_error(path.string() + ": write failed");
}

}  // namespace

void write_timeline_csv(const std::filesystem::path& path,
                        const std::vector<TimelineSample>& samples, std::size_t rays_screen) {
    write_output(path, [&](const std::filesystem::path& t) {
        encode_timeline(path, t, samples, rays_screen);
    });
}

void write_timeline_csv(OutputFiles& batch, const std::filesystem::path& path,
                        const std::vector<TimelineSample>& samples, std::size_t rays_screen) {
    encode_timeline(path, batch.stage(path), samples, rays_screen);
}

std::optional<std::size_t> first_reaching(const std::vector<TimelineSample>& samples,
                                          double threshold, Measure measure) {
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const double m =
            measure == Measure::c ? samples[i].correctness.c : samples[i].correctness.final_pixels;
        if (m >= threshold) return i;
    }
    return std::nullopt;
}

}  // namespace isowall
