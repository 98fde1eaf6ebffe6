// HDF5 through libhdf5's C API. The library gives us the file's structure, the chunking and
// compression filters, and the conversion from the file's byte order and type to ours (we read
// with the native memory type that matches the stored class, size and sign). What we add: the
// choice of dataset, the checks of rank, type and size before anything is allocated, and the
// spacing from the attributes microscopy tools write (ImageJ and ilastik: element_size_um).
#include <hdf5.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/number.h"
#include "readers/plane_stack.h"
#include "readers/readers.h"
#include "readers/voxel_ops.h"
#include "volume/load_checks.h"

namespace isowall::formats {
namespace fs = std::filesystem;
namespace {

// An HDF5 identifier, closed on every path out by the function of its kind.
class Handle {
  public:
    using Closer = herr_t (*)(hid_t);
    Handle(hid_t id, Closer close) : id_(id), close_(close) {}
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
    ~Handle() {
        if (id_ >= 0) close_(id_);
    }
    hid_t get() const { return id_; }
    bool valid() const { return id_ >= 0; }

  private:
    hid_t id_;
    Closer close_;
};

Handle open_file(const fs::path& file, const std::string& where) {
    check_regular_file(file, where, "file");
    if (H5Fis_hdf5(file.c_str()) <= 0)
        throw InputError(where, "file", "not an HDF5 file (no HDF5 signature)");
    Handle f(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!f.valid()) throw InputError(where, "file", "libhdf5 cannot open it");
    return f;
}

// What a walk of the file found: how many datasets, and the first few names for the message.
struct DatasetList {
    std::size_t count = 0;
    std::vector<std::string> names;
};
constexpr std::size_t kNamesListed = 5;

herr_t note_dataset(hid_t group, const char* name, const H5L_info_t* info, void* data) {
    // Only hard links: a soft link to a dataset would count that dataset twice.
    if (info->type != H5L_TYPE_HARD) return 0;
    Handle obj(H5Oopen(group, name, H5P_DEFAULT), H5Oclose);
    if (!obj.valid() || H5Iget_type(obj.get()) != H5I_DATASET) return 0;
    auto& list = *static_cast<DatasetList*>(data);
    if (list.names.size() < kNamesListed) list.names.push_back(std::string("/").append(name));
    ++list.count;
    return 0;
}

std::string joined(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

// The file's only dataset: an empty name asks for it, and two or more are ambiguous.
std::string only_dataset(hid_t file, const std::string& where) {
    DatasetList list;
    if (H5Lvisit(file, H5_INDEX_NAME, H5_ITER_INC, note_dataset, &list) < 0)
        throw InputError(where, "dataset", "libhdf5 cannot walk the file's groups");
    if (list.count == 0) throw InputError(where, "dataset", "the file holds no dataset");
    if (list.count > 1)
        throw InputError(where, "dataset",
                         "the file holds " + std::to_string(list.count) + " datasets (" +
                             joined(list.names) + (list.count > list.names.size() ? ", ..." : "") +
                             "); name one as FILE:/path");
    return list.names.front();
}

// The dataset at `name`, as an object handle (which the H5D functions take).
Handle open_dataset(hid_t file, const std::string& name, const std::string& where) {
    Handle obj(H5Oopen(file, name.c_str(), H5P_DEFAULT), H5Oclose);
    if (!obj.valid())
        throw InputError(where, "dataset", quote(name) + " does not exist in the file");
    switch (H5Iget_type(obj.get())) {
        case H5I_DATASET:
            return obj;
        case H5I_GROUP:
            throw InputError(where, "dataset", name + " is a group, not a dataset");
        case H5I_DATATYPE:
            throw InputError(where, "dataset", name + " is a named datatype, not a dataset");
        default:
            throw InputError(where, "dataset", name + " is not a dataset");
    }
}

std::string class_name(H5T_class_t c) {
    switch (c) {
        case H5T_COMPOUND:
            return "a compound type";
        case H5T_STRING:
            return "a string type";
        case H5T_ENUM:
            return "an enum type";
        case H5T_ARRAY:
            return "an array type";
        case H5T_VLEN:
            return "a variable-length type";
        case H5T_BITFIELD:
            return "a bitfield type";
        case H5T_OPAQUE:
            return "an opaque type";
        case H5T_REFERENCE:
            return "a reference type";
        case H5T_TIME:
            return "a time type";
        default:
            return "a type";
    }
}

// Our voxel type for the stored class, size and sign (either byte order: libhdf5 converts).
VoxelType voxel_type_of(hid_t dtype, const std::string& name, const std::string& where) {
    const H5T_class_t cls = H5Tget_class(dtype);
    const std::size_t size = H5Tget_size(dtype);
    const std::string what = name + " holds ";
    if (cls == H5T_INTEGER) {
        const bool is_signed = H5Tget_sign(dtype) == H5T_SGN_2;
        if (size == 1) return is_signed ? VoxelType::i8 : VoxelType::u8;
        if (size == 2) return is_signed ? VoxelType::i16 : VoxelType::u16;
        if (size == 4) return is_signed ? VoxelType::i32 : VoxelType::u32;
        throw InputError(where, "type",
                         what + std::to_string(size * 8) +
                             "-bit integers; isowall reads 8, 16 and 32-bit integers");
    }
    if (cls == H5T_FLOAT) {
        if (size == 4) return VoxelType::f32;
        if (size == 8) return VoxelType::f64;
        throw InputError(
            where, "type",
            what + std::to_string(size * 8) + "-bit floats; isowall reads 32 and 64-bit floats");
    }
    throw InputError(where, "type",
                     what + class_name(cls) + "; isowall reads one scalar integer or float");
}

hid_t native_type(VoxelType t) {
    switch (t) {
        case VoxelType::u8:
            return H5T_NATIVE_UINT8;
        case VoxelType::i8:
            return H5T_NATIVE_INT8;
        case VoxelType::u16:
            return H5T_NATIVE_UINT16;
        case VoxelType::i16:
            return H5T_NATIVE_INT16;
        case VoxelType::u32:
            return H5T_NATIVE_UINT32;
        case VoxelType::i32:
            return H5T_NATIVE_INT32;
        case VoxelType::f32:
            return H5T_NATIVE_FLOAT;
        case VoxelType::f64:
            return H5T_NATIVE_DOUBLE;
    }
    return H5T_NATIVE_UINT8;
}

// Our dims (x y z) from the dataspace's C order (z y x: the last varies fastest).
glm::ivec3 dataset_dims(hid_t ds, VoxelType type, const std::string& name,
                        const std::string& where) {
    Handle space(H5Dget_space(ds), H5Sclose);
    const int rank = space.valid() ? H5Sget_simple_extent_ndims(space.get()) : -1;
    if (rank != 3)
        throw InputError(
            where, "rank",
            name + " has " + std::to_string(rank) + " dimensions; isowall reads a 3-D dataset");
    std::array<hsize_t, 3> d{};
    H5Sget_simple_extent_dims(space.get(), d.data(), nullptr);
    const std::uint64_t sizes[3] = {d[2], d[1], d[0]};
    return checked_dims(where, "dims", sizes, type);
}

// A filter the file needs and this libhdf5 lacks (szip, blosc, lz4 plugins) is named up front;
// otherwise the read fails with no word of why.
void check_filters(hid_t ds, const std::string& where) {
    Handle dcpl(H5Dget_create_plist(ds), H5Pclose);
    if (!dcpl.valid()) return;
    const int n = H5Pget_nfilters(dcpl.get());
    for (int i = 0; i < n; ++i) {
        unsigned flags = 0, config = 0;
        std::size_t nvalues = 0;
        std::array<char, 64> fname{};
        const H5Z_filter_t id = H5Pget_filter2(dcpl.get(), unsigned(i), &flags, &nvalues, nullptr,
                                               fname.size(), fname.data(), &config);
        if (id >= 0 && H5Zfilter_avail(id) <= 0)
            throw InputError(where, "filter",
                             "the data needs filter " + std::to_string(id) + " (" +
                                 clip(fname.data()) + "), which this libhdf5 does not have");
    }
}

// The most a filter in libhdf5's reach inflates data: deflate tops out near 1032:1 (a run of
// zeros), the others (shuffle, fletcher32, nbit, scaleoffset) less.
constexpr std::uint64_t kMaxInflation = 1100;

// The voxels the dataset declares must be stored in the file (compressed: within what deflate
// could inflate them from), before a byte of memory or disk is spent on them: libhdf5 gives the
// fill value for every chunk never written, so 2 KB declaring 100000^3 float64 would read as 8 PB
// of zeros. Stored bytes past the file's size mean a file cut short.
void check_storage(hid_t ds, glm::ivec3 dims, const std::string& where, const std::string& name,
                   const fs::path& file) {
    const Handle dtype(H5Dget_type(ds), H5Tclose);
    const Handle dcpl(H5Dget_create_plist(ds), H5Pclose);
    if (!dtype.valid() || !dcpl.valid()) return;
    const std::uint64_t declared =
        *checked_product({std::uint64_t(dims.x), std::uint64_t(dims.y), std::uint64_t(dims.z),
                          H5Tget_size(dtype.get())});
    const std::uint64_t stored = H5Dget_storage_size(ds);
    const bool filtered = H5Pget_nfilters(dcpl.get()) > 0;
    const std::uint64_t least = filtered ? declared / kMaxInflation : declared;
    if (stored < least)
        throw InputError(
            where, "data",
            name + " declares " + std::to_string(declared) +
                " bytes of voxels and the file stores " + std::to_string(stored) +
                (filtered ? " compressed (more than " + std::to_string(kMaxInflation) + ":1)"
                          : "") +
                ": data never written, or a damaged file");
    std::error_code ec;
    const std::uint64_t size = fs::file_size(file, ec);
    if (!ec && stored > size)
        throw InputError(where, "data",
                         name + " stores " + std::to_string(stored) + " bytes, the file holds " +
                             std::to_string(size) + " (a file cut short)");
}

// Three numbers of attribute `attr` of the dataset, z y x, or nullopt when it has none.
std::optional<std::array<double, 3>> zyx_attribute(hid_t ds, const char* attr,
                                                   const std::string& where) {
    if (H5Aexists(ds, attr) <= 0) return std::nullopt;
    Handle a(H5Aopen(ds, attr, H5P_DEFAULT), H5Aclose);
    Handle space(H5Aget_space(a.get()), H5Sclose);
    Handle type(H5Aget_type(a.get()), H5Tclose);
    const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
    std::array<double, 3> v{};
    if (!space.valid() || H5Sget_simple_extent_npoints(space.get()) != 3 ||
        (cls != H5T_INTEGER && cls != H5T_FLOAT) ||
        H5Aread(a.get(), H5T_NATIVE_DOUBLE, v.data()) < 0)
        throw InputError(where, attr, "expected three numbers (z y x)");
    return v;
}

// Spacing from element_size_um (ImageJ, ilastik) or spacing, both z y x; else 1 1 1.
glm::vec3 dataset_spacing(hid_t ds, const std::string& where, std::vector<VolumeFact>& facts) {
    for (const char* attr : {"element_size_um", "spacing"}) {
        if (const auto v = zyx_attribute(ds, attr, where)) {
            facts.push_back({"spacing from", std::string("attribute ") + attr + " (z y x)"});
            return {float((*v)[2]), float((*v)[1]), float((*v)[0])};
        }
    }
    facts.push_back({"spacing from", "none in the file (1 1 1)"});
    return glm::vec3(1.0f);
}

// The open file and dataset the stack's reads share.
struct OpenDataset {
    Handle file, dataset;
};

}  // namespace

PlaneStack hdf5_planes(const fs::path& file, const std::string& dataset) {
    const std::string where = file.string();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // libhdf5's stack dumps; ours is the one line
    Handle f = open_file(file, where);
    const std::string name = dataset.empty() ? only_dataset(f.get(), where) : dataset;
    Handle dset = open_dataset(f.get(), name, where);
    auto open = std::make_shared<OpenDataset>(OpenDataset{std::move(f), std::move(dset)});
    const hid_t ds = open->dataset.get();
    const Handle dtype(H5Dget_type(ds), H5Tclose);
    if (!dtype.valid()) throw InputError(where, "type", "libhdf5 cannot read the type of " + name);
    PlaneStack stack;
    Decoded& d = stack.head;
    d.type = voxel_type_of(dtype.get(), name, where);
    d.dims = dataset_dims(ds, d.type, name, where);
    check_filters(ds, where);
    d.facts.push_back({"dataset", name});
    d.spacing = dataset_spacing(ds, where, d.facts);
    check_storage(ds, d.dims, where, name, file);
    d.format = "HDF5";
    d.files = {file};
    stack.size_field = "dims";
    // Each call reads its planes as one hyperslab (z y x in the file's C order).
    const glm::ivec3 dims = d.dims;
    const hid_t mem_type = native_type(d.type);
    stack.read = [open, dims, mem_type, where, name](int z0, int z1, std::byte* to) {
        const hsize_t start[3] = {hsize_t(z0), 0, 0};
        const hsize_t count[3] = {hsize_t(z1 - z0), hsize_t(dims.y), hsize_t(dims.x)};
        Handle space(H5Dget_space(open->dataset.get()), H5Sclose);
        Handle mem(H5Screate_simple(3, count, nullptr), H5Sclose);
        if (!space.valid() || !mem.valid() ||
            H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0 ||
            H5Dread(open->dataset.get(), mem_type, mem.get(), space.get(), H5P_DEFAULT, to) < 0)
            throw InputError(where, "data",
                             "libhdf5 cannot read the voxels of " + name + " (slices " +
                                 std::to_string(z0) + " to " + std::to_string(z1 - 1) +
                                 "; the file is damaged or cut short)");
    };
    return stack;
}

Volume read_hdf5(const fs::path& file, const std::string& dataset) {
    return read_whole(hdf5_planes(file, dataset), file.string());
}

}  // namespace isowall::formats
