// NRRD voxel data, read by our code after ITK has parsed the header (like MetaImage's,
// metaimage_data.h).
//
// Why: NrrdIO (ITK 5.2) fills the whole buffer before it notices that the data is short: a
// 200-byte .nrrd or .nhdr whose "sizes: 30000 30000 3" claims 5.4 GB touched 5.3 GB and took
// 8 s before "fread got only 960 2-sized things". Raw and gzip data, attached or in one data
// file, are therefore located here and read incrementally (raw: the length is checked before
// anything is allocated); type conversions go through the small staging buffer.
//
// Left to NrrdIO, with a length check before allocating: ascii (at least one byte per value)
// and hex (two characters per byte) encodings, and "data file: LIST" / pattern headers (raw:
// the data files together must hold the bytes). bzip2 data is left to NrrdIO unchecked: its
// ratio has no useful bound.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "io/metaimage_data.h"

namespace lacuna::io {

// Checks the geometry fields of a NRRD header before NrrdIO reads it (issue 14, bad input):
// Error(header, "space directions", ...) for a coefficient that is not finite or an axis that is
// the zero vector (a zero or singular affine), Error(header, "space origin", ...) for a
// coordinate that is not finite. NrrdIO would refuse the first with "existance of all space
// vector coefficients must be consistent" and read the second as spacing 0; `none` axes and
// anything else are left to NrrdIO.
void check_nrrd_geometry(const std::string& header);

// NRRD's left-anterior-superior space (LAS, and its -time variant) read as ITK 5.2's
// NrrdImageIO reads it is wrong: it negates the x coordinates of the space directions and
// origin (as for RAS) where LAS to LPS negates y, so such a file came out mirrored left-right
// and front-back. For a LAS header with three domain axes this sets v's LPS direction and
// origin from the header itself (x kept, y negated; an ITK that reads LAS right gives the same
// numbers) and returns true; otherwise leaves v alone and returns false.
bool apply_nrrd_las_space(const std::string& header, Volume& v);

// The layout of a NRRD file's voxels when our reader can take them (raw or gzip, attached or
// one data file), nullopt otherwise. `data_bytes` is the voxel bytes the header claims; `swap`
// whether they are in the other byte order. Throws Error(header, "voxel data", "truncated:
// ...") when raw (or ascii/hex) data is shorter than that, before anything is allocated.
// `data_files` are the data files check_nrrd_data_files found (empty: attached data).
std::optional<MetaDataLayout> nrrd_layout(const std::string& header,
                                          const std::vector<std::string>& data_files,
                                          uint64_t data_bytes, uint64_t voxels, bool swap);

}  // namespace lacuna::io
