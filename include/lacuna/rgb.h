// RGB and RGBA volumes (docs/formats.md, "RGB volumes"): a NIfTI RGB24/RGBA32 file read as an
// ordinary scalar Volume whose voxels are the *opacity scalar* (what the TF's opacity, the value
// range and every skipping structure read: the Rec. 709 luminance 0.2126 r + 0.7152 g +
// 0.0722 b in float32, 0..255, or one channel in uint8), plus the colour of every voxel
// (RgbColours). The ray marcher takes a sample's colour from the trilinear RGB of the data and
// its opacity from the TF at the opacity scalar (src/render/rgb_march.h), so skipping stays exact
// by construction: nothing below the reader knows a volume is RGB but the one kernel that
// colours its samples.
//
// Where the colours live. They belong to the voxel buffer: the reader allocates the scalar
// buffer itself and hands it to the Volume (its adopting constructor) with an owner that also
// holds the colours; rgb_colours() finds them by the buffer's address while that owner lives.
// Copies and moves of the Volume share the buffer, hence the colours; a volume made from other
// voxels (a resample, a brick, a view of part of the buffer) is scalar. (A Volume member would
// say the same thing; this keeps lacuna/volume.h, which every file includes, unchanged.)
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "lacuna/io.h"
#include "lacuna/volume.h"

namespace lacuna {

// Which scalar of an RGB(A) volume drives opacity and skipping.
enum class RgbOpacity : uint8_t { Luminance, R, G, B, A };
std::string to_string(RgbOpacity o);
// Parses "luminance", "r", "g", "b", "a"; throws lacuna::Error(where, "rgb opacity", ...).
RgbOpacity parse_rgb_opacity(const std::string& name, const std::string& where = "--rgb-opacity");

struct RgbColours {
    int channels = 3;                            // in the file: 3 (RGB24) or 4 (RGBA32)
    RgbOpacity opacity = RgbOpacity::Luminance;  // what the volume's scalar voxels hold
    std::vector<uint8_t> rgba;  // 4 bytes per voxel (a = 255 without alpha), x fastest
};

// The colours of an RGB volume; nullptr for a scalar one.
const RgbColours* rgb_colours(const Volume& v);

// read_volume (lacuna/io.h) with the opacity scalar of RGB files chosen (A needs an RGBA file);
// scalar files read as read_volume(path, opts) reads them.
Volume read_volume(const std::string& path, const ReadOptions& opts, RgbOpacity rgb_opacity);

}  // namespace lacuna
