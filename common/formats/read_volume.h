#pragma once
// --volume: picks the reader by what the path is (common/formats/readers.h).
//   a folder                     a DICOM series, or a stack of TIFF slices
//   .nii .nii.gz .hdr .img       NIfTI-1 or NIfTI-2
//   .mhd .mha                    MetaImage
//   FILE.h5:/path (.hdf5 .he5)   the HDF5 dataset at /path (the file's only one without :/path)
//   .tif .tiff                   a multi-page TIFF
//   .dcm, or DICM at byte 128    the DICOM series the file belongs to
//   .nrrd .nhdr                  NRRD (common/volume/volume.h: load_nrrd)
//   anything else                headerless raw, with `raw` (--dims, --type)
#include <optional>
#include <string>

#include "common/volume/volume.h"

namespace isowall::formats {

// populate: as load_raw's (common/volume/volume.h), for the formats that map their file.
Volume read_volume(const std::string& path, const std::optional<RawSpec>& raw,
                   bool populate = true);

}  // namespace isowall::formats
