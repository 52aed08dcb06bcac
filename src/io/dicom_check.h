// A walk over a DICOM Part 10 file's top-level elements before GDCM reads it (dicom.cpp).
//
// GDCM trusts length fields: a 996-byte slice whose Pixel Data length says 805 MB makes it
// allocate that much, and one whose Pixel Data is shorter than the image makes it return the
// slice silently short. This walk reads only tags and lengths (never values): the preamble,
// "DICM", the file meta group (always explicit VR little endian), then the data set in the
// transfer syntax the meta group names. Every element with a defined length must end inside
// the file, up to the last one (GDCM also reads what follows the Pixel Data: a 1710-byte slice
// with a junk element after it made GDCM allocate 3.9 GB; found by fuzz_dicom_dir). The walk
// stops, without a verdict, at the first undefined length (a sequence or
// encapsulated pixel data, whose items GDCM parses) and for files without "DICM" (GDCM also
// reads bare data sets; such files are left to it and to the child's memory cap).
#pragma once
#include <cstdint>
#include <string>

namespace lacuna::io {

struct DicomWalk {
    bool part10 = false;             // "DICM" at byte 128
    int64_t pixel_data_length = -1;  // defined length of (7FE0,0010), -1 if not reached
};

// Throws Error(dir, <file name>, "element (gggg,eeee) says N bytes, M are left in the file
// (a damaged or truncated slice)") for a length that runs past the end of the file, and
// "the file ends inside an element header" for a file cut inside a tag/VR/length (GDCM
// asserts on that one: found by fuzz_dicom_dir).
DicomWalk walk_dicom_file(const std::string& file, const std::string& dir);

}  // namespace lacuna::io
