#pragma once
// A reader run in a child process, so that a decoder library's crash on a damaged or hostile file
// ends the child, not isowall. Our fuzzers found such crashes in the libraries we read through:
// GDCM, which Debian builds with its assertions on, aborts on some damaged DICOM files, and
// libhdf5 1.10 reads freed memory on some damaged HDF5 files. Isolated, each is one line naming
// the file, like any other bad input.
//
// The child is a fork() of this process: it calls the reader, writes the volume into an
// anonymous memory file (memfd) and leaves with _exit(), calling nothing else (no MPI, no exit
// handlers). An error the reader throws travels back over a pipe as its line. The parent maps the
// memory file as the volume's voxels, so they are not copied again.
#include <chrono>
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "volume/volume.h"
#include "wire/wire.h"

namespace isowall::formats {

// The volume's description (dims, type, spacing, source, files, orientation, facts), as the
// child writes it before the voxels. encode, then decode, gives the same description back.
std::vector<std::byte> encode_volume_header(const Volume& v);
// The volume of the voxels at `offset` of `file` with the description in `header`; throws
// WireError (wire/wire.h) on a malformed header, std::runtime_error when `file` is too
// short for the voxels.
Volume decode_volume(std::span<const std::byte> header, MappedFile file, std::size_t offset);

// The dims, type and spacing at the start of the description above, and of a streamed child's
// (isolated_stream.h): written, then read back with the type's range checked (a WireError).
struct VolumeShape {
    glm::ivec3 dims{0};
    VoxelType type = VoxelType::u8;
    glm::vec3 spacing{1.0f};
};
void put_shape(MessageWriter& w, const VolumeShape& s);
VolumeShape get_shape(MessageReader& r);

// How long a child may read before it is ended (a decoder looping on a crafted file).
inline constexpr std::chrono::seconds kIsolatedReadLimit{600};

// Runs `read` in a child process and returns its volume. `where` (the file or folder) and
// `decoder` ("the DICOM decoder (GDCM)") name the source in the errors: an InputError from the
// reader is passed on as it is; a child that dies (a signal) or runs past `limit` becomes an
// InputError naming `where`, field "data".
Volume read_isolated(const std::string& where, const std::string& decoder,
                     const std::function<Volume()>& read,
                     std::chrono::milliseconds limit = kIsolatedReadLimit);

}  // namespace isowall::formats
