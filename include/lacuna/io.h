// Volume readers and writers: one interface, implemented in src/io/ (ITK's image IO for NRRD,
// MetaImage headers and DICOM series; our own code for NIfTI-1/2, MetaImage voxel data and raw
// files). Formats, conversions and error messages: docs/formats.md.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "lacuna/volume.h"

namespace lacuna {

struct RawSpec {
    Vec3i dims{0, 0, 0};
    VoxelType type = VoxelType::UInt8;
    Vec3d spacing{1, 1, 1};
    bool big_endian = false;
};

// The most memory one read may allocate (voxels plus any conversion buffer), checked from the
// header before anything is allocated. `name` is how errors call the limit, so a front end can
// name its own flag ("--max-memory") while the library names none.
struct MemoryBudget {
    uint64_t bytes = 0;  // 0: default_memory_budget()
    std::string name = "the memory budget";
};
// Half of the physical memory (or of the cgroup's memory.max when that is lower): a volume may
// take half the machine, the other half is left for skipping structures, images and the rest.
uint64_t default_memory_budget();
// "5.4 GB", "120 MB", "17 B": decimal units, two significant digits.
std::string format_bytes(uint64_t bytes);

struct ReadOptions {
    // For .raw files: explicit layout; when unset, parsed from "name_301x370x316_uint8.raw".
    std::optional<RawSpec> raw;
    // Called with a fraction in [0,1] during long reads (may be null).
    std::function<void(double)> progress;
    MemoryBudget max_memory;
    // Detached data files (.nhdr "data file", .mhd ElementDataFile) must be regular files in
    // the header's folder or below it; true also allows any other regular file.
    bool allow_external_data = false;
    // Which volume of a 4D NIfTI file (0-based, along dim[4]): required when the file holds more
    // than one, which is otherwise an error naming their count; a 3D file takes only 0. Other
    // formats are read as one volume and take only 0.
    std::optional<int64_t> frame;
};

// Reads a volume: .nii/.nii.gz (NIfTI-1/2; of a 4D file the volume ReadOptions::frame),
// .nrrd/.nhdr, .mha/.mhd, a folder of DICOM slices, or .raw. Voxel types other than
// uint8/int16/uint16/float32 are converted (int8 -> int16, uint32/int32/float64 -> float32);
// non-scalar images are rejected. Computes the value range and rejects NaN/Inf. The voxels are read
// once into the Volume's own buffer (no second full-size copy). Throws lacuna::Error("<path>",
// "<field>", "<problem>") on any bad input.
Volume read_volume(const std::string& path, const ReadOptions& opts = {});

// Parses "name_301x370x316_uint8.raw"-style names; nullopt if the name does not match.
std::optional<RawSpec> raw_spec_from_name(const std::string& path);

// Writes a volume as .nrrd, .nhdr, .nii, .nii.gz, .mha, .mhd or .raw (by extension), atomically:
// a temporary file beside the target, its written size checked, fsync'ed, then renamed. A path
// ending in '/' writes a DICOM series into that folder (integer volumes only; the folder must
// not exist or be empty, and is renamed into place complete). Temporary files left by dead
// processes are removed first (docs/formats.md, "Writing"). Throws lacuna::Error on failure
// and leaves nothing behind.
void write_volume(const std::string& path, const Volume& v);

}  // namespace lacuna
