#pragma once
// One reader per format, each through the library its community keeps where Debian has one.
// Every reader returns a Volume with its files (the octree cache key covers each), orientation
// and facts (readers/voxel_ops.h: finish_volume), or throws an InputError naming the file
// and the field. read_volume (read_volume.h) picks among them. Each X_planes is the same reader
// before a voxel is read (plane_stack.h): what `import` streams; read_X reads it whole.
#include <filesystem>
#include <string>

#include "readers/plane_stack.h"
#include "volume/volume.h"

namespace isowall::formats {

// NIfTI-1 and NIfTI-2 through niftilib: .nii, .nii.gz, and .hdr/.img pairs. scl_slope and
// scl_inter applied; the orientation from the sform, else the qform (RAS turned to LPS).
Volume read_nifti(const std::filesystem::path& path);
PlaneStack nifti_planes(const std::filesystem::path& path);

// A DICOM series through GDCM (every transfer syntax GDCM decodes): `path` is a folder holding
// one series, or one file of the series to read. Slices sorted by ImagePositionPatient along the
// slice normal, spacing from the positions, RescaleSlope/Intercept applied.
Volume read_dicom(const std::filesystem::path& path);
PlaneStack dicom_planes(const std::filesystem::path& path);

// The dataset `dataset` ("/group/name"; empty: the file's only dataset) of an HDF5 file through
// libhdf5: three dimensions, any of our scalar types, chunked or contiguous; C order (the last
// dimension varies fastest, and is our x).
Volume read_hdf5(const std::filesystem::path& file, const std::string& dataset);
PlaneStack hdf5_planes(const std::filesystem::path& file, const std::string& dataset);

// A stack of TIFF slices through OpenImageIO: a multi-page TIFF, or a folder of .tif/.tiff files
// taken in name order (numbers compared as numbers: slice2 before slice10). One channel, every
// slice the same size and type.
Volume read_tiff_stack(const std::filesystem::path& path);
PlaneStack tiff_planes(const std::filesystem::path& path);

// MetaImage (.mhd with its data file, or .mha with the data inside): a small reader of our own
// (no maintained library in Debian outside ITK). ElementSpacing, TransformMatrix and Offset kept.
Volume read_metaimage(const std::filesystem::path& path);
PlaneStack metaimage_planes(const std::filesystem::path& path);

}  // namespace isowall::formats
