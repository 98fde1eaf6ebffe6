// The voxel values of the cells encoding (remote/cell_values.h): the step a coarse pass's values
// travel to must keep every unit's case, so the client triangulates the server's units.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "remote/cell_values.h"

namespace isowall::remote {
namespace {

// What keeps a coarse pass's cases the server's: a value's bin's middle lies on the value's side
// of the isovalue and in its bin, for every value of the type, at isovalues on and between
// values, for every step.
template <class T>
void expect_bins_keep_sides(double iso) {
    for (int shift = 2; shift <= 8 * int(sizeof(T)) - 2; shift += 3) {
        const cells::Bins<T> bins{iso, shift};
        const std::int64_t lo = std::numeric_limits<T>::lowest(),
                           hi = std::numeric_limits<T>::max();
        const std::int64_t stride = sizeof(T) == 1 ? 1 : 7;
        for (std::int64_t v = lo; v <= hi; v += stride) {
            const T middle = bins.middle(bins.of(static_cast<T>(v)));
            ASSERT_EQ(middle >= iso, double(v) >= iso)
                << "value " << v << ", iso " << iso << ", step 2^" << shift;
            ASSERT_EQ(bins.of(middle), bins.of(static_cast<T>(v)))
                << "value " << v << ", iso " << iso << ", step 2^" << shift;
        }
    }
}

TEST(RemoteCellValues, AStepsBinsKeepEveryValuesSideOfTheIsovalue) {
    for (double iso : {0.0, 1.0, 40.0, 40.5, 254.9, 255.0})
        expect_bins_keep_sides<std::uint8_t>(iso);
    for (double iso : {-128.0, -0.5, 0.0, 17.25, 127.0}) expect_bins_keep_sides<std::int8_t>(iso);
    for (double iso : {0.0, 600.0, 1650.5, 65535.0}) expect_bins_keep_sides<std::uint16_t>(iso);
    for (double iso : {-32768.0, -9000.5, 0.0, 32767.0}) expect_bins_keep_sides<std::int16_t>(iso);
}

}  // namespace
}  // namespace isowall::remote
