// A rank's brick of voxels (docs/distributed.md, "Reading").
//
// First step, stated plainly: every rank reads the whole file through the ordinary readers
// (lacuna/io.h; compressed NIfTI is streamed once per rank) and keeps only its brick, so the peak
// memory of a rank is the whole volume while it loads; the rendering and the structures then hold
// the brick only. Reading a raw/NRRD/MetaImage/uncompressed NIfTI brick by file offset is the
// next step (not built yet).
#pragma once
#include "lacuna/volume.h"

namespace lacuna::dist {

// The voxels offset + [0, dims) of `whole` as a volume of their own, keeping the whole grid's
// geometry (origin, direction, spacing: BrickOwnership's convention, lacuna/renderer.h) and its
// visualization range (the TF's domain must map the same values to the same LUT entries).
Volume crop_brick(const Volume& whole, Vec3i offset, Vec3i dims);

}  // namespace lacuna::dist
