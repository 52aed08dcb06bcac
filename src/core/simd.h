// lacuna's SIMD, in one place (STYLE.md): the only file with intrinsics. For now the
// ray-marching kernel's batch (src/render/ray_march_kernel.h): Steps 1 and 3 of a batch of kBatch samples with SSE4.1 (the x86-64-v2 baseline every
// Release build targets): lattice positions, clamping, cells, fractions and offsets, then the
// trilinear lerps and the LUT index, four lanes at a time.
//
// Bit-exactness with the scalar trilinear() and ValueToLut::operator(): the same IEEE single
// operations in the same order (mul and add stay separate: no FMA), and the clamps written so
// that signed zeros and NaN come out as the scalar ternaries give them:
//   x < 0 ? 0 : (x > hi ? hi : x)   ==   max_ps(0, min_ps(hi, x))
// (min_ps/max_ps return their second operand on equality and on NaN).
#pragma once
#include <cstdint>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#define LACUNA_SIMD_SSE41 1
#endif

#include "lacuna/transfer_function.h"

namespace lacuna::simd {

#if LACUNA_SIMD_SSE41

// Positions of the lattice samples k[0..7]: fractions fx/fy/fz and int32 voxel offsets.
inline void positions8(float ox, float oy, float oz, float dx, float dy, float dz, float t_base,
                       float dt, const int32_t* k, float hi_x, float hi_y, float hi_z, int cell_x,
                       int cell_y, int cell_z, int32_t sy, int32_t sz, float* fx, float* fy,
                       float* fz, int32_t* off) {
    const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f), vdt = _mm_set1_ps(dt),
                 vbase = _mm_set1_ps(t_base);
    const __m128 vo[3] = {_mm_set1_ps(ox), _mm_set1_ps(oy), _mm_set1_ps(oz)};
    const __m128 vd[3] = {_mm_set1_ps(dx), _mm_set1_ps(dy), _mm_set1_ps(dz)};
    const __m128 vhi[3] = {_mm_set1_ps(hi_x), _mm_set1_ps(hi_y), _mm_set1_ps(hi_z)};
    const __m128i vcell[3] = {_mm_set1_epi32(cell_x), _mm_set1_epi32(cell_y),
                              _mm_set1_epi32(cell_z)};
    float* const f[3] = {fx, fy, fz};
    for (int h = 0; h < 8; h += 4) {
        const __m128i kk = _mm_loadu_si128(reinterpret_cast<const __m128i*>(k + h));
        // t = t_base + (float(k) + 0.5) * dt
        const __m128 t =
            _mm_add_ps(vbase, _mm_mul_ps(_mm_add_ps(_mm_cvtepi32_ps(kk), half), vdt));
        __m128i cell[3];
        for (int a = 0; a < 3; ++a) {
            __m128 x = _mm_add_ps(vo[a], _mm_mul_ps(t, vd[a]));
            x = _mm_max_ps(zero, _mm_min_ps(vhi[a], x));
            cell[a] = _mm_min_epi32(_mm_cvttps_epi32(x), vcell[a]);
            _mm_storeu_ps(f[a] + h, _mm_sub_ps(x, _mm_cvtepi32_ps(cell[a])));
        }
        // off = k*sz + j*sy + i (int32 arithmetic, as the scalar Index = int32_t path)
        const __m128i o = _mm_add_epi32(
            _mm_add_epi32(_mm_mullo_epi32(cell[2], _mm_set1_epi32(sz)),
                          _mm_mullo_epi32(cell[1], _mm_set1_epi32(sy))),
            cell[0]);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(off + h), o);
    }
}

// Trilinear lerps of 8 samples from their corners and fractions, then the LUT entry.
inline void interpolate8(const float* c000, const float* c100, const float* c010,
                         const float* c110, const float* c001, const float* c101,
                         const float* c011, const float* c111, const float* fx, const float* fy,
                         const float* fz, ValueToLut map, int* entry) {
    const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f),
                 vmin = _mm_set1_ps(map.offset()), vscale = _mm_set1_ps(map.scale()),
                 vlast = _mm_set1_ps(float(map.last()));
    auto lerp = [](__m128 a, __m128 b, __m128 w) {
        return _mm_add_ps(a, _mm_mul_ps(w, _mm_sub_ps(b, a)));
    };
    for (int h = 0; h < 8; h += 4) {
        const __m128 wx = _mm_loadu_ps(fx + h), wy = _mm_loadu_ps(fy + h), wz = _mm_loadu_ps(fz + h);
        const __m128 c00 = lerp(_mm_loadu_ps(c000 + h), _mm_loadu_ps(c100 + h), wx);
        const __m128 c10 = lerp(_mm_loadu_ps(c010 + h), _mm_loadu_ps(c110 + h), wx);
        const __m128 c01 = lerp(_mm_loadu_ps(c001 + h), _mm_loadu_ps(c101 + h), wx);
        const __m128 c11 = lerp(_mm_loadu_ps(c011 + h), _mm_loadu_ps(c111 + h), wx);
        const __m128 c0 = lerp(c00, c10, wy), c1 = lerp(c01, c11, wy);
        const __m128 v = lerp(c0, c1, wz);
        // ValueToLut: u = (v - min) * scale + 0.5, clamped to [0, last], truncated.
        __m128 u = _mm_add_ps(_mm_mul_ps(_mm_sub_ps(v, vmin), vscale), half);
        u = _mm_max_ps(zero, _mm_min_ps(vlast, u));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(entry + h), _mm_cvttps_epi32(u));
    }
}

#endif

}  // namespace lacuna::simd
