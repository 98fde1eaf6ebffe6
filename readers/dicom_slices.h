#pragma once
// The geometry of a DICOM series from its slices' headers, as pure functions over numbers: the
// order of the slices along the normal of their plane (ImagePositionPatient projected on
// row x column of ImageOrientationPatient, never the file name or InstanceNumber, which scanners
// and anonymisers number in any order), and the slice spacing from those positions (not
// SliceThickness, which is the thickness of the excitation and may overlap or leave gaps).
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace isowall::formats {

struct SliceHeader {
    std::string file;
    glm::dvec3 position{0};      // ImagePositionPatient (mm, LPS)
    glm::dvec3 row{1, 0, 0};     // ImageOrientationPatient 0-2: along a row (x)
    glm::dvec3 column{0, 1, 0};  // ImageOrientationPatient 3-5: down a column (y)
    int rows = 0, columns = 0;
};

struct SliceOrder {
    std::vector<std::size_t> order;  // indices into the headers, first slice first
    glm::dvec3 normal{0, 0, 1};      // row x column: the direction the slices advance
    double spacing = 1;              // mm between neighbouring slices
};

// The order and spacing of a series' slices. InputError naming the file and the field when the
// slices differ in size or orientation, two share a position, one is missing (a gap more than
// 1.5 spacings) or the spacing varies by more than 10%; `where` names the series.
SliceOrder order_slices(const std::vector<SliceHeader>& slices, const std::string& where);

}  // namespace isowall::formats
