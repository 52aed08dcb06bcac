// Synthetic volumes for tests, demos and benchmarks (`lacuna generate KIND`).
//
// Every kind is a normalised signal s in [0,1], quantised to the voxel type's useful range
// (synthetic_value_range): stored = lo + round(s * (hi - lo)), s clamped to [0,1] first.
//     uint8    0 .. 255
//     uint16   0 .. 65535
//     int16    -1024 .. 3071   (CT-like: "empty" is -1024, the air value, not 0)
//     float32  0 .. 1          (s stored as is, no rounding)
// "Empty" below means s = 0 (stored lo); "max" means s = 1 (stored hi). The volume's
// data_range is computed before generate() returns. Definitions per kind: docs/synthetic.md.
//
// Index space as in volume.h: voxel (i,j,k), dims (nx,ny,nz), centre c = (dims-1)/2 (double),
// m = min(nx,ny,nz) - 1.
//
//   SphereShells   rho = |p - c| / (m/2); s = 1.0 for 0.15 <= rho <= 0.30, 0.75 for
//                  0.40..0.55, 0.5 for 0.65..0.75, 0.25 for 0.85..0.95 (inclusive), else 0.
//   MarschnerLobb  s = marschner_lobb(x,y,z), x = -1 + 2*float(i)/float(nx-1) (same for y, z).
//   Tree           trunk up from the bottom centre (k = 0), 3-6 levels of tapering branches
//                  and leaf blobs, all from the seed; > 90% empty voxels at 64^3 and larger.
//                  Wood s = 1 on the trunk's axis; leaves s in [0.35, 0.55].
//   NoiseBlobs     24-40 truncated Gaussians summed and clamped to 1; exactly 0 beyond 3 sigma.
//   ThinSheets     s = 1 on the planes i = nx/3, j = ny/2, k = 2*nz/3, i = j, and
//                  i + j + k = (nx+ny+nz-3)/2 (integer division), else 0.
//   Checkerboard   s = 1 where (i + j + k) is odd, else 0.
//   BinBoundaries  2x2x2 bricks of values on/around LUT and bitfield-bin boundaries, and
//                  empty bricks (see generate_bin_boundaries in src/volume/synthetic.cpp).
//   Slab           s = 1 for nz/4 <= k <= 3*nz/4 (integer division, both ends inclusive, all i,j),
//                  else 0. E.g. nz = 64: slices 16..48 are max, 0..15 and 49..63 empty.
//   Sphere         s = 1 where d2 <= r*r, else 0, computed in double:
//                  d2 = (i-cx)^2 + (j-cy)^2 + (k-cz)^2, r = 0.35 * m. Binary, no anti-aliasing.
//
// Deterministic for (kind, dims, type, seed): every voxel is a pure function of those (random
// numbers come from a splitmix64 stream, never <random>), so the bytes never depend on the
// thread count. Only Tree and NoiseBlobs use the seed.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "lacuna/volume.h"

namespace lacuna {

enum class SyntheticKind {
    SphereShells,   // concentric spherical shells of different values
    MarschnerLobb,  // the Marschner-Lobb test signal (float32 or quantised)
    Tree,           // sparse branching tree-like structure (the kd-tree paper's plant models)
    NoiseBlobs,     // smooth noise blobs in empty space
    ThinSheets,     // adversarial: one-voxel-thin planes
    Checkerboard,   // adversarial: 0/max voxel checkerboard
    BinBoundaries,  // adversarial: values exactly on LUT/bitfield bin boundaries
    Slab,           // a homogeneous slab (analytic transmittance tests)
    Sphere,         // a solid sphere (silhouette tests)
};

struct SyntheticOptions {
    Vec3i dims{64, 64, 64};  // any size >= 2, odd and non-power-of-two included
    VoxelType type = VoxelType::UInt8;
    uint32_t seed = 1;
    int threads = 0;  // worker threads (0 = all hardware threads); never changes the result
};

std::string to_string(SyntheticKind k);
// Throws lacuna::Error listing valid names.
SyntheticKind parse_synthetic_kind(const std::string& name);
std::vector<std::string> synthetic_kind_names();

// Deterministic for (kind, options): same bytes on every machine and thread count.
Volume generate(SyntheticKind kind, const SyntheticOptions& opts);

// Stored values of s = 0 (min) and s = 1 (max) for a voxel type (table above).
ValueRange synthetic_value_range(VoxelType t);

// The Marschner-Lobb signal (Marschner & Lobb 1994) over [-1,1]^3, in [0,1]:
//     rho(x,y,z) = (1 - sin(pi z/2) + alpha (1 + rho_r(sqrt(x^2 + y^2)))) / (2 (1 + alpha))
//     rho_r(r)   = cos(2 pi f_M cos(pi r / 2)),  f_M = 6, alpha = 0.25
// Evaluated in double, rounded to float once.
float marschner_lobb(float x, float y, float z);

}  // namespace lacuna
