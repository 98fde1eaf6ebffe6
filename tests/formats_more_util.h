#pragma once
// What the HDF5, TIFF and MetaImage reader tests share: a small volume of each voxel type whose
// every voxel differs from its neighbours (so a swapped axis, a reversed slice order or a byte
// order left unswapped changes the values), and the check that an error is one line naming the
// file and the field.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/error.h"
#include "volume/volume.h"

namespace isowall::test {

// 5 x 4 x 3: three different sizes, so dims given in the wrong order fail.
inline constexpr glm::ivec3 kDims{5, 4, 3};

// The voxel (x, y, z) of the test volume: distinct, negative ones for signed types, halves for
// floats; every value fits int8.
template <class T>
T test_value(int x, int y, int z) {
    const int v = x + 7 * y + 31 * z;
    if constexpr (std::is_floating_point_v<T>) return T(v - 40) * T(0.5);
    if constexpr (std::is_signed_v<T>) return T(v - 40);
    return T(v);
}

// The test volume, x fastest.
template <class T>
std::vector<T> test_voxels(glm::ivec3 dims = kDims) {
    std::vector<T> v;
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x) v.push_back(test_value<T>(x, y, z));
    return v;
}

template <class T>
std::vector<std::byte> as_bytes(const std::vector<T>& v) {
    std::vector<std::byte> b(v.size() * sizeof(T));
    std::memcpy(b.data(), v.data(), b.size());
    return b;
}

// `v` holds the test volume of T: its dims, type and every voxel.
template <class T>
void expect_test_volume(const Volume& v, glm::ivec3 dims = kDims) {
    ASSERT_EQ(v.dims(), dims);
    ASSERT_EQ(v.type(), voxel_type_of<T>()) << type_name(v.type());
    const std::vector<T> want = test_voxels<T>(dims);
    const VolumeView<T> got = v.view<T>();
    for (std::size_t i = 0; i < want.size(); ++i)
        ASSERT_EQ(got.data[i], want[i]) << "voxel " << i << " of " << type_name(v.type());
}

// The value of fact `name`, or "" when the volume has none.
inline std::string fact(const Volume& v, const std::string& name) {
    for (const VolumeFact& f : v.facts())
        if (f.name == name) return f.value;
    return "";
}

// `load` throws one InputError line that names `where` and `field` (and holds `words`).
template <class F>
void expect_input_error(F&& load, const std::string& where, const std::string& field,
                        const std::string& words = "") {
    try {
        load();
        ADD_FAILURE() << "loaded; expected an InputError naming " << where << " and " << field;
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(where + ": ", 0), 0u) << what;
        EXPECT_NE(what.find(": " + field + ": "), std::string::npos) << what;
        EXPECT_NE(what.find(words), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
}

}  // namespace isowall::test
