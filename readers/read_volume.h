#pragma once
// --volume: picks the reader by what the path is (readers/readers.h).
//   a folder, FOLDER:t=3,c=0     a Zarr v2 array or OME-Zarr image (zarr_reader.h; isowall's own
//                                stores page instead: store/open_store.h), a DICOM series, or a
//                                stack of TIFF slices
//   .nii .nii.gz .hdr .img       NIfTI-1 or NIfTI-2
//   .mhd .mha                    MetaImage
//   FILE.h5:/path (.hdf5 .he5)   the HDF5 dataset at /path (the file's only one without :/path)
//   .tif .tiff                   a multi-page TIFF
//   .dcm, or DICM at byte 128    the DICOM series the file belongs to
//   .nrrd .nhdr                  NRRD (volume/volume.h: load_nrrd)
//   anything else                headerless raw, with `raw` (--dims, --type)
#include <memory>
#include <optional>
#include <string>

#include "readers/http_fetch.h"
#include "volume/plane_source.h"
#include "volume/volume.h"

namespace isowall::formats {

// populate: as load_raw's (volume/volume.h), for the formats that map their file.
Volume read_volume(const std::string& path, const std::optional<RawSpec>& raw,
                   bool populate = true);

// A Zarr store served over HTTP(S) (zarr_reader.h), URL or URL:t=3,c=0, decoded in a child
// process as a folder's is.
Volume read_url(const std::string& url, const HttpOptions& options);

// Whether `path` names another tool's Zarr store: a folder (zarr_reader.h: is_foreign_zarr), one
// with a selection (FOLDER:t=3), or a URL.
bool is_zarr_source(const std::string& path);

// The planes of the volume read_volume gives, for `isowall import` to stream a slab at a time:
// TIFF stacks, NIfTI, MetaImage, DICOM series, HDF5 datasets and Zarr stores, a folder or a URL
// fetched with `http` (their readers' plane stacks, plane_stack.h; DICOM, HDF5 and Zarr decoded
// in a child process as read_volume does), and gzip or
// other-endian NRRD and raw (nrrd_planes, raw_planes). Null for what read_volume maps without
// decoding (raw and raw NRRD in host order), and for bzip2, hex and ascii NRRD, decoded whole.
std::unique_ptr<PlaneSource> open_planes(const std::string& path, const std::optional<RawSpec>& raw,
                                         const HttpOptions& http = {});

}  // namespace isowall::formats
