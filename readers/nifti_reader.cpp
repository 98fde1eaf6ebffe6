// NIfTI through niftilib (nifti2_io reads NIfTI-1 and NIfTI-2, .nii, .nii.gz and .hdr/.img
// pairs, and swaps bytes). What it leaves to us: the scale checked as the file wrote it (the
// library turns a NaN or infinite scl_slope into 0, which the standard reads as "no scaling"),
// the size checked before the data is read, and the orientation turned from RAS into LPS.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include <nifti2_io.h>

#include "core/error.h"
#include "readers/plane_stack.h"
#include "readers/readers.h"
#include "readers/voxel_ops.h"
#include "volume/load_checks.h"

namespace isowall::formats {
namespace fs = std::filesystem;
namespace {

// niftilib prints its own "** ERROR" lines to stderr whatever its debug level; ours is the one
// line a user sees, so stderr is pointed at /dev/null while a niftilib call runs. Volumes load
// before any thread of ours prints.
class QuietStderr {
  public:
    QuietStderr() : saved_(::dup(STDERR_FILENO)) {
        std::fflush(stderr);
        const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
        if (null >= 0) {
            ::dup2(null, STDERR_FILENO);
            ::close(null);
        }
    }
    ~QuietStderr() {
        std::fflush(stderr);
        if (saved_ >= 0) {
            ::dup2(saved_, STDERR_FILENO);
            ::close(saved_);
        }
    }
    QuietStderr(const QuietStderr&) = delete;
    QuietStderr& operator=(const QuietStderr&) = delete;

  private:
    int saved_;
};

// An uncompressed image file must hold the voxels before they are read: niftilib allocates what
// the header says first, so a short file claiming gigabytes would cost gigabytes. A gzip stream
// proves its length only as it is inflated (its trailer holds the length modulo 2^32, which any
// writer may set): read_whole grows its buffer as the stream delivers (PlaneStack::read_unproven).
void check_data_present(const std::string& image, std::uint64_t offset, glm::ivec3 dims,
                        VoxelType type, const std::string& where) {
    if (nifti_is_gzfile(image.c_str())) return;
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(image, ec);
    if (ec) throw InputError(where, "data", "cannot read the image file " + quote_bounded(image));
    const std::string holder =
        image == where ? "the file" : "the image file " + quote_bounded(image);
    if (offset > size)
        throw InputError(where, "vox_offset",
                         "the voxels start at byte " + std::to_string(offset) +
                             ", past the end of " + holder + " (" + std::to_string(size) +
                             " bytes)");
    const std::uint64_t need = offset + voxel_bytes(dims, type);  // both below 2^63
    if (size < need)
        throw InputError(where, "dim",
                         std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                             std::to_string(dims.z) + " " + std::string(type_name(type)) +
                             " voxels from vox_offset " + std::to_string(offset) + " end at byte " +
                             std::to_string(need) + ", " + holder + " holds " +
                             std::to_string(size) + " (a truncated file)");
}

struct NiftiDeleter {
    void operator()(nifti_image* n) const { nifti_image_free(n); }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiDeleter>;

std::optional<VoxelType> voxel_type_of_nifti(int datatype) {
    switch (datatype) {
        case DT_UINT8:
            return VoxelType::u8;
        case DT_INT8:
            return VoxelType::i8;
        case DT_UINT16:
            return VoxelType::u16;
        case DT_INT16:
            return VoxelType::i16;
        case DT_UINT32:
            return VoxelType::u32;
        case DT_INT32:
            return VoxelType::i32;
        case DT_FLOAT32:
            return VoxelType::f32;
        case DT_FLOAT64:
            return VoxelType::f64;
        default:
            return std::nullopt;
    }
}

// What the header holds before niftilib adjusts it: niftilib turns a NaN or infinite scl_slope
// into 0 (the standard's "not scaled"), and casts vox_offset to an integer, so a NaN, 1e10 or 352.5
// becomes some other offset (a negative one it counts from the end of the file).
struct RawHeader {
    Scaling scaling;
    double vox_offset = 0;
    bool one_file = false;           // .nii: the voxels follow the header in the same file
    std::uint64_t header_bytes = 0;  // of a .nii: 348 + 4 (extension flags), 540 for NIfTI-2
    std::string version;             // "NIfTI-1", "NIfTI-2" (ANALYZE 7.5 reads as NIfTI-1)
};

RawHeader raw_header(const fs::path& path, const std::string& where) {
    int version = 0;
    void* raw = nifti_read_header(path.c_str(), &version, 1);
    if (!raw) throw InputError(where, "header", "not a NIfTI-1 or NIfTI-2 header niftilib reads");
    RawHeader r;
    if (version == 2) {
        const auto* h = static_cast<const nifti_2_header*>(raw);
        r = {{h->scl_slope, h->scl_inter},
             double(h->vox_offset),
             h->magic[1] == '+',
             540,
             "NIfTI-2"};
    } else {
        const auto* h = static_cast<const nifti_1_header*>(raw);
        r = {{h->scl_slope, h->scl_inter},
             h->vox_offset,
             std::memcmp(h->magic, "n+1", 4) == 0,
             352,
             "NIfTI-1"};
    }
    std::free(raw);
    // The standard's "not scaled"; a non-finite intercept beside it is still a damaged header.
    if (std::isfinite(r.scaling.slope) && r.scaling.slope == 0 &&
        std::isfinite(r.scaling.intercept))
        r.scaling = {};
    return r;
}

// vox_offset as a byte offset: a whole number of bytes, past the header in a .nii; from the
// start of the .img in a .hdr/.img pair, where 0 is the usual value.
std::uint64_t checked_offset(const RawHeader& h, const std::string& where) {
    const double v = h.vox_offset;
    std::ostringstream text;
    text.precision(17);
    text << v;
    if (!std::isfinite(v) || std::trunc(v) != v || v < 0 || v >= 0x1p62)
        throw InputError(where, "vox_offset",
                         "expected a whole number of bytes from 0 to 2^62, got " + text.str());
    if (h.one_file && v < double(h.header_bytes))
        throw InputError(where, "vox_offset",
                         text.str() + " lies inside the " + std::to_string(h.header_bytes) +
                             "-byte header of a single-file " + h.version +
                             " (.nii); its voxels start at byte " + std::to_string(h.header_bytes) +
                             " or later");
    return std::uint64_t(v);
}

// The file's index-to-patient matrix: the sform when it has one, else the qform; RAS columns
// scaled by the spacing. Nullopt when it has neither (method 1 of the standard: pixdim alone).
std::optional<nifti_dmat44> patient_matrix(const nifti_image& n, std::string& which) {
    if (n.sform_code > 0) {
        which = "sform";
        return n.sto_xyz;
    }
    if (n.qform_code > 0) {
        which = "qform";
        return n.qto_xyz;
    }
    return std::nullopt;
}

// Spacing from the matrix's columns and the orientation from their directions, RAS -> LPS.
void take_geometry(const nifti_image& n, const std::string& where, Decoded& d) {
    std::string which;
    const std::optional<nifti_dmat44> m = patient_matrix(n, which);
    if (!m) {
        d.spacing = {float(std::abs(n.dx)), float(std::abs(n.dy)), float(std::abs(n.dz))};
        d.facts.push_back({"orientation", "none in the file (sform and qform codes 0)"});
        return;
    }
    for (int c = 0; c < 3; ++c) {
        const glm::vec3 ras(float(m->m[0][c]), float(m->m[1][c]), float(m->m[2][c]));
        const float len = glm::length(ras);
        if (!(len > 0) || !std::isfinite(len))
            throw InputError(
                where, which,
                "axis " + std::to_string(c) + " has no direction (a zero or non-finite column)");
        d.spacing[c] = len;
        d.orientation.axes[c] = glm::vec3(-ras.x, -ras.y, ras.z) / len;
    }
    d.orientation.origin = {-float(m->m[0][3]), -float(m->m[1][3]), float(m->m[2][3])};
    d.orientation.known = true;
    d.facts.push_back({"orientation from", which});
}

// The open image file and the header niftilib read, shared by the stack's reads.
struct OpenImage {
    NiftiPtr n;
    znzFile fp = nullptr;
    std::uint64_t delivered = 0, total = 0;  // bytes of voxels read, and the header's
    ~OpenImage() {
        if (fp) znzclose(fp);
    }
};

}  // namespace

PlaneStack nifti_planes(const fs::path& path) {
    const std::string where = path.string();
    nifti_set_debug_level(0);
    const QuietStderr quiet;
    const RawHeader header = raw_header(path, where);
    const std::uint64_t offset = checked_offset(header, where);
    auto image = std::make_shared<OpenImage>();
    image->n.reset(nifti_image_read(path.c_str(), 0));
    nifti_image* n = image->n.get();
    if (!n) throw InputError(where, "header", "not a NIfTI file niftilib reads");
    n->iname_offset = int64_t(offset);  // the header's, not niftilib's reading of it
    for (int a = 4; a <= n->dim[0] && a < 8; ++a)
        if (n->dim[a] > 1)
            throw InputError(where, "dim",
                             "dimension " + std::to_string(a) + " has " +
                                 std::to_string(n->dim[a]) +
                                 " entries (a time series or vectors); isowall reads one 3-D "
                                 "scalar volume");
    const auto type = voxel_type_of_nifti(n->datatype);
    if (!type)
        throw InputError(where, "datatype",
                         std::string(nifti_datatype_string(n->datatype)) +
                             " is not a scalar type isowall reads (uint8 to int32, float32, "
                             "float64)");
    const std::uint64_t sizes[3] = {std::uint64_t(std::max<int64_t>(n->nx, 0)),
                                    std::uint64_t(std::max<int64_t>(n->ny, 0)),
                                    std::uint64_t(std::max<int64_t>(n->nz, 0))};
    PlaneStack stack;
    Decoded& d = stack.head;
    d.dims = checked_dims(where, "dim", sizes, *type);
    d.type = *type;
    check_data_present(n->iname, offset, d.dims, d.type, where);
    take_geometry(*n, where, d);
    d.scaling = header.scaling;
    d.format = n->nifti_type >= NIFTI_FTYPE_NIFTI2_1  ? "NIfTI-2"
               : n->nifti_type == NIFTI_FTYPE_ANALYZE ? "ANALYZE 7.5"
                                                      : "NIfTI-1";
    d.files = {fs::path(n->fname)};
    if (std::string(n->iname) != n->fname) d.files.emplace_back(n->iname);
    if (n->descrip[0])
        d.facts.push_back({"description", std::string(n->descrip, strnlen(n->descrip, 80))});
    stack.scaling_field = "scl_slope";
    stack.size_field = "dim";
    // niftilib's reads run with stderr pointed away (QuietStderr): on a thread beside the
    // import's, that would swallow its progress bar.
    stack.read_ahead = false;
    // The image file is streamed once, in order (a gzip stream cannot seek back cheaply);
    // niftilib's buffer read swaps the bytes of a file of the other byte order.
    image->total = voxel_bytes(d.dims, d.type);
    const auto read_bytes = [image, where](std::size_t count, std::byte* to) {
        const QuietStderr quiet;
        nifti_image* n = image->n.get();
        if (!image->fp) {
            image->fp = znzopen(n->iname, "rb", nifti_is_gzfile(n->iname));
            if (znz_isnull(image->fp) || znzseek(image->fp, n->iname_offset, SEEK_SET) < 0)
                throw InputError(where, "data",
                                 "cannot open the image file " + quote_bounded(n->iname));
        }
        const auto want = static_cast<int64_t>(count);
        if (nifti_read_buffer(image->fp, to, want, n) != want) {
            // Where the stream stopped: the uncompressed position, past the offset.
            const int64_t at = znztell(image->fp) - n->iname_offset;
            const auto got = std::clamp<int64_t>(at, int64_t(image->delivered),
                                                 int64_t(image->delivered + count));
            throw InputError(where, "dim",
                             "the file ends after " + std::to_string(got) + " of " +
                                 std::to_string(image->total) +
                                 " bytes of voxels (a truncated or damaged file)");
        }
        image->delivered += count;
    };
    const std::size_t plane = std::size_t(d.dims.x) * d.dims.y * voxel_size(d.type);
    stack.read = [read_bytes, plane](int z0, int z1, std::byte* to) {
        read_bytes(plane * std::size_t(z1 - z0), to);
    };
    if (nifti_is_gzfile(n->iname)) stack.read_unproven = read_bytes;
    return stack;
}

Volume read_nifti(const fs::path& path) {
    return read_whole(nifti_planes(path), path.string());
}

}  // namespace isowall::formats
