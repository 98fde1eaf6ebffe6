// The HDF5 reader (readers/hdf5_reader.cpp): files written here through libhdf5's C API,
// chunked with deflate and contiguous, in both byte orders, load voxel for voxel; every bad file
// is one line naming the file and the field.
#include <hdf5.h>

#include <array>
#include <fstream>
#include <functional>

#include "readers/read_volume.h"
#include "readers/readers.h"
#include "tests/formats_more_util.h"
#include "tests/plane_stream_util.h"
#include "tests/test_util.h"

namespace isowall {
namespace {

namespace fs = std::filesystem;
using test::expect_input_error;
using test::kDims;

// A handle closed at the end of the scope, so a failed assertion leaks nothing.
struct H5 {
    hid_t id;
    herr_t (*close)(hid_t);
    ~H5() {
        if (id >= 0) close(id);
    }
};

enum class Layout { contiguous, chunked_deflate };

struct Dataset {
    std::string name = "/volume";
    hid_t file_type = H5T_STD_U8LE;  // what the file stores
    hid_t memory_type = H5T_NATIVE_UINT8;
    std::vector<hsize_t> dims{3, 4, 5};  // z y x
    const void* data = nullptr;
    Layout layout = Layout::contiguous;
    // An attribute of three doubles (z y x), or none when the name is empty.
    std::string attribute;
    std::array<double, 3> attribute_value{};
};

void write_attribute(hid_t ds, const Dataset& d) {
    const hsize_t three = 3;
    H5 space{H5Screate_simple(1, &three, nullptr), H5Sclose};
    H5 a{H5Acreate2(ds, d.attribute.c_str(), H5T_IEEE_F64LE, space.id, H5P_DEFAULT, H5P_DEFAULT),
         H5Aclose};
    ASSERT_GE(H5Awrite(a.id, H5T_NATIVE_DOUBLE, d.attribute_value.data()), 0);
}

// Adds dataset `d` to the open file (its groups made on the way).
void add_dataset(hid_t file, const Dataset& d) {
    H5 space{H5Screate_simple(int(d.dims.size()), d.dims.data(), nullptr), H5Sclose};
    H5 lcpl{H5Pcreate(H5P_LINK_CREATE), H5Pclose};
    H5Pset_create_intermediate_group(lcpl.id, 1);
    H5 dcpl{H5Pcreate(H5P_DATASET_CREATE), H5Pclose};
    if (d.layout == Layout::chunked_deflate) {
        std::vector<hsize_t> chunk(d.dims.size(), 2);
        H5Pset_chunk(dcpl.id, int(chunk.size()), chunk.data());
        H5Pset_deflate(dcpl.id, 6);
    }
    H5 ds{H5Dcreate2(file, d.name.c_str(), d.file_type, space.id, lcpl.id, dcpl.id, H5P_DEFAULT),
          H5Dclose};
    ASSERT_GE(ds.id, 0) << d.name;
    if (d.data) {
        ASSERT_GE(H5Dwrite(ds.id, d.memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.data), 0);
    }
    if (!d.attribute.empty()) write_attribute(ds.id, d);
}

// A dataset of no data (its fill value) at `name`: for the cases that fail before the read.
Dataset empty_dataset(const std::string& name, std::vector<hsize_t> dims = {3, 4, 5},
                      hid_t file_type = H5T_STD_U8LE) {
    Dataset d;
    d.name = name;
    d.dims = std::move(dims);
    d.file_type = file_type;
    return d;
}

fs::path write_h5(const fs::path& path, const std::vector<Dataset>& sets,
                  const std::function<void(hid_t)>& extra = {}) {
    H5 file{H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose};
    EXPECT_GE(file.id, 0) << path;
    for (const Dataset& d : sets) add_dataset(file.id, d);
    if (extra) extra(file.id);
    return path;
}

template <class T>
void expect_round_trip(const std::string& name, hid_t file_type, hid_t memory_type, Layout layout) {
    const fs::path dir = test::scratch_dir("formats_hdf5_" + name);
    const std::vector<T> voxels = test::test_voxels<T>();
    Dataset d;
    d.file_type = file_type;
    d.memory_type = memory_type;
    d.data = voxels.data();
    d.layout = layout;
    const fs::path file = write_h5(dir / "v.h5", {d});
    const Volume v = formats::read_hdf5(file, "/volume");
    test::expect_test_volume<T>(v);
    EXPECT_EQ(v.spacing(), glm::vec3(1.0f));
    EXPECT_EQ(test::fact(v, "format"), "HDF5");
    EXPECT_EQ(test::fact(v, "spacing from"), "none in the file (1 1 1)");
    EXPECT_FALSE(v.orientation().known);
    ASSERT_EQ(v.files().size(), 1u);
    EXPECT_EQ(v.files()[0], file);
    EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0) << "a handle left open";
    // Streamed from a child process, a hyperslab of planes at a time.
    test::expect_streams_alike(file.string() + ":/volume");
}

TEST(FormatsHdf5, EveryVoxelTypeInBothByteOrdersAndLayouts) {
    const auto chunked = Layout::chunked_deflate;
    const auto flat = Layout::contiguous;
    expect_round_trip<std::uint8_t>("u8", H5T_STD_U8LE, H5T_NATIVE_UINT8, chunked);
    expect_round_trip<std::int8_t>("i8", H5T_STD_I8LE, H5T_NATIVE_INT8, flat);
    expect_round_trip<std::uint16_t>("u16be", H5T_STD_U16BE, H5T_NATIVE_UINT16, chunked);
    expect_round_trip<std::int16_t>("i16", H5T_STD_I16LE, H5T_NATIVE_INT16, flat);
    expect_round_trip<std::uint32_t>("u32", H5T_STD_U32LE, H5T_NATIVE_UINT32, chunked);
    expect_round_trip<std::int32_t>("i32be", H5T_STD_I32BE, H5T_NATIVE_INT32, flat);
    expect_round_trip<float>("f32", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, chunked);
    expect_round_trip<double>("f64be", H5T_IEEE_F64BE, H5T_NATIVE_DOUBLE, chunked);
}

TEST(FormatsHdf5, SpacingFromElementSizeUmInZyxOrder) {
    const fs::path dir = test::scratch_dir("formats_hdf5_spacing");
    const auto voxels = test::test_voxels<std::uint16_t>();
    for (const char* attr : {"element_size_um", "spacing"}) {
        Dataset d = empty_dataset("/volume", {3, 4, 5}, H5T_STD_U16LE);
        d.memory_type = H5T_NATIVE_UINT16;
        d.data = voxels.data();
        d.attribute = attr;
        d.attribute_value = {2.0, 0.5, 0.25};
        const fs::path file = write_h5(dir / (std::string(attr) + ".h5"), {d});
        const Volume v = formats::read_hdf5(file, "volume");
        EXPECT_EQ(v.spacing(), glm::vec3(0.25f, 0.5f, 2.0f)) << attr;
        EXPECT_EQ(test::fact(v, "spacing from"), "attribute " + std::string(attr) + " (z y x)");
    }
}

TEST(FormatsHdf5, EmptyNameTakesTheOnlyDatasetWhereverItIs) {
    const fs::path dir = test::scratch_dir("formats_hdf5_only");
    const auto voxels = test::test_voxels<float>();
    Dataset d = empty_dataset("/exported/data/raw", {3, 4, 5}, H5T_IEEE_F32LE);
    d.memory_type = H5T_NATIVE_FLOAT;
    d.data = voxels.data();
    const fs::path file = write_h5(dir / "v.h5", {d});
    const Volume v = formats::read_hdf5(file, "");
    test::expect_test_volume<float>(v);
    EXPECT_EQ(test::fact(v, "dataset"), "/exported/data/raw");
    // The same through --volume's FILE:/path spelling.
    test::expect_test_volume<float>(
        formats::read_volume(file.string() + ":/exported/data/raw", {}));
}

TEST(FormatsHdf5, NoneOrSeveralDatasetsNameTheCandidates) {
    const fs::path dir = test::scratch_dir("formats_hdf5_several");
    const fs::path none = write_h5(dir / "none.h5", {}, [](hid_t f) {
        H5 g{H5Gcreate2(f, "/empty", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
    });
    expect_input_error([&] { formats::read_hdf5(none, ""); }, none.string(), "dataset",
                       "holds no dataset");
    const fs::path two = write_h5(dir / "two.h5", {empty_dataset("/a"), empty_dataset("/g/b")});
    expect_input_error([&] { formats::read_hdf5(two, ""); }, two.string(), "dataset",
                       "2 datasets (/a, /g/b)");
}

TEST(FormatsHdf5, BadPathsAreOneLine) {
    const fs::path dir = test::scratch_dir("formats_hdf5_paths");
    const fs::path file = write_h5(dir / "v.h5", {empty_dataset("/x/volume")});
    expect_input_error([&] { formats::read_hdf5(file, "/x"); }, file.string(), "dataset",
                       "/x is a group, not a dataset");
    expect_input_error([&] { formats::read_hdf5(file, "/nothing/here"); }, file.string(), "dataset",
                       "does not exist");
    const fs::path text = dir / "text.h5";
    std::ofstream(text) << "not hdf5 at all\n";
    expect_input_error([&] { formats::read_hdf5(text, ""); }, text.string(), "file",
                       "not an HDF5 file");
    expect_input_error([&] { formats::read_hdf5(dir / "missing.h5", ""); },
                       (dir / "missing.h5").string(), "file", "no such file");
}

// One file of a dataset for each rank, type and size the reader refuses.
fs::path write_refused(const fs::path& path) {
    H5 compound{H5Tcreate(H5T_COMPOUND, 8), H5Tclose};
    H5Tinsert(compound.id, "a", 0, H5T_NATIVE_FLOAT);
    H5Tinsert(compound.id, "b", 4, H5T_NATIVE_FLOAT);
    H5 string{H5Tcopy(H5T_C_S1), H5Tclose};
    H5Tset_size(string.id, 8);
    return write_h5(path, {empty_dataset("/flat", {4, 5}), empty_dataset("/four", {2, 3, 4, 5}),
                           empty_dataset("/pairs", {3, 4, 5}, compound.id),
                           empty_dataset("/words", {3, 4, 5}, string.id),
                           empty_dataset("/wide", {3, 4, 5}, H5T_STD_I64LE),
                           empty_dataset("/thin", {1, 4, 5})});
}

TEST(FormatsHdf5, RankTypeAndSizeProblemsNameTheField) {
    const fs::path file = write_refused(test::scratch_dir("formats_hdf5_bad") / "bad.h5");
    const std::string f = file.string();
    expect_input_error([&] { formats::read_hdf5(file, "/flat"); }, f, "rank", "2 dimensions");
    expect_input_error([&] { formats::read_hdf5(file, "/four"); }, f, "rank", "4 dimensions");
    expect_input_error([&] { formats::read_hdf5(file, "/pairs"); }, f, "type", "compound");
    expect_input_error([&] { formats::read_hdf5(file, "/words"); }, f, "type", "string");
    expect_input_error([&] { formats::read_hdf5(file, "/wide"); }, f, "type", "64-bit integers");
    expect_input_error([&] { formats::read_hdf5(file, "/thin"); }, f, "dims", "got \"5 4 1\"");
    // Every path out closed what it opened: no file, group, dataset or attribute is left.
    EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);
}

// Voxels the dataset declares but the file does not store (chunks never written read as the
// fill value) are refused before anything is allocated: a 2 KB file declaring 100000^3 float64.
TEST(FormatsHdf5, DeclaredVoxelsTheFileDoesNotStoreAreRefused) {
    const fs::path dir = test::scratch_dir("formats_hdf5_unstored");
    const fs::path plain = write_h5(dir / "plain.h5", {empty_dataset("/v", {40, 40, 40})});
    expect_input_error([&] { formats::read_hdf5(plain, ""); }, plain.string(), "data",
                       "/v declares 64000 bytes of voxels and the file stores 0: data never "
                       "written");
    Dataset huge = empty_dataset("/v", {100000, 100000, 100000}, H5T_IEEE_F64LE);
    huge.layout = Layout::chunked_deflate;
    const fs::path claim = write_h5(dir / "claim.h5", {huge});
    EXPECT_LT(fs::file_size(claim), 8192u);
    expect_input_error([&] { formats::read_hdf5(claim, ""); }, claim.string(), "data",
                       "declares 8000000000000000 bytes of voxels and the file stores 0 "
                       "compressed (more than 1100:1)");
    EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0) << "a handle left open";
}

TEST(FormatsHdf5, AMalformedSpacingAttributeIsAnError) {
    const fs::path dir = test::scratch_dir("formats_hdf5_bad_spacing");
    const fs::path file = write_h5(dir / "v.h5", {Dataset{}}, [](hid_t f) {
        H5 ds{H5Dopen2(f, "/volume", H5P_DEFAULT), H5Dclose};
        const hsize_t two = 2;
        H5 space{H5Screate_simple(1, &two, nullptr), H5Sclose};
        H5 a{H5Acreate2(ds.id, "element_size_um", H5T_IEEE_F64LE, space.id, H5P_DEFAULT,
                        H5P_DEFAULT),
             H5Aclose};
        const double v[2] = {1, 2};
        H5Awrite(a.id, H5T_NATIVE_DOUBLE, v);
    });
    expect_input_error([&] { formats::read_hdf5(file, ""); }, file.string(), "element_size_um",
                       "three numbers");
    EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0) << "a handle left open";
}

}  // namespace
}  // namespace isowall
