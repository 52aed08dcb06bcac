// Half-open ownership of the sample lattice (distributed rendering, docs/distributed.md).
//
// A ray's lattice is t_k = t_base + (k + 0.5) * dt, k = 0 .. k_end - 1 (lacuna/renderer.h), and
// sample k sits at p_k = o + t_k * d, evaluated in float exactly as the kernels evaluate it
// (render/ray_march_kernel.h RayStream::lut_entries: the same two operations per coordinate, in
// the same order, no fma contraction: the build passes -ffp-contract=off). A rank owns the samples
// with lo[a] <= p_k[a] < hi[a] on every axis a.
//
// Why the owned samples of one ray are one run [ka, kb) of k. Each IEEE operation rounds
// monotonically: float(k) is exact (k < 2^24), (k + 0.5) * dt and t_base + ... are non-decreasing
// in k, t * d[a] is non-decreasing for d[a] > 0 and non-increasing for d[a] < 0, and o[a] + ...
// keeps that. So p_k[a] is monotone in k on every axis, the samples with p_k[a] in [lo, hi) are
// an interval of k per axis, and their intersection over the three axes is an interval. The
// bounds below are found by evaluating the kernel's expression itself next to an analytic
// estimate, never by the estimate alone, so a sample on a face goes to exactly one side: the
// rank whose box holds the float position the kernel will sample at.
//
// Why no sample is taken twice or missed across ranks. The owned boxes of the decomposition
// (src/dist/decomposition.h) partition R^3: every interior face is the hi of one brick and the lo
// of its neighbour, and the outer faces are -inf / +inf. Every p_k therefore lies in exactly one
// owned box, so exactly one rank takes sample k of every ray.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lacuna/renderer.h"
#include "render/ray_march_kernel.h"

namespace lacuna {

// The whole grid seen through a brick's voxels: the whole grid's clamp box and cells with the
// brick's strides, and the voxel pointer moved so that a whole-grid offset k*sz + j*sy + i lands
// on the brick's voxel (i, j, k) - offset. Owned samples only read voxels of the brick
// (BrickOwnership's condition), and so do their gradients' central differences (the ghost layer,
// src/dist/decomposition.h); the moved pointer itself may point outside the buffer, which is why
// it is formed by integer arithmetic and only ever dereferenced at in-brick offsets.
inline ptrdiff_t brick_shift(const BrickOwnership& own, Vec3i brick_dims) {
    const ptrdiff_t sy = brick_dims.x, sz = ptrdiff_t(brick_dims.x) * brick_dims.y;
    return ptrdiff_t(own.offset.z) * sz + ptrdiff_t(own.offset.y) * sy + own.offset.x;
}
template <class T>
const T* shift_to_whole(const T* p, ptrdiff_t shift) {
    return reinterpret_cast<const T*>(reinterpret_cast<uintptr_t>(p) -
                                      uintptr_t(shift) * sizeof(T));
}
template <class T>
kernel::Grid<T, int64_t> brick_grid(const T* data, Vec3i brick_dims, const BrickOwnership& own) {
    kernel::Grid<T, int64_t> g = kernel::make_grid<int64_t>(data, own.whole_dims);
    g.sy = ptrdiff_t(brick_dims.x);
    g.sz = ptrdiff_t(brick_dims.x) * ptrdiff_t(brick_dims.y);
    g.data = shift_to_whole(data, brick_shift(own, brick_dims));
    return g;
}

// Coordinate `a` of lattice sample k: the kernel's expression, operation for operation.
inline float lattice_coordinate(const kernel::IndexRay& r, int a, float t_base, float dt, int k) {
    const float t = t_base + (float(k) + 0.5f) * dt;
    const float o = a == 0 ? r.ox : a == 1 ? r.oy : r.oz;
    const float d = a == 0 ? r.dx : a == 1 ? r.dy : r.dz;
    return o + t * d;
}

// The first k in [0, k_end] with pred(k) true (k_end if none), for pred monotone false -> true
// over k, searched from the estimate `guess` outward one sample at a time.
template <class Pred>
inline int first_true(double guess, int k_end, Pred&& pred) {
    int k =
        std::isfinite(guess) ? int(std::clamp(guess, 0.0, double(k_end))) : (guess > 0 ? k_end : 0);
    while (k > 0 && pred(k - 1)) --k;
    while (k < k_end && !pred(k)) ++k;
    return k;
}

// The run [ka, kb) of lattice samples of ray `r` (k < k_end) whose position lies in the box
// [lo, hi) (whole index space; -inf / +inf are allowed). Empty: ka >= kb.
inline void owned_run(const kernel::IndexRay& r, float t_base, float dt, int k_end,
                      const float lo[3], const float hi[3], int& ka, int& kb) {
    ka = 0;
    kb = k_end;
    const float o[3] = {r.ox, r.oy, r.oz}, d[3] = {r.dx, r.dy, r.dz};
    for (int a = 0; a < 3 && ka < kb; ++a) {
        auto p = [&](int k) { return lattice_coordinate(r, a, t_base, dt, k); };
        if (d[a] == 0.f) {  // p_k[a] = o[a] + t * 0 = o[a] for every sample
            const float x = p(0);
            if (!(x >= lo[a] && x < hi[a])) kb = ka;
            continue;
        }
        // k estimate where the coordinate crosses `bound`: t = (bound - o) / d.
        auto guess = [&](float bound) {
            return ((double(bound) - o[a]) / d[a] - t_base) / dt - 0.5;
        };
        int b, e;
        if (d[a] > 0.f) {  // p increases: [first p >= lo, first p >= hi)
            b = lo[a] == -INFINITY
                    ? 0
                    : first_true(guess(lo[a]), k_end, [&](int k) { return p(k) >= lo[a]; });
            e = hi[a] == INFINITY
                    ? k_end
                    : first_true(guess(hi[a]), k_end, [&](int k) { return p(k) >= hi[a]; });
        } else {  // p decreases: [first p < hi, first p < lo)
            b = hi[a] == INFINITY
                    ? 0
                    : first_true(guess(hi[a]), k_end, [&](int k) { return p(k) < hi[a]; });
            e = lo[a] == -INFINITY
                    ? k_end
                    : first_true(guess(lo[a]), k_end, [&](int k) { return p(k) < lo[a]; });
        }
        ka = std::max(ka, b);
        kb = std::min(kb, e);
    }
}

}  // namespace lacuna
