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
#include <cstddef>
#include <cstdint>
#include <type_traits>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#define LACUNA_SIMD_SSE41 1
#endif

#include "lacuna/transfer_function.h"

namespace lacuna::simd {

#if LACUNA_SIMD_SSE41

// The whole sample, four lanes in registers: lattice positions of k[0..3], cells, fractions,
// the 8 corners, the trilinear lerps and the LUT entries. Corners are loaded as pairs (voxels i
// and i+1 are adjacent in memory): one 16-bit (uint8), 32-bit (int16/uint16) or 64-bit (float)
// load per pair, four pairs a sample, inserted into vectors and split by shuffles, instead of
// eight scalar loads and conversions. Same operations in the same order as trilinear() and
// ValueToLut, so the same bits.
struct Sample4Grid {
    float o[3], d[3];     // the ray in index space
    float t_base, dt;     // lattice t_k = t_base + (k + 0.5) * dt
    float hi[3];          // dims - 1
    int cell[3];          // dims - 2
    int32_t sy, sz;       // strides
    float lut_offset, lut_scale, lut_last;  // ValueToLut
};

template <class T>
inline __m128i sample4(const Sample4Grid& g, const T* data, const int32_t* k) {
    const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f);
    const __m128i kk = _mm_loadu_si128(reinterpret_cast<const __m128i*>(k));
    const __m128 t = _mm_add_ps(_mm_set1_ps(g.t_base),
                                _mm_mul_ps(_mm_add_ps(_mm_cvtepi32_ps(kk), half), _mm_set1_ps(g.dt)));
    __m128 f[3];
    __m128i c[3];
    for (int a = 0; a < 3; ++a) {
        __m128 x = _mm_add_ps(_mm_set1_ps(g.o[a]), _mm_mul_ps(t, _mm_set1_ps(g.d[a])));
        x = _mm_max_ps(zero, _mm_min_ps(_mm_set1_ps(g.hi[a]), x));
        c[a] = _mm_min_epi32(_mm_cvttps_epi32(x), _mm_set1_epi32(g.cell[a]));
        f[a] = _mm_sub_ps(x, _mm_cvtepi32_ps(c[a]));
    }
    const __m128i off = _mm_add_epi32(_mm_add_epi32(_mm_mullo_epi32(c[2], _mm_set1_epi32(g.sz)),
                                                    _mm_mullo_epi32(c[1], _mm_set1_epi32(g.sy))),
                                      c[0]);
    alignas(16) int32_t o[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(o), off);
    const ptrdiff_t sy = g.sy, sz = g.sz, syz = ptrdiff_t(g.sy) + g.sz;
    // Corners: v[q][lane] for the pairs q = (0, sy, sz, sy+sz) -> c000/c100, c010/c110, ...
    __m128 lo[4], hi[4];
    if constexpr (sizeof(T) == 1) {
        // Two vectors of 8 x 16-bit pairs: lanes 0-3 pair q (samples 0..3), lanes 4-7 pair q+1.
        __m128i v01 = _mm_setzero_si128(), v23 = _mm_setzero_si128();
        auto pair = [](const T* p) {
            uint16_t w;
            __builtin_memcpy(&w, p, 2);
            return int(w);
        };
#define LACUNA_PAIRS(l)                                                   \
    {                                                                     \
        const T* p = data + o[l];                                         \
        v01 = _mm_insert_epi16(v01, pair(p), l);                          \
        v01 = _mm_insert_epi16(v01, pair(p + sy), 4 + l);                 \
        v23 = _mm_insert_epi16(v23, pair(p + sz), l);                     \
        v23 = _mm_insert_epi16(v23, pair(p + syz), 4 + l);                \
    }
        LACUNA_PAIRS(0) LACUNA_PAIRS(1) LACUNA_PAIRS(2) LACUNA_PAIRS(3)
#undef LACUNA_PAIRS
        const __m128i m_lo0 = _mm_setr_epi8(0, -1, -1, -1, 2, -1, -1, -1, 4, -1, -1, -1, 6, -1, -1, -1);
        const __m128i m_hi0 = _mm_setr_epi8(1, -1, -1, -1, 3, -1, -1, -1, 5, -1, -1, -1, 7, -1, -1, -1);
        const __m128i m_lo1 = _mm_setr_epi8(8, -1, -1, -1, 10, -1, -1, -1, 12, -1, -1, -1, 14, -1, -1, -1);
        const __m128i m_hi1 = _mm_setr_epi8(9, -1, -1, -1, 11, -1, -1, -1, 13, -1, -1, -1, 15, -1, -1, -1);
        lo[0] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v01, m_lo0));
        hi[0] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v01, m_hi0));
        lo[1] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v01, m_lo1));
        hi[1] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v01, m_hi1));
        lo[2] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v23, m_lo0));
        hi[2] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v23, m_hi0));
        lo[3] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v23, m_lo1));
        hi[3] = _mm_cvtepi32_ps(_mm_shuffle_epi8(v23, m_hi1));
    } else if constexpr (sizeof(T) == 2) {
        // Four vectors of 4 x 32-bit pairs.
        __m128i v[4] = {_mm_setzero_si128(), _mm_setzero_si128(), _mm_setzero_si128(),
                        _mm_setzero_si128()};
        auto pair = [](const T* p) {
            int32_t w;
            __builtin_memcpy(&w, p, 4);
            return w;
        };
#define LACUNA_PAIRS(l)                                 \
    {                                                   \
        const T* p = data + o[l];                       \
        v[0] = _mm_insert_epi32(v[0], pair(p), l);      \
        v[1] = _mm_insert_epi32(v[1], pair(p + sy), l); \
        v[2] = _mm_insert_epi32(v[2], pair(p + sz), l); \
        v[3] = _mm_insert_epi32(v[3], pair(p + syz), l); \
    }
        LACUNA_PAIRS(0) LACUNA_PAIRS(1) LACUNA_PAIRS(2) LACUNA_PAIRS(3)
#undef LACUNA_PAIRS
        for (int q = 0; q < 4; ++q) {
            if constexpr (std::is_signed_v<T>) {
                lo[q] = _mm_cvtepi32_ps(_mm_srai_epi32(_mm_slli_epi32(v[q], 16), 16));
                hi[q] = _mm_cvtepi32_ps(_mm_srai_epi32(v[q], 16));
            } else {
                lo[q] = _mm_cvtepi32_ps(_mm_and_si128(v[q], _mm_set1_epi32(0xffff)));
                hi[q] = _mm_cvtepi32_ps(_mm_srli_epi32(v[q], 16));
            }
        }
    } else {
        // float: per pair q two vectors of 2 pairs (64-bit loads), split into even and odd.
        const ptrdiff_t step[4] = {0, sy, sz, syz};
        for (int q = 0; q < 4; ++q) {
            const float* p0 = reinterpret_cast<const float*>(data + o[0] + step[q]);
            const float* p1 = reinterpret_cast<const float*>(data + o[1] + step[q]);
            const float* p2 = reinterpret_cast<const float*>(data + o[2] + step[q]);
            const float* p3 = reinterpret_cast<const float*>(data + o[3] + step[q]);
            const __m128 a = _mm_loadh_pi(_mm_loadl_pi(zero, reinterpret_cast<const __m64*>(p0)),
                                          reinterpret_cast<const __m64*>(p1));
            const __m128 b = _mm_loadh_pi(_mm_loadl_pi(zero, reinterpret_cast<const __m64*>(p2)),
                                          reinterpret_cast<const __m64*>(p3));
            lo[q] = _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0));
            hi[q] = _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1));
        }
    }
    auto lerp = [](__m128 a, __m128 b, __m128 w) {
        return _mm_add_ps(a, _mm_mul_ps(w, _mm_sub_ps(b, a)));
    };
    const __m128 c00 = lerp(lo[0], hi[0], f[0]), c10 = lerp(lo[1], hi[1], f[0]);
    const __m128 c01 = lerp(lo[2], hi[2], f[0]), c11 = lerp(lo[3], hi[3], f[0]);
    const __m128 c0 = lerp(c00, c10, f[1]), c1 = lerp(c01, c11, f[1]);
    const __m128 v = lerp(c0, c1, f[2]);
    __m128 u = _mm_add_ps(
        _mm_mul_ps(_mm_sub_ps(v, _mm_set1_ps(g.lut_offset)), _mm_set1_ps(g.lut_scale)), half);
    u = _mm_max_ps(zero, _mm_min_ps(_mm_set1_ps(g.lut_last), u));
    return _mm_cvttps_epi32(u);
}

#endif

}  // namespace lacuna::simd
