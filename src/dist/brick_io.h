// A rank's brick of voxels (docs/distributed.md, "Reading").
//
// Two ways in:
//   - a headerless raw file of integer voxels in the host's byte order (the layout from the
//     front end or the name, as lacuna/io.h reads it): each rank reads only its brick, row by row
//     at the file offsets of its voxels (read_brick), and never holds more. Its visualization
//     range is the whole volume's, from every rank's brick range (Comm::minmax: the bricks cover
//     every voxel) by Volume::compute_range's rule;
//   - every other file (and --balance visible, which classifies the whole grid): every rank reads
//     the whole file through the ordinary readers and cuts its brick out (crop_brick), so while
//     it loads a rank's memory peaks at the whole volume (compressed NIfTI is inflated once per
//     rank). NRRD, MetaImage and uncompressed NIfTI by offset are not built yet.
#pragma once
#include <optional>
#include <string>

#include "lacuna/io.h"
#include "lacuna/volume.h"

namespace lacuna::dist {

// The voxels offset + [0, dims) of `whole` as a volume of their own, keeping the whole grid's
// geometry (origin, direction, spacing: BrickOwnership's convention, lacuna/renderer.h) and its
// visualization range (the TF's domain must map the same values to the same LUT entries).
Volume crop_brick(const Volume& whole, Vec3i offset, Vec3i dims);

// A file a brick can be read from by offset.
struct RawBrickFile {
    std::string path;
    RawSpec spec;  // dims, type, spacing; little-endian on a little-endian host
};
// `path` as such a file: a .raw name with a layout (`raw`, else the name's), integer voxels in
// the host's byte order, of exactly the layout's size (lacuna::Error otherwise, as read_volume
// says it). nullopt: another format, float voxels or the other byte order (read whole).
std::optional<RawBrickFile> raw_brick_file(const std::string& path,
                                           const std::optional<RawSpec>& raw);
// The whole volume's header alone: dims, type and geometry, no voxels (Volume's adopting
// constructor with no buffer): what world_bounds and the decomposition need.
Volume header_of(const RawBrickFile& f);
// The voxels offset + [0, dims) of the file, geometry as the whole file's; its range computed
// over the brick (the caller sets the whole volume's visualization range).
Volume read_brick(const RawBrickFile& f, Vec3i offset, Vec3i dims);
// The visualization range read_volume gives a volume whose voxels span [lo, hi]
// (Volume::compute_range's rule for a range never set).
ValueRange default_vis_range(float lo, float hi);

}  // namespace lacuna::dist
