// Loaders: NRRD (attached, detached, raw, gzip) and raw agree in every type and both endians.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>

#include "core/error.h"
#include "tests/test_util.h"
#include "volume/volume.h"

namespace isowall {
namespace {

constexpr glm::ivec3 kDims{7, 5, 3};  // odd sizes on purpose

std::string nrrd_type(VoxelType t) {
    switch (t) {
        case VoxelType::u8:
            return "uchar";
        case VoxelType::i8:
            return "signed char";
        case VoxelType::u16:
            return "ushort";
        case VoxelType::i16:
            return "short";
        case VoxelType::u32:
            return "uint";
        case VoxelType::i32:
            return "int";
        case VoxelType::f32:
            return "float";
        case VoxelType::f64:
            return "double";
    }
    return "";
}

// Host-order voxels with values that use every byte (so a wrong swap shows).
std::vector<std::byte> make_values(VoxelType t, std::size_t count) {
    std::vector<std::byte> bytes(count * voxel_size(t));
    std::mt19937 rng(42);
    dispatch_voxel_type(t, [&](auto tag) {
        using T = decltype(tag);
        for (std::size_t i = 0; i < count; ++i) {
            T v;
            if constexpr (std::is_floating_point_v<T>) {
                v = static_cast<T>(std::uniform_real_distribution<double>(-1e3, 1e3)(rng));
            } else {
                v = static_cast<T>(rng());
            }
            std::memcpy(bytes.data() + i * sizeof(T), &v, sizeof(T));
        }
    });
    return bytes;
}

void write_file(const std::filesystem::path& p, const std::string& text,
                std::span<const std::byte> data) {
    std::ofstream out(p, std::ios::binary);
    out << text;
    out.write(reinterpret_cast<const char*>(data.data()),
              static_cast<std::streamsize>(data.size()));
}

std::string header(VoxelType t, Endian e, const std::string& data_file) {
    std::string h = "NRRD0004\ntype: " + nrrd_type(t) +
                    "\ndimension: 3\nsizes: 7 5 3\n"
                    "spacings: 0.5 1 2\nencoding: raw\n";
    if (voxel_size(t) > 1)
        h += std::string("endian: ") + (e == Endian::big ? "big" : "little") + "\n";
    if (!data_file.empty()) h += "data file: " + data_file + "\n";
    return h;
}

class LoaderAgreement : public ::testing::TestWithParam<std::tuple<VoxelType, Endian>> {};

TEST_P(LoaderAgreement, NrrdAndRawGiveTheSameVoxels) {
    const auto [type, endian] = GetParam();
    const std::string tag = std::string(type_name(type)) + (endian == Endian::big ? "_be" : "_le");
    const auto dir = test::scratch_dir("loader_" + tag);
    const std::size_t count = std::size_t(kDims.x) * kDims.y * kDims.z;
    const auto host = make_values(type, count);
    auto file_bytes = host;
    if (endian != host_endian()) swap_bytes(file_bytes, voxel_size(type));

    write_file(dir / "v.raw", "", file_bytes);
    write_file(dir / "v.nhdr", header(type, endian, "v.raw"), {});
    write_file(dir / "v.nrrd", header(type, endian, "") + "\n", file_bytes);

    RawSpec spec;
    spec.dims = kDims;
    spec.type = type;
    spec.endian = endian;
    spec.spacing = {0.5f, 1.0f, 2.0f};
    const Volume raw = load_raw(dir / "v.raw", spec);
    const Volume detached = load_nrrd(dir / "v.nhdr");
    const Volume attached = load_nrrd(dir / "v.nrrd");
    for (const Volume* v : {&raw, &detached, &attached}) {
        SCOPED_TRACE(v->source());
        EXPECT_EQ(v->type(), type);
        EXPECT_EQ(v->dims(), kDims);
        EXPECT_EQ(v->spacing(), glm::vec3(0.5f, 1.0f, 2.0f));
        ASSERT_EQ(v->bytes().size(), host.size());
        EXPECT_EQ(std::memcmp(v->bytes().data(), host.data(), host.size()), 0);
    }
    // Host byte order is mapped, not copied; the other order must be decoded into memory.
    const bool host_order = endian == host_endian() || voxel_size(type) == 1;
    EXPECT_EQ(raw.mapped(), host_order);
    EXPECT_EQ(detached.mapped(), host_order);

    // gzip through Teem, attached and detached.
    save_nrrd(dir / "g.nrrd", raw, "gzip", host_endian());
    save_nrrd(dir / "g.nhdr", raw, "gzip", host_endian());
    for (const char* name : {"g.nrrd", "g.nhdr"}) {
        const Volume g = load_nrrd(dir / name);
        SCOPED_TRACE(name);
        EXPECT_FALSE(g.mapped());
        EXPECT_EQ(g.spacing(), glm::vec3(0.5f, 1.0f, 2.0f));
        ASSERT_EQ(g.bytes().size(), host.size());
        EXPECT_EQ(std::memcmp(g.bytes().data(), host.data(), host.size()), 0);
    }
}

INSTANTIATE_TEST_SUITE_P(AllTypes, LoaderAgreement,
                         ::testing::Combine(::testing::Values(VoxelType::u8, VoxelType::i8,
                                                              VoxelType::u16, VoxelType::i16,
                                                              VoxelType::u32, VoxelType::i32,
                                                              VoxelType::f32, VoxelType::f64),
                                            ::testing::Values(Endian::little, Endian::big)),
                         [](const auto& info) {
                             return std::string(type_name(std::get<0>(info.param))) +
                                    (std::get<1>(info.param) == Endian::big ? "_big" : "_little");
                         });

TEST(Volume, SizeMismatchIsAnErrorNamingTheFile) {
    const auto dir = test::scratch_dir("volume_size");
    const std::vector<std::byte> bytes(7 * 5 * 3 - 1);
    write_file(dir / "short.raw", "", bytes);
    RawSpec spec;
    spec.dims = kDims;
    try {
        load_raw(dir / "short.raw", spec);
        FAIL() << "expected an error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("short.raw"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("shorter"), std::string::npos) << e.what();
    }
    const std::vector<std::byte> more(7 * 5 * 3 + 1);
    write_file(dir / "v.raw", "", more);
    write_file(dir / "v.nhdr", header(VoxelType::u8, Endian::little, "v.raw"), {});
    EXPECT_THROW(load_nrrd(dir / "v.nhdr"), InputError);
}

TEST(Volume, ParseVoxelTypeKnowsNrrdSpellings) {
    EXPECT_EQ(parse_voxel_type("ushort"), VoxelType::u16);
    EXPECT_EQ(parse_voxel_type("float64"), VoxelType::f64);
    EXPECT_FALSE(parse_voxel_type("int64").has_value());
}

TEST(Volume, SharedCtHeadLoadsMapped) {
    const auto data = test::shared_data_dir();
    if (!data) GTEST_SKIP() << "../shared/data is absent: skipping the CT head";
    const Volume v = load_nrrd(*data / "cthead.nhdr");
    EXPECT_EQ(v.dims(), glm::ivec3(256, 256, 113));
    EXPECT_EQ(v.type(), VoxelType::u16);
    EXPECT_EQ(v.spacing(), glm::vec3(1, 1, 2));
    EXPECT_TRUE(v.mapped());
}

}  // namespace
}  // namespace isowall
