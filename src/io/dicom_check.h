// A walk over a DICOM file's top-level elements before GDCM reads it (dicom.cpp).
//
// GDCM trusts length fields: a 996-byte slice whose Pixel Data length says 805 MB makes it
// allocate that much, and one whose Pixel Data is shorter than the image makes it return the
// slice silently short. This walk reads only tags and lengths (never values) of every file GDCM
// would parse, from where GDCM starts:
//   - a Part 10 file ("DICM" at byte 128): from byte 132, the file meta group (group 0002,
//     explicit VR little endian, or implicit as some old GE files have it), then the data set
//     in the transfer syntax the meta group names;
//   - a file without the preamble and "DICM" (ACR-NEMA, or a bare data set: real data has
//     them, and GDCM reads them): from byte 0, in the encoding GDCM's
//     FileMetaInformation::ReadCompat guesses from the first tag (a group 0002 meta group;
//     group 0008 little endian, explicit if a VR follows; group 0800 big endian; element 0010
//     little endian, explicit if a VR follows; else explicit if a VR follows, big endian when the
//     tag reads above 0xFF). A file whose first tag fits none of these is not DICOM to GDCM either,
//     which gives up on it before reading any value (notes, thumbnails): no verdict, the walk
//     stops.
// Every element with a defined length must end inside the file, up to the last one (GDCM also
// reads what follows the Pixel Data: a 1710-byte slice with a junk element after it made GDCM
// allocate 3.9 GB; and a 12-byte file without a preamble whose first element, (0002,0000) in
// implicit VR, says 4.2 GB: both found by fuzz_dicom_dir). The walk stops, without a verdict,
// at the first undefined length (a sequence or encapsulated pixel data, whose items GDCM
// parses, under the child's memory cap) and in a deflated data set.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace lacuna::io {

struct DicomWalk {
    bool part10 = false;             // "DICM" at byte 128
    bool dicom = false;              // GDCM would parse it (part10, or its first tag fits)
    bool checked = false;            // every top-level length checked, up to the end of the file
    int64_t pixel_data_length = -1;  // defined length of (7FE0,0010), -1 if not reached
};

// Throws Error(dir, <file name>, "element (gggg,eeee) says N bytes, M are left in the file
// (a damaged or truncated slice)") for a length that runs past the end of the file, and
// "the file ends inside an element header" for a file cut inside a tag/VR/length (GDCM
// asserts on that one: found by fuzz_dicom_dir).
DicomWalk walk_dicom_file(const std::string& file, const std::string& dir);

// The same walk over bytes in memory (fuzz_dicom_check); `name` stands for the file name.
DicomWalk walk_dicom_bytes(const uint8_t* data, size_t size, const std::string& name,
                           const std::string& dir);

}  // namespace lacuna::io
