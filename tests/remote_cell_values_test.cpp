// The voxel values of the cells encoding (remote/cell_values.h): the step a coarse pass's values
// travel to must keep every unit's case, so the client triangulates the server's units.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "remote/cell_predict.h"
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

// The prediction at 1 voxel (cell_predict.h), axis by axis: the mean of two known sides, one side
// carried on by half its slope when the voxel beyond is known, one side alone as it is; the mean
// of the axes' estimates, rounded, within the type; the ring at 2 when none at 1 is known.
TEST(RemoteCellValues, APredictionTakesEachAxisAsItsKnownNeighboursSay) {
    const cells::VoxelBox box{glm::ivec3(0), glm::ivec3(8)};
    auto held_with = [&](std::initializer_list<std::pair<glm::ivec3, int>> values) {
        cells::BoxVoxels<std::uint8_t> held(box, glm::ivec3(8), glm::vec3(1));
        for (const auto& [p, v] : values) {
            held.name(p);
            held.set(p, static_cast<std::uint8_t>(v));
        }
        return held;
    };
    const glm::ivec3 p(4, 4, 4);
    auto at = [&](int dx, int dy, int dz) { return p + glm::ivec3(dx, dy, dz); };
    // x: both sides, 10 and 20 (15); y: one side 40, beyond it 30 (45); z: one side 7 alone (7).
    const auto held = held_with({{at(-1, 0, 0), 10},
                                 {at(1, 0, 0), 20},
                                 {at(0, 1, 0), 40},
                                 {at(0, 2, 0), 30},
                                 {at(0, 0, -1), 7}});
    const auto guess = cells::predict(held, p, std::uint8_t{0});
    EXPECT_EQ(guess.value, 22) << "(15 + 45 + 7) / 3 = 22.3";
    // The axes' estimates 15, 45 and 7 are 38 apart: 9 units of kSpreadUnit (4), 4 bits.
    EXPECT_EQ(guess.spread, 4);
    // One axis alone: its two sides' spread, 10 apart (4 bits); one neighbour alone: its class.
    const auto one_axis = held_with({{at(0, -1, 0), 10}, {at(0, 1, 0), 20}});
    EXPECT_EQ(cells::predict(one_axis, p, std::uint8_t{0}).spread, 4);
    const auto one = held_with({{at(0, 1, 0), 20}});
    EXPECT_EQ(cells::predict(one, p, std::uint8_t{0}).spread, cells::kSpreadClasses - 2);
    // A ramp carried past the type's top stays at 255.
    const auto steep = held_with({{at(1, 0, 0), 250}, {at(2, 0, 0), 100}});
    EXPECT_EQ(cells::predict(steep, p, std::uint8_t{0}).value, 255);
    // Nothing at 1 voxel: the mean of the ring at 2, 9 and 12 (10.5, rounded away from zero).
    const auto far = held_with({{at(-2, 0, 0), 9}, {at(0, 0, 2), 12}});
    const auto ring2 = cells::predict(far, p, std::uint8_t{0});
    EXPECT_EQ(ring2.value, 11);
    EXPECT_EQ(ring2.spread, cells::kSpreadClasses - 1);
    // Nothing known: the value sent before.
    EXPECT_EQ(cells::predict(held_with({}), p, std::uint8_t{77}).value, 77);
}

}  // namespace
}  // namespace isowall::remote
