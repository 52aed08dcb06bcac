// RGB24 and RGBA32 voxels read into a volume (lacuna/rgb.h): the colours beside the buffer, the
// opacity scalar into the volume's own voxels.
//
// The opacity scalar is computed once here, while reading, and nowhere else: every consumer
// below (value range, TF, skipping structures, the renderers' opacity) then sees an ordinary
// scalar volume, which is why skipping is exact for RGB volumes without a line of new
// structure code. Luminance is Rec. 709 (ITU-R BT.709 luma weights on the stored values, as
// ITK's RGBPixel::GetLuminance computes it), in float32 so that no rounding merges two colours'
// opacities; a single channel is its uint8 value as is.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "lacuna/rgb.h"

namespace lacuna::io {

// Rec. 709 luminance of stored 8-bit values (0..255): one float expression, one operation
// order, so every caller gets the same bits.
inline float rgb_luminance(uint8_t r, uint8_t g, uint8_t b) {
    return 0.2126f * float(r) + 0.7152f * float(g) + 0.0722f * float(b);
}

// The voxel type of the opacity scalar: float32 for luminance, uint8 for a channel.
VoxelType rgb_scalar_type(RgbOpacity o);
// Bytes one RGB volume takes in memory per voxel: the 4 colour bytes and the scalar.
uint64_t rgb_bytes_per_voxel(RgbOpacity o);
// Throws Error(path, "rgb opacity", ...) when `o` asks for alpha of a file without it.
void check_rgb_opacity(int channels, RgbOpacity o, const std::string& path);

// A zeroed volume of rgb_scalar_type(o) whose rgb_colours() are `channels`, `o` and no voxels
// yet (read_rgb_stream fills both). The caller checked the memory budget.
Volume rgb_volume(Vec3i dims, int channels, RgbOpacity o, const std::string& where);

// Reads voxel_count * channels interleaved bytes (r, g, b[, a] per voxel) from `read` (as in
// read_voxel_stream) into the colours and the scalar voxels of a volume from rgb_volume().
// Throws Error(where, "voxel data", "truncated: ...") when the stream ends early.
void read_rgb_stream(const std::function<size_t(void*, size_t)>& read, Volume& v,
                     const std::string& where, const std::function<void(double)>& progress);

}  // namespace lacuna::io
