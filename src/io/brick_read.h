// A brick of a volume file read by file offset (docs/distributed.md, "Reading"): what lets each
// rank of a distributed frame hold only its share of a volume larger than one machine.
//
// The argument. A file whose voxels are one plain binary block — raw, NRRD with raw encoding
// (attached or in one detached data file), uncompressed MetaImage (.mha, or .mhd with its data
// file), uncompressed NIfTI (.nii, or a .hdr/.img pair) — stores voxel (i, j, k) at
//     offset + ((k * dy + j) * dx + i) * size
// bytes, x fastest. So the voxels offset + [0, dims) of a brick are dims.y * dims.z runs of
// dims.x voxels each (one run per row; whole planes when the brick spans x and y), and a rank
// reads exactly those with pread, never touching the rest of the file.
//
// The header is parsed by the ordinary readers (src/io/readers.h, asked for the header alone),
// so dims, type, byte order, NIfTI scaling, geometry and orientation are read_volume's to the
// bit, with its checks and its one-line errors: a truncated file is refused from its length
// before any voxel is read, as read_volume refuses it. The values are converted as read_volume
// converts them (convert_voxels: byte order, int8 -> int16, wide types -> float32, NIfTI's
// slope and intercept), row by row through a small buffer.
//
// What read_volume does after reading needs the whole volume and is the caller's: NaN voxels
// are replaced by the smallest finite value of the whole volume, and the visualization range is
// the whole volume's (src/dist/brick_io.h agrees both over the ranks). Compressed files (.nii.gz,
// gzip NRRD, compressed MetaImage), ascii/hex NRRD, data-file lists and DICOM series have no
// voxel offset: open_brick_file says nullopt and they are read whole.
#pragma once
#include <optional>
#include <string>

#include "io/readers.h"
#include "lacuna/io.h"
#include "lacuna/volume.h"

namespace lacuna::io {

struct BrickFile {
    std::string path;    // the file as named (errors name it)
    Volume header;       // dims, stored type and geometry; no voxels (data() is null)
    VoxelLayout layout;  // where the voxels are, their disk type and byte order
};

// The header of `path` and where its voxels are, when they can be read by offset; nullopt for a
// file that must be read whole (see above). Throws lacuna::Error as read_volume would for a
// header it refuses, a missing or a truncated file.
std::optional<BrickFile> open_brick_file(const std::string& path, const ReadOptions& opts);

// The voxels offset + [0, dims) of the file as a volume of their own with the whole file's
// geometry (origin, direction, spacing: BrickOwnership's convention, lacuna/renderer.h). Values
// as read_volume converts them, NaN kept, range not computed. `budget` applies to the brick's
// bytes, checked before anything is allocated. Error(path, "voxel data", ...) on a short read.
Volume read_brick(const BrickFile& f, Vec3i offset, Vec3i dims, const MemoryBudget& budget);

}  // namespace lacuna::io
