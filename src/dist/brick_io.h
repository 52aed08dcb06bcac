// A rank's brick of voxels (docs/distributed.md, "Reading").
//
// Two ways in:
//   - a file whose voxels lie at a fixed offset (raw, raw-encoded NRRD, uncompressed MetaImage
//     and NIfTI, any voxel type and byte order: src/io/brick_read.h): each rank reads only its
//     brick (with --balance visible a slab first, distributed_frame.cpp), never the whole file.
//     What read_volume does with the whole volume after reading is agreed over the ranks: the
//     smallest and largest values that are not NaN of every brick (Comm::minmax; the bricks
//     cover every voxel) are the whole volume's, NaN voxels become that smallest value
//     (Volume::replace_nan_with_minimum's rule), and the visualization range is
//     Volume::compute_range's rule over them (default_vis_range), or --range;
//   - every other file (compressed, DICOM, ascii NRRD): every rank reads the whole file through
//     the ordinary readers and cuts its brick out (crop_brick), so while it loads a rank's memory
//     peaks at the whole volume (a .nii.gz is inflated once per rank).
#pragma once
#include <cstddef>

#include "io/brick_read.h"
#include "lacuna/volume.h"

namespace lacuna::dist {

// The voxels offset + [0, dims) of `whole` as a volume of their own, keeping the whole grid's
// geometry (origin, direction, spacing: BrickOwnership's convention, lacuna/renderer.h) and its
// visualization range (the TF's domain must map the same values to the same LUT entries).
Volume crop_brick(const Volume& whole, Vec3i offset, Vec3i dims);

// The smallest and largest voxel values of `v` that are not NaN (+inf and -inf when there are
// none): this rank's part of the whole volume's range.
void finite_minmax(const Volume& v, float& lo, float& hi);
// Sets every NaN voxel of a float volume to `value` (the whole volume's smallest); returns how
// many there were.
size_t replace_nan(Volume& v, float value);

// The visualization range read_volume gives a volume whose voxels span [lo, hi]
// (Volume::compute_range's rule for a range never set).
ValueRange default_vis_range(float lo, float hi);

}  // namespace lacuna::dist
