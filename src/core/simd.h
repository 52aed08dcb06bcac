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

// Four rays in lockstep, one per lane: the ray marcher's inner loop (src/render/ray_lanes.h).
//
// Why lanes are rays. Front-to-back compositing is a serial chain per ray (w = 1 - a, then
// a += w * c: a subtract, a multiply and an add of latency, ~10 cycles a sample), so one ray at
// a time cannot go faster than that however wide the sampling is. Four rays advance the four
// chains in one set of instructions; each lane performs exactly the scalar operations of its own
// ray in its own sample order, so every ray's bits are those of one ray at a time.
//
// State is kept in arrays (the scheduler in render/ reads and refills single lanes) and held in
// registers while march_lanes4 runs. A lane is valid while k < kend; an invalid lane composites
// the zero LUT entry `zero_entry` (C + w*0 = C, exactly), so it changes nothing and is not counted.
struct Lanes4 {
    alignas(16) float ox[4], oy[4], oz[4], dx[4], dy[4], dz[4], t_base[4];
    alignas(16) int32_t k[4], kend[4];
    alignas(16) float r[4], g[4], b[4], a[4];
    alignas(16) int32_t n[4];       // samples composited
    alignas(16) int32_t active[4];  // -1: the lane holds a ray; 0: idle
};

struct LaneGrid {
    float dt;
    float hi[3];
    int cell[3];
    int32_t sy, sz;
    float lut_offset, lut_scale, lut_last;
    int32_t zero_entry;
    float ert;
};

// Marches every active lane until one of them needs the scheduler: its run ended (k == kend) or
// it turned opaque (a >= ert). Returns that lane mask (bit l = lane l). `lut` holds RGBA entries
// (premultiplied, step-corrected), entry zero_entry all zero.
template <class T>
inline int march_lanes4(Lanes4& s, const LaneGrid& g, const T* data, const float* lut) {
    const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f), one = _mm_set1_ps(1.f);
    const __m128 vdt = _mm_set1_ps(g.dt), vert = _mm_set1_ps(g.ert);
    const __m128 vhi[3] = {_mm_set1_ps(g.hi[0]), _mm_set1_ps(g.hi[1]), _mm_set1_ps(g.hi[2])};
    const __m128i vcell[3] = {_mm_set1_epi32(g.cell[0]), _mm_set1_epi32(g.cell[1]),
                              _mm_set1_epi32(g.cell[2])};
    const __m128i vsy = _mm_set1_epi32(g.sy), vsz = _mm_set1_epi32(g.sz);
    const __m128 voff = _mm_set1_ps(g.lut_offset), vscale = _mm_set1_ps(g.lut_scale),
                 vlast = _mm_set1_ps(g.lut_last);
    const __m128i vzero_entry = _mm_set1_epi32(g.zero_entry);
    const __m128 o[3] = {_mm_load_ps(s.ox), _mm_load_ps(s.oy), _mm_load_ps(s.oz)};
    const __m128 d[3] = {_mm_load_ps(s.dx), _mm_load_ps(s.dy), _mm_load_ps(s.dz)};
    const __m128 tb = _mm_load_ps(s.t_base);
    const __m128i kend = _mm_load_si128(reinterpret_cast<const __m128i*>(s.kend));
    const __m128i active = _mm_load_si128(reinterpret_cast<const __m128i*>(s.active));
    __m128i k = _mm_load_si128(reinterpret_cast<const __m128i*>(s.k));
    __m128i n = _mm_load_si128(reinterpret_cast<const __m128i*>(s.n));
    __m128 ar = _mm_load_ps(s.r), ag = _mm_load_ps(s.g), ab = _mm_load_ps(s.b),
           aa = _mm_load_ps(s.a);
    const ptrdiff_t sy = g.sy, sz = g.sz, syz = ptrdiff_t(g.sy) + g.sz;
    int need;
    for (;;) {
        const __m128i valid = _mm_cmplt_epi32(k, kend);
        // 1. Positions t_k = t_base + (k + 0.5) * dt; cells, fractions, offsets.
        const __m128 t = _mm_add_ps(tb, _mm_mul_ps(_mm_add_ps(_mm_cvtepi32_ps(k), half), vdt));
        __m128 f[3];
        __m128i c[3];
        for (int a = 0; a < 3; ++a) {
            __m128 x = _mm_add_ps(o[a], _mm_mul_ps(t, d[a]));
            x = _mm_max_ps(zero, _mm_min_ps(vhi[a], x));
            c[a] = _mm_min_epi32(_mm_cvttps_epi32(x), vcell[a]);
            f[a] = _mm_sub_ps(x, _mm_cvtepi32_ps(c[a]));
        }
        __m128i off = _mm_add_epi32(
            _mm_add_epi32(_mm_mullo_epi32(c[2], vsz), _mm_mullo_epi32(c[1], vsy)), c[0]);
        // Idle lanes read voxel 0 (their position is garbage); their entry is replaced below.
        off = _mm_and_si128(off, active);
        alignas(16) int32_t ofs[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(ofs), off);
        // 2. Corners as pairs (as sample4).
        __m128 lo[4], hi[4];
        if constexpr (sizeof(T) == 1) {
            __m128i v01 = _mm_setzero_si128(), v23 = _mm_setzero_si128();
            auto pair = [](const T* p) {
                uint16_t w;
                __builtin_memcpy(&w, p, 2);
                return int(w);
            };
#define LACUNA_PAIRS(l)                                        \
    {                                                          \
        const T* p = data + ofs[l];                            \
        v01 = _mm_insert_epi16(v01, pair(p), l);               \
        v01 = _mm_insert_epi16(v01, pair(p + sy), 4 + l);      \
        v23 = _mm_insert_epi16(v23, pair(p + sz), l);          \
        v23 = _mm_insert_epi16(v23, pair(p + syz), 4 + l);     \
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
            __m128i v[4] = {_mm_setzero_si128(), _mm_setzero_si128(), _mm_setzero_si128(),
                            _mm_setzero_si128()};
            auto pair = [](const T* p) {
                int32_t w;
                __builtin_memcpy(&w, p, 4);
                return w;
            };
#define LACUNA_PAIRS(l)                                  \
    {                                                    \
        const T* p = data + ofs[l];                      \
        v[0] = _mm_insert_epi32(v[0], pair(p), l);       \
        v[1] = _mm_insert_epi32(v[1], pair(p + sy), l);  \
        v[2] = _mm_insert_epi32(v[2], pair(p + sz), l);  \
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
            const ptrdiff_t step[4] = {0, sy, sz, syz};
            for (int q = 0; q < 4; ++q) {
                const __m64* p0 = reinterpret_cast<const __m64*>(data + ofs[0] + step[q]);
                const __m64* p1 = reinterpret_cast<const __m64*>(data + ofs[1] + step[q]);
                const __m64* p2 = reinterpret_cast<const __m64*>(data + ofs[2] + step[q]);
                const __m64* p3 = reinterpret_cast<const __m64*>(data + ofs[3] + step[q]);
                const __m128 x01 = _mm_loadh_pi(_mm_loadl_pi(zero, p0), p1);
                const __m128 x23 = _mm_loadh_pi(_mm_loadl_pi(zero, p2), p3);
                lo[q] = _mm_shuffle_ps(x01, x23, _MM_SHUFFLE(2, 0, 2, 0));
                hi[q] = _mm_shuffle_ps(x01, x23, _MM_SHUFFLE(3, 1, 3, 1));
            }
        }
        // 3. Trilinear lerps (trilinear()'s order) and the LUT entry (ValueToLut).
        auto lerp = [](__m128 a, __m128 b, __m128 w) {
            return _mm_add_ps(a, _mm_mul_ps(w, _mm_sub_ps(b, a)));
        };
        const __m128 c00 = lerp(lo[0], hi[0], f[0]), c10 = lerp(lo[1], hi[1], f[0]);
        const __m128 c01 = lerp(lo[2], hi[2], f[0]), c11 = lerp(lo[3], hi[3], f[0]);
        const __m128 c0 = lerp(c00, c10, f[1]), c1 = lerp(c01, c11, f[1]);
        const __m128 v = lerp(c0, c1, f[2]);
        __m128 u = _mm_add_ps(_mm_mul_ps(_mm_sub_ps(v, voff), vscale), half);
        u = _mm_max_ps(zero, _mm_min_ps(vlast, u));
        const __m128i entry = _mm_blendv_epi8(vzero_entry, _mm_cvttps_epi32(u), valid);
        // 4. Composite one sample per lane: RGBA of the 4 entries, transposed to SoA.
        alignas(16) int32_t e[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(e), entry);
        __m128 cr = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[0])), cg = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[1]));
        __m128 cb = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[2])), ca = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[3]));
        _MM_TRANSPOSE4_PS(cr, cg, cb, ca);
        const __m128 w = _mm_sub_ps(one, aa);
        ar = _mm_add_ps(ar, _mm_mul_ps(w, cr));
        ag = _mm_add_ps(ag, _mm_mul_ps(w, cg));
        ab = _mm_add_ps(ab, _mm_mul_ps(w, cb));
        aa = _mm_add_ps(aa, _mm_mul_ps(w, ca));
        n = _mm_sub_epi32(n, valid);
        k = _mm_sub_epi32(k, valid);  // k + 1 on valid lanes
        // 5. A lane needs the scheduler when its run is over or it is opaque.
        const __m128i over = _mm_or_si128(_mm_cmpeq_epi32(k, kend),
                                          _mm_castps_si128(_mm_cmpge_ps(aa, vert)));
        need = _mm_movemask_ps(_mm_castsi128_ps(_mm_and_si128(over, active)));
        if (need) break;
    }
    _mm_store_si128(reinterpret_cast<__m128i*>(s.k), k);
    _mm_store_si128(reinterpret_cast<__m128i*>(s.n), n);
    _mm_store_ps(s.r, ar);
    _mm_store_ps(s.g, ag);
    _mm_store_ps(s.b, ab);
    _mm_store_ps(s.a, aa);
    return need;
}

#endif

}  // namespace lacuna::simd
