// The on-the-fly gradient of the shaded paths (GradientSource::OnTheFly): the voxels' central
// differences, interpolated trilinearly at the sample.
//
// Why this form. The gradient of a shaded sample was (f(p + e) - f(p - e)) / 2 per axis, f the
// trilinear field: six trilinear values, 48 voxel reads. Trilinear interpolation is linear in the
// voxels and a shift by one voxel keeps the weights, so wherever p +- 1 stays in the grid that is
// exactly the interpolation, with p's own cell and weights, of the voxels' central differences
// D_x = v[i+1] - v[i-1] (and D_y, D_z): the same quantity from the 32 voxels around p's cell
// (rows of four voxels along each axis through the cell's corners), and one lerp tree per axis
// instead of two. At the grid's faces the border voxel is repeated
// (D_x = v[1] - v[0] at i = 0), half the one-sided difference, as the clamped
// positions of the former six-sample form gave.
//
// Bit-exactness. Every path computes this function's operations in its order: the clamp, cell
// and weights of kernel::trilinear, corner differences float(a) - float(b) (exact for integer
// voxels), trilinear's lerps, then (d * 0.5f) * inv_sp. The SIMD lanes (core/simd_shading.h
// gradients4/8) run the same operations, or call this function for lanes on the grid's faces.
#pragma once
#include <algorithm>
#include <cstddef>

namespace lacuna {

// Values per mm at index point (x, y, z) of the grid `data` (strides sy, sz; hi = dims - 1,
// cell = dims - 2 per axis), into g[3].
template <class T>
inline void central_gradient(const T* data, ptrdiff_t sy, ptrdiff_t sz, const float hi[3],
                             const int cell[3], const float inv_sp[3], float x, float y, float z,
                             float g[3]) {
    x = std::clamp(x, 0.f, hi[0]);
    y = std::clamp(y, 0.f, hi[1]);
    z = std::clamp(z, 0.f, hi[2]);
    const int i = std::min(int(x), cell[0]), j = std::min(int(y), cell[1]),
              k = std::min(int(z), cell[2]);
    const float fx = x - float(i), fy = y - float(j), fz = z - float(k);
    const int last[3] = {cell[0] + 1, cell[1] + 1, cell[2] + 1};
    auto v = [&](int a, int b, int c) {
        a = std::clamp(a, 0, last[0]), b = std::clamp(b, 0, last[1]), c = std::clamp(c, 0, last[2]);
        return float(data[ptrdiff_t(c) * sz + ptrdiff_t(b) * sy + a]);
    };
    // Corner differences in trilinear's corner order: 000, 100, 010, 110, 001, 101, 011, 111.
    float d[3][8];
    for (int q = 0; q < 8; ++q) {
        const int a = i + (q & 1), b = j + (q >> 1 & 1), c = k + (q >> 2);
        d[0][q] = v(a + 1, b, c) - v(a - 1, b, c);
        d[1][q] = v(a, b + 1, c) - v(a, b - 1, c);
        d[2][q] = v(a, b, c + 1) - v(a, b, c - 1);
    }
    for (int e = 0; e < 3; ++e) {
        const float* c = d[e];
        const float c00 = c[0] + fx * (c[1] - c[0]), c10 = c[2] + fx * (c[3] - c[2]);
        const float c01 = c[4] + fx * (c[5] - c[4]), c11 = c[6] + fx * (c[7] - c[6]);
        const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
        g[e] = (c0 + fz * (c1 - c0)) * 0.5f * inv_sp[e];
    }
}

// The same gradient at voxel (i, j, k) itself (nearest sampling: the sample moved to its voxel),
// from the voxel's own central differences only. central_gradient at that integer point gives
// these bits for integer voxels (weights 0 or 1 on exact differences), but it also reads the
// cell's far corners, one voxel further than the differences need: a voxel past a distributed
// brick's ghost layer (src/dist/decomposition.h). This reads the six neighbours only, clamped
// to the grid as above (last = dims - 1).
template <class T>
inline void voxel_gradient(const T* data, ptrdiff_t sy, ptrdiff_t sz, const int last[3],
                           const float inv_sp[3], int i, int j, int k, float g[3]) {
    auto v = [&](int a, int b, int c) {
        a = std::clamp(a, 0, last[0]), b = std::clamp(b, 0, last[1]), c = std::clamp(c, 0, last[2]);
        return float(data[ptrdiff_t(c) * sz + ptrdiff_t(b) * sy + a]);
    };
    g[0] = (v(i + 1, j, k) - v(i - 1, j, k)) * 0.5f * inv_sp[0];
    g[1] = (v(i, j + 1, k) - v(i, j - 1, k)) * 0.5f * inv_sp[1];
    g[2] = (v(i, j, k + 1) - v(i, j, k - 1)) * 0.5f * inv_sp[2];
}

}  // namespace lacuna
