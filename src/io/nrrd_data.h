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

// The layout of a NRRD file's voxels when our reader can take them (raw or gzip, attached or
// one data file), nullopt otherwise. `data_bytes` is the voxel bytes the header claims; `swap`
// whether they are in the other byte order. Throws Error(header, "voxel data", "truncated:
// ...") when raw (or ascii/hex) data is shorter than that, before anything is allocated.
// `data_files` are the data files check_nrrd_data_files found (empty: attached data).
std::optional<MetaDataLayout> nrrd_layout(const std::string& header,
                                          const std::vector<std::string>& data_files,
                                          uint64_t data_bytes, uint64_t voxels, bool swap);

}  // namespace lacuna::io
