#pragma once
// A walk over a DICOM Part 10 file's data elements that checks every declared length against the
// bytes that follow it, before GDCM reads the file: GDCM sizes an element's buffer from its
// declared length before reading it (gdcm::ByteValue::SetLength), so a 5 KB file declaring a
// 4 GB element cost 4 GB. The walk reads tags and lengths only; values are skipped, sequences and
// items walked into (their contents are elements too), undefined lengths passed.
#include <cstddef>
#include <span>
#include <string>

namespace isowall::formats {

// True when the bytes start with the Part 10 preamble and "DICM" at byte 128.
bool has_part10_magic(std::span<const std::byte> file);

// Empty when every length fits; otherwise what does not, e.g. "element (0010,0010) declares
// 4294967294 bytes where 4831 remain". A deflated data set is walked as far as its file meta.
std::string dicom_length_problem(std::span<const std::byte> file);

}  // namespace isowall::formats
