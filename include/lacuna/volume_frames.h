// How many volumes a file holds along a fourth axis, for front ends that let the user pick one
// (the viewer's frame selector; ReadOptions::frame reads it, lacuna/io.h).
#pragma once
#include <cstdint>
#include <string>

namespace lacuna {

// NIfTI (.nii, .nii.gz, .hdr/.img): dim[4] when the header is a 4D volume series, else 1; every
// other format reads as one volume: 1. Reads only the header. Throws lacuna::Error as
// read_volume does for a file it cannot read or a header it refuses.
int64_t count_volume_frames(const std::string& path);

}  // namespace lacuna
