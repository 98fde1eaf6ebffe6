#pragma once
// A volume that changes over time, given as numbered files: `--volume 'run/head_%03d.nrrd'` names
// every file of the folder whose name is the pattern's with a number in place of the conversion
// (%d, or %0Nd for zero-padded numbers), in any format --volume reads. The numbers found must run
// without a gap; step 0 of the series is the lowest. Every step is opened as a volume of its own
// (and its octree cached under its own name); each must have the first step's voxels.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace isowall {

// A series is at most this long: a bound for a message to check, and more steps than anyone plays.
inline constexpr std::size_t kMaxTimeSteps = 100000;

// Whether `path` is a series pattern: it holds one printf integer conversion (%d or %0Nd).
bool is_series_pattern(std::string_view path);

struct TimeSeries {
    std::string pattern;
    int first = 0;  // the number of step 0
    std::vector<std::filesystem::path> steps;
};

// The steps `pattern` names, in order. Throws an InputError naming the pattern and `option` for a
// pattern with more than one conversion, no file that matches, a gap in the numbers (naming the
// missing step's file), or more than kMaxTimeSteps files.
TimeSeries find_series(const std::string& pattern, const std::string& option);

}  // namespace isowall
