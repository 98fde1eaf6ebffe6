#include "readers/dicom_slices.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <glm/geometric.hpp>

#include "core/error.h"

namespace isowall::formats {
namespace {

std::string mm(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g mm", v);
    return buf;
}

void check_alike(const std::vector<SliceHeader>& s) {
    const SliceHeader& a = s.front();
    for (const SliceHeader& b : s) {
        if (b.rows != a.rows || b.columns != a.columns)
            throw InputError(b.file, "Rows/Columns",
                             std::to_string(b.columns) + "x" + std::to_string(b.rows) +
                                 ", but the series' first slice (" + a.file + ") is " +
                                 std::to_string(a.columns) + "x" + std::to_string(a.rows));
        if (glm::length(b.row - a.row) > 1e-3 || glm::length(b.column - a.column) > 1e-3)
            throw InputError(b.file, "ImageOrientationPatient",
                             "differs from the series' first slice (" + a.file +
                                 "): the slices do not lie in parallel planes");
    }
    const glm::dvec3 n = glm::cross(a.row, a.column);
    if (!(glm::length(n) > 0.5))
        throw InputError(a.file, "ImageOrientationPatient",
                         "the row and column directions are not two perpendicular unit vectors");
}

}  // namespace

SliceOrder order_slices(const std::vector<SliceHeader>& slices, const std::string& where) {
    if (slices.size() < 2)
        throw InputError(
            where, "slices",
            "a volume needs at least 2 slices, the series has " + std::to_string(slices.size()));
    check_alike(slices);
    SliceOrder out;
    out.normal = glm::normalize(glm::cross(slices[0].row, slices[0].column));
    std::vector<double> depth(slices.size());
    for (std::size_t i = 0; i < slices.size(); ++i)
        depth[i] = glm::dot(slices[i].position, out.normal);
    out.order.resize(slices.size());
    std::iota(out.order.begin(), out.order.end(), std::size_t{0});
    std::stable_sort(out.order.begin(), out.order.end(),
                     [&](std::size_t a, std::size_t b) { return depth[a] < depth[b]; });
    std::vector<double> gaps;
    for (std::size_t i = 1; i < out.order.size(); ++i)
        gaps.push_back(depth[out.order[i]] - depth[out.order[i - 1]]);
    std::vector<double> sorted = gaps;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    out.spacing = sorted[sorted.size() / 2];
    // Two slices in one place first: the gap that leaves elsewhere is its consequence.
    for (std::size_t i = 0; i < gaps.size(); ++i)
        if (!(gaps[i] > 1e-4))
            throw InputError(slices[out.order[i + 1]].file, "ImagePositionPatient",
                             "the same position as " + slices[out.order[i]].file +
                                 " (two slices in one place: a second series, or a repeat)");
    for (std::size_t i = 0; i < gaps.size(); ++i) {
        const SliceHeader& a = slices[out.order[i]];
        const SliceHeader& b = slices[out.order[i + 1]];
        if (gaps[i] > 1.5 * out.spacing)
            throw InputError(b.file, "ImagePositionPatient",
                             mm(gaps[i]) + " after " + a.file + " where the series' spacing is " +
                                 mm(out.spacing) + ": slices are missing between them");
        if (std::abs(gaps[i] - out.spacing) > 0.1 * out.spacing)
            throw InputError(b.file, "ImagePositionPatient",
                             mm(gaps[i]) + " after " + a.file + " where the series' spacing is " +
                                 mm(out.spacing) + ": the spacing varies along the series");
    }
    return out;
}

}  // namespace isowall::formats
