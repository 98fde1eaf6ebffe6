#pragma once
// A plane stack (plane_stack.h) decoded in a child process, as read_isolated (isolated_read.h)
// decodes a whole volume and for the same reason: a decoder library's crash on a damaged file ends
// the child, not isowall. The child hands its planes over a pipe as it decodes them, a slab at a
// time, so `isowall import` streams a DICOM series or an HDF5 dataset larger than memory with its
// decoder isolated. The pipe paces the child: it decodes no further ahead than the pipe holds.
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "readers/isolated_read.h"
#include "readers/plane_stack.h"
#include "volume/plane_source.h"

namespace isowall::formats {

// The planes stream_planes(open(), where) gives, decoded in a child. Errors as read_isolated's:
// the reader's InputError passed on as it is; a child that dies, or sends nothing for `quiet`, is
// an InputError naming `where` and `decoder`, field "data". Dropping the source ends the child.
std::unique_ptr<PlaneSource> stream_isolated(const std::string& where, const std::string& decoder,
                                             const std::function<PlaneStack()>& open,
                                             std::chrono::milliseconds quiet = kIsolatedReadLimit);

}  // namespace isowall::formats
