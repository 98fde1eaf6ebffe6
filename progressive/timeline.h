#pragma once
// The timeline of one progressive frame: samples by rays and by time of what has been cast,
// visited, triangulated and drawn, with the cumulative time of each stage and (after a replay
// against the final image) both correctness measures. Written as CSV for scripts/plot_timeline.py.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

#include "files/output_files.h"
#include "progressive/correctness.h"

namespace isowall {

struct TimelineSample {
    double time_s = 0;
    std::size_t rays = 0;
    std::size_t cells_visited = 0;
    std::size_t triangles = 0;
    std::size_t groups = 0;
    // Cumulative seconds per stage (chapter 2.2: intersection, propagation, extraction, rendering).
    double t_intersect_s = 0, t_propagate_s = 0, t_extract_s = 0, t_render_s = 0;
    int level = 0;            // ray-order level being cast
    Correctness correctness;  // against the final image; filled by a replay
};

// `to` plus what `s` adds: the figures of several frames cast together (the surfaces of one
// picture) at one moment: counts and stage seconds summed, the deepest level.
void add_sample(TimelineSample& to, const TimelineSample& s);

// Columns: time_s, rays, rays_share (of `rays_screen`), cells_visited, triangles, groups,
// final_pixels, c, t_intersect_s, t_propagate_s, t_extract_s, t_render_s, level.
void write_timeline_csv(const std::filesystem::path& path,
                        const std::vector<TimelineSample>& samples, std::size_t rays_screen);
// The same, staged in a command's batch: the file appears at batch.commit().
void write_timeline_csv(OutputFiles& batch, const std::filesystem::path& path,
                        const std::vector<TimelineSample>& samples, std::size_t rays_screen);

enum class Measure { c, final_pixels };
// The first sample whose measure is >= threshold (0..1), if any.
std::optional<std::size_t> first_reaching(const std::vector<TimelineSample>& samples,
                                          double threshold, Measure measure = Measure::c);

}  // namespace isowall
