// Where a MetaImage's voxels live and how to read them (see metaimage_data.cpp).
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "io/io_util.h"
#include "lacuna/volume.h"

namespace lacuna::io {

struct MetaDataLayout {
    std::string path;    // file holding the voxels
    int64_t offset = 0;  // first voxel byte (of the compressed stream when compressed)
    bool compressed = false;
    bool swap = false;  // file byte order differs from the host's
};

// Guards MetaIO against headers it mishandles: MetaIO reads NDims-long (and NDims^2-long)
// fields without checking NDims, so "NDims = -3" makes it try to read billions of numbers.
// Throws Error(path, "header", ...) unless NDims is 3 or 4. Also guards MetaIO's fixed 255-byte
// field buffers (a 256-character key or value aborted the process through glibc's fortify
// check, found by fuzz_metaimage): every key and value up to ElementDataFile is at most 254
// characters, and ElementDataFile must come within the first MiB. A geometry field
// (TransformMatrix, Offset, ElementSpacing and their synonyms) holding a number that is not
// finite is Error(path, <field>, ...): MetaIO stops at it and blames a later field. Call before
// ITK reads the header. Returns what the header says about orientation (below).
struct MetaHeaderOrientation {
    bool has_matrix = false;             // TransformMatrix (or its synonyms Rotation, Orientation)
    std::string anatomical_orientation;  // the raw AnatomicalOrientation value ("" when absent)
};
MetaHeaderOrientation check_metaimage_header(const std::string& path);

// Applies AnatomicalOrientation to v's LPS direction (read from TransformMatrix by ITK). MetaIO's
// letters name the side each index axis comes FROM: "RAI" = x from right to left, y from anterior
// to posterior, z from inferior to superior, i.e. LPS+ identity (what ITK writes for it). Without
// a TransformMatrix (which MetaIO then takes as identity) the letters define the axes; with both,
// TransformMatrix wins (ITK and every ITK-based tool read only it) and a disagreement is noted in
// v.geometry_source. Throws Error(path, "AnatomicalOrientation", ...) for a value that is not
// three letters, one of R/L, A/P and S/I each ("???" and an absent field mean none).
void apply_anatomical_orientation(const MetaHeaderOrientation& h, Volume& v,
                                  const std::string& path);

// Locates the voxel data described by a parsed MetaImage header; nullopt for ASCII voxels,
// which MetaIO parses. An external data file must pass check_data_file (detached_data.h);
// slice lists and file-name patterns are rejected. For uncompressed data, throws
// Error(header_path, "voxel data", "truncated: ...") when the file is shorter than
// `data_bytes` — before anything is allocated.
std::optional<MetaDataLayout> metaimage_layout(const std::string& header_path,
                                               const std::string& data_file, int header_size,
                                               bool compressed, bool binary, bool msb,
                                               size_t data_bytes, bool allow_external);

// Reads (inflating if needed) the voxels into v, converting from `disk`.
void read_metaimage_voxels(const MetaDataLayout& layout, DiskType disk, Volume& v,
                           const std::string& where, const std::function<void(double)>& progress);

}  // namespace lacuna::io
