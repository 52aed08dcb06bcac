// The per-format readers and writers behind read_volume/write_volume (private to src/io/).
// Each reader assumes the caller checked that `path` exists and is readable, and returns a
// volume whose range has not been computed yet.
#pragma once
#include <string>

#include "lacuna/io.h"
#include "lacuna/rgb.h"
#include "lacuna/volume.h"

namespace lacuna::io {

// .nii / .nii.gz, NIfTI-1 and NIfTI-2, parsed by our own code (nifti_reader.cpp) so the voxels
// are inflated straight into the volume's buffer.
// RGB24/RGBA32 files: their opacity scalar is `rgb_opacity` (lacuna/rgb.h).
Volume read_nifti(const std::string& path, const ReadOptions& opts,
                  RgbOpacity rgb_opacity = RgbOpacity::Luminance);
// The volumes of a NIfTI file along dim[4] (1 for a 3D file), from its header alone.
int64_t nifti_frames(const std::string& path);
// NRRD (.nrrd/.nhdr), MetaImage (.mha/.mhd) and anything else ITK recognises.
Volume read_itk(const std::string& path, const ReadOptions& opts);
// A folder holding a DICOM series.
Volume read_dicom_dir(const std::string& dir, const ReadOptions& opts);
// Headerless voxels with a layout from opts.raw or the file name.
Volume read_raw(const std::string& path, const ReadOptions& opts);

// ITK writers (.nrrd .nhdr .nii .nii.gz .mha .mhd); `path` is the final name, the data is
// written under a temporary name and renamed.
void write_itk(const std::string& path, const Volume& v);
// One DICOM file per z slice into `dir` (created if missing). Integer volumes only.
void write_dicom_dir(const std::string& dir, const Volume& v);
// Headerless little-endian voxels.
void write_raw(const std::string& path, const Volume& v);

}  // namespace lacuna::io
