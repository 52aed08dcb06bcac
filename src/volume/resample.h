// Trilinear resampling of a volume onto another grid of the same voxel type (benchmarks: the
// mricron templates at about 256^3 and 512^3).
//
// Corner-aligned, in index space: output voxel i on an axis with n_in input and n_out output
// voxels samples the input at x = i * (n_in - 1) / (n_out - 1), so the first and last voxels of
// both grids coincide and the sampled region [0, dims-1] covers the same physical box. The output
// spacing is spacing_in * (n_in - 1) / (n_out - 1); origin and direction are copied, so the
// world extent (and a rendering's framing) is unchanged.
//
// Values: the trilinear interpolant evaluated in double, then stored as the voxel type does
// (float32 as is; integer types rounded to nearest, ties away from zero, and clamped to the
// type's range, which a trilinear value never leaves). A linear field a + b.x is therefore
// reproduced exactly up to that rounding. The visualization range of the input is kept (so a TF
// means the same thing on both grids); the data range is recomputed.
#pragma once
#include "lacuna/volume.h"

namespace lacuna {

// Throws lacuna::Error("resample", "dims", ...) for output dims outside [2, kMaxDim].
// `threads` as everywhere (0 = all); the result never depends on it.
Volume resample_trilinear(const Volume& in, Vec3i out_dims, int threads = 0);

// Output dims for "about n^3": every axis resampled to n voxels (cubic grids keep the
// comparison with the paper's 256^3 / 512^3 figures direct; the spacing keeps the shape).
inline Vec3i cube_dims(int n) {
    return {n, n, n};
}

}  // namespace lacuna
