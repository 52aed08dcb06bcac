// The per-format readers and writers behind read_volume/write_volume (private to src/io/).
// Each reader assumes the caller checked that `path` exists and is readable, and returns a
// volume whose range has not been computed yet.
#pragma once
#include <string>

#include "io/io_util.h"
#include "lacuna/io.h"
#include "lacuna/rgb.h"
#include "lacuna/volume.h"

namespace lacuna::io {

// Where a file's voxels are, for reading a brick of them by offset (src/io/brick_read.h). A
// reader given one fills it and returns the header alone: dims, type and geometry, no voxels
// (a Volume without a buffer), after the checks it makes before allocating — except the memory
// budget, which the brick's reader applies to the brick.
struct VoxelLayout {
    std::string path;     // the file holding the voxels
    uint64_t offset = 0;  // its first voxel byte (of the chosen volume of a 4D NIfTI)
    DiskType disk = DiskType::U8;
    bool swap = false;       // the file's byte order is not the host's
    bool at_offset = false;  // plain binary voxels at `offset` (not compressed, ascii, lists)
    bool rescale = false;    // NIfTI scl_slope / scl_inter
    double slope = 1, intercept = 0;
};

// .nii / .nii.gz, NIfTI-1 and NIfTI-2, parsed by our own code (nifti_reader.cpp) so the voxels
// are inflated straight into the volume's buffer.
// RGB24/RGBA32 files: their opacity scalar is `rgb_opacity` (lacuna/rgb.h); `header_only`:
// VoxelLayout's contract (RGB files are not read by brick: an error).
Volume read_nifti(const std::string& path, const ReadOptions& opts,
                  RgbOpacity rgb_opacity = RgbOpacity::Luminance,
                  VoxelLayout* header_only = nullptr);
// The volumes of a NIfTI file along dim[4] (1 for a 3D file), from its header alone.
int64_t nifti_frames(const std::string& path);
// NRRD (.nrrd/.nhdr), MetaImage (.mha/.mhd) and anything else ITK recognises.
Volume read_itk(const std::string& path, const ReadOptions& opts,
                VoxelLayout* header_only = nullptr);
// A folder holding a DICOM series.
Volume read_dicom_dir(const std::string& dir, const ReadOptions& opts);
// Headerless voxels with a layout from opts.raw or the file name.
Volume read_raw(const std::string& path, const ReadOptions& opts,
                VoxelLayout* header_only = nullptr);

// ITK writers (.nrrd .nhdr .nii .nii.gz .mha .mhd); `path` is the final name, the data is
// written under a temporary name and renamed.
void write_itk(const std::string& path, const Volume& v);
// One DICOM file per z slice into `dir` (created if missing). Integer volumes only.
void write_dicom_dir(const std::string& dir, const Volume& v);
// Headerless little-endian voxels.
void write_raw(const std::string& path, const Volume& v);

}  // namespace lacuna::io
