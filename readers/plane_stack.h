#pragma once
// A volume as its reader finds it before reading a voxel: the description (dims, stored type,
// spacing, orientation, scaling, facts) and a function that decodes planes in z order. Read whole,
// it is the reader's volume (read_whole); streamed, it is the planes of that volume a slab at a
// time (stream_planes), so `isowall import` brings a TIFF stack, a DICOM series, an HDF5 dataset,
// a NIfTI or MetaImage file past memory into a store without holding it.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "readers/voxel_ops.h"
#include "volume/plane_source.h"

namespace isowall::formats {

// The most bytes one slice of a stack may hold: 512 MiB (16384 x 16384 at 16 bits). Checked on
// a header before a library decodes it (GDCM and OpenImageIO size their buffers from the header);
// a volume of slices past it could not be held in memory anyway.
inline constexpr std::uint64_t kMaxSliceBytes = std::uint64_t(1) << 29;

struct PlaneStack {
    Decoded head;  // everything but the bytes (head.type: the stored type)
    // Decodes the stored voxels of planes [z0, z1) into `to`: called with z0 rising from 0, each
    // call starting where the last ended. Throws InputErrors naming the file and the field.
    std::function<void(int z0, int z1, std::byte* to)> read;
    // The range the stored values may take, when the file says (DICOM's BitsStored): a scaled
    // stream's type comes from it, else from the stored type's range.
    std::optional<std::pair<double, double>> declared_range;
    std::string scaling_field = "scaling";  // the field a bad scaling is reported under
    std::string size_field = "size";        // the field a volume too large for memory is
    // Whether the stream may decode the next slab on a thread of its own while the last one is
    // written (DecodedPlanes); off for a decoder that must run where it was opened.
    bool read_ahead = true;
    // Set when the file cannot prove the header's size before it is read (a gzip stream):
    // reads the next `count` bytes of stored voxels (a multiple of the voxel size), from the
    // first on, and throws when the file ends first. read_whole then grows its buffer as the
    // bytes arrive instead of allocating what the header claims before a byte is read.
    std::function<void(std::size_t count, std::byte* to)> read_unproven = nullptr;
};

// Every plane, then the reader's usual end (finish_volume): the volume read_volume gives.
Volume read_whole(PlaneStack stack, const std::string& where);

// The planes of the volume read_whole would give, scaled and mirrored a plane at a time. Its type
// is chosen before any voxel is read: when the scaling turns integers into integers, the smallest
// type that holds the declared range scaled (read_whole looks at the values instead, so a stream
// may hold the same values in a wider type). Errors in the description are thrown here.
std::unique_ptr<PlaneSource> stream_planes(PlaneStack stack, const std::string& where);

}  // namespace isowall::formats
