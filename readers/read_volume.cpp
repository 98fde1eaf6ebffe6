#include "readers/read_volume.h"
#include "readers/zarr_reader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <optional>
#include <span>
#include <utility>

#include "core/error.h"
#include "readers/dicom_lengths.h"
#include "readers/isolated_read.h"
#include "readers/isolated_stream.h"
#include "readers/plane_stack.h"
#include "readers/readers.h"
#include "volume/load_checks.h"

namespace isowall::formats {
namespace fs = std::filesystem;
namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

bool is_hdf5_name(const std::string& name) {
    const std::string n = lower(name);
    return ends_with(n, ".h5") || ends_with(n, ".hdf5") || ends_with(n, ".he5") ||
           ends_with(n, ".hdf");
}

// A DICOM Part 10 file by its first 132 bytes (dicom_lengths.h).
bool has_dicom_magic(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::array<char, 132> head{};
    return in.read(head.data(), head.size()) && has_part10_magic(std::as_bytes(std::span(head)));
}

// A folder is a stack of TIFF slices when it holds .tif/.tiff files (the reader passes over
// anything else, a note or a thumbnail), else a DICOM series.
bool is_tiff_folder(const fs::path& dir) {
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string n = lower(e.path().filename().string());
        if (e.is_regular_file() && !n.starts_with(".") &&
            (ends_with(n, ".tif") || ends_with(n, ".tiff")))
            return true;
    }
    return false;
}

// GDCM and libhdf5 read in a child process (isolated_read.h): a crash of theirs on a damaged file
// is then one line, not the end of isowall.
Volume dicom(const fs::path& p) {
    return read_isolated(p.string(), "the DICOM decoder (GDCM)", [&] { return read_dicom(p); });
}

Volume hdf5(const fs::path& file, const std::string& dataset) {
    return read_isolated(file.string(), "the HDF5 library (libhdf5)",
                         [&] { return read_hdf5(file, dataset); });
}

// DICOM and HDF5 streamed from a child process (isolated_read.h) as it decodes them.
std::unique_ptr<PlaneSource> dicom_stream(const fs::path& p) {
    return stream_isolated(p.string(), "the DICOM decoder (GDCM)", [&] { return dicom_planes(p); });
}

constexpr const char* kZarrDecoders = "the Zarr chunk decoders (c-blosc, zstd, zlib, lz4)";

// Zarr chunks decoded by c-blosc, zstd, zlib and lz4 in a child as well: a decoder's crash on a
// damaged chunk is one line.
Volume zarr(const fs::path& dir, const std::string& selection = "") {
    return read_isolated(dir.string(), kZarrDecoders, [&] { return read_zarr(dir, selection); });
}

std::unique_ptr<PlaneSource> zarr_stream(const fs::path& dir, const std::string& selection = "") {
    return stream_isolated(dir.string(), kZarrDecoders,
                           [=] { return zarr_planes(dir, selection); });
}

// A URL's store and its selection: a last ':' followed by AXIS=INDEX pairs, after the host's own
// colons.
std::pair<std::string, std::string> url_selection(const std::string& url) {
    const std::size_t colon = url.rfind(':');
    if (colon != std::string::npos && colon > url.find("://") + 2 &&
        url.find('=', colon) != std::string::npos && url.find('/', colon) == std::string::npos)
        return {url.substr(0, colon), url.substr(colon + 1)};
    return {url, ""};
}

// STORE:t=3,c=0 (zarr_reader.h): the store and the selection, when STORE is another tool's.
std::optional<std::pair<fs::path, std::string>> zarr_selection(const std::string& path) {
    const std::size_t colon = path.rfind(':');
    std::error_code ec;
    if (colon == std::string::npos || fs::exists(path, ec)) return std::nullopt;
    const fs::path store = path.substr(0, colon);
    if (!is_foreign_zarr(store)) return std::nullopt;
    return std::pair{store, path.substr(colon + 1)};
}

std::unique_ptr<PlaneSource> hdf5_stream(const fs::path& file, const std::string& dataset) {
    return stream_isolated(file.string(), "the HDF5 library (libhdf5)",
                           [&] { return hdf5_planes(file, dataset); });
}

Volume read_file(const fs::path& p, const std::string& name, bool populate) {
    const std::string n = lower(name);
    if (ends_with(n, ".nrrd") || ends_with(n, ".nhdr")) return load_nrrd(p, populate);
    if (ends_with(n, ".nii") || ends_with(n, ".nii.gz") || ends_with(n, ".hdr") ||
        ends_with(n, ".img") || ends_with(n, ".img.gz"))
        return read_nifti(p);
    if (ends_with(n, ".mhd") || ends_with(n, ".mha")) return read_metaimage(p);
    if (is_hdf5_name(n)) return hdf5(p, "");
    if (ends_with(n, ".tif") || ends_with(n, ".tiff")) return read_tiff_stack(p);
    if (ends_with(n, ".dcm") || has_dicom_magic(p)) return dicom(p);
    throw InputError(p.string(), "format",
                     "not a format isowall reads (NRRD, NIfTI, DICOM, MetaImage, HDF5, TIFF by "
                     "name or content); for headerless data give --dims X Y Z and --type T");
}

std::unique_ptr<PlaneSource> streamed(PlaneStack stack, const fs::path& p) {
    return stream_planes(std::move(stack), p.string());
}

std::unique_ptr<PlaneSource> file_planes(const fs::path& p, const std::string& name) {
    const std::string n = lower(name);
    if (ends_with(n, ".nrrd") || ends_with(n, ".nhdr")) return nrrd_planes(p);
    if (ends_with(n, ".nii") || ends_with(n, ".nii.gz") || ends_with(n, ".hdr") ||
        ends_with(n, ".img") || ends_with(n, ".img.gz"))
        return streamed(nifti_planes(p), p);
    if (ends_with(n, ".mhd") || ends_with(n, ".mha")) return streamed(metaimage_planes(p), p);
    if (is_hdf5_name(n)) return hdf5_stream(p, "");
    if (ends_with(n, ".tif") || ends_with(n, ".tiff")) return streamed(tiff_planes(p), p);
    if (ends_with(n, ".dcm") || has_dicom_magic(p)) return dicom_stream(p);
    return nullptr;  // read_volume names what it is not
}

}  // namespace

bool is_zarr_source(const std::string& path) {
    return is_url(path) || is_foreign_zarr(path) || zarr_selection(path).has_value();
}

std::unique_ptr<PlaneSource> open_planes(const std::string& path, const std::optional<RawSpec>& raw,
                                         const HttpOptions& http) {
    if (raw) return raw_planes(path, *raw);
    if (is_url(path)) {
        const auto url = url_selection(path);  // (a structured binding clang 14 cannot capture)
        return stream_isolated(path, kZarrDecoders,
                               [=] { return zarr_url_planes(url.first, url.second, http); });
    }
    const fs::path p(path);
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
        if (is_foreign_zarr(p)) return zarr_stream(p);
        return is_tiff_folder(p) ? streamed(tiff_planes(p), p) : dicom_stream(p);
    }
    const std::size_t colon = path.rfind(":/");
    if (colon != std::string::npos && !fs::exists(p, ec)) {
        const std::string file = path.substr(0, colon);
        if (is_hdf5_name(file)) return hdf5_stream(file, path.substr(colon + 1));
    }
    if (const auto z = zarr_selection(path)) return zarr_stream(z->first, z->second);
    check_regular_file(p, path, "file");
    return file_planes(p, p.filename().string());
}

Volume read_url(const std::string& url, const HttpOptions& options) {
    const auto store = url_selection(url);
    return read_isolated(url, kZarrDecoders,
                         [&] { return read_zarr_url(store.first, store.second, options); });
}

Volume read_volume(const std::string& path, const std::optional<RawSpec>& raw, bool populate) {
    if (raw) return load_raw(path, *raw, populate);
    const fs::path p(path);
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
        if (is_foreign_zarr(p)) return zarr(p);
        return is_tiff_folder(p) ? read_tiff_stack(p) : dicom(p);
    }
    // FILE.h5:/path/to/dataset, when FILE.h5 is a file (a name may hold a colon itself).
    const std::size_t colon = path.rfind(":/");
    if (colon != std::string::npos && !fs::exists(p, ec)) {
        const std::string file = path.substr(0, colon);
        if (is_hdf5_name(file)) return hdf5(file, path.substr(colon + 1));
    }
    if (const auto z = zarr_selection(path)) return zarr(z->first, z->second);
    check_regular_file(p, path, "file");
    return read_file(p, p.filename().string(), populate);
}

}  // namespace isowall::formats
