// SIMD helpers of the shaded ray path (src/render/feature_kernel.h, docs/shading.md "Batched
// shading"): lattice positions, trilinear values, LUT entries and opacity masks, on-the-fly
// central-difference and gradient-volume gradients, and Phong / PBR shading of a batch of
// samples, one sample per lane. SSE4.1 (4 lanes, the baseline) and AVX2 (8 lanes, through
// __attribute__((target)) like core/simd_lanes.h; run only after simd::isa_supported).
//
// Bit-exactness with kernel::trilinear() and feature::gradient(): each lane performs the scalar
// operations of its own sample in the same order. Clamps: std::clamp(x, 0, hi) is
// x < 0 ? 0 : (hi < x ? hi : x) == max_ps(0, min_ps(hi, x)) (min/max return their second operand
// on ties, so -0 and NaN come out alike); int() truncates like cvttps; corners convert exactly
// (integers below 2^24, or floats as they are); lerps are a + w * (b - a) with mul and add kept
// apart (-ffp-contract=off, no fma intrinsics). The gradient's neighbour positions are x + 1.f and
// x - 1.f in single precision, as the scalar code computes them, never a shifted cell.
//
// Offsets are int32: callers use these only for grids under 2^31 voxels.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "core/gradient.h"
#include "core/simd_lanes.h"
#include "core/spec_pow.h"

namespace lacuna::simd {

// The sampled grid, as kernel::Grid holds it.
struct ShadeGrid {
    float hi[3];                            // dims - 1
    int32_t cell[3];                        // dims - 2
    int32_t sy, sz;                         // strides of j and k
    float inv_sp[3];                        // 1 / spacing: index-space differences -> values per mm
    float lut_offset, lut_scale, lut_last;  // ValueToLut
    const float* alpha;  // TF opacities, every 4th float (&Rgba::a of the front LUT)
    // The structure's visible-cell mask (accel/cell_ranges.h visible_cell_mask), or nullptr.
    // A batch none of whose cells is visible is exactly transparent: samples4/8 return an
    // empty mask without interpolating (x, y, z are still written; v and e are not).
    const uint32_t* cell_mask = nullptr;
};

// One ray's sample lattice in index space: sample k at o + t*d, t = t_base + (k + 0.5)*dt
// (composite_ray's positions, operation for operation).
struct ShadeRay {
    float o[3], d[3];
    float t_base, dt;
};

// central_gradient (core/gradient.h) at the first n positions, one after the other.
template <class T>
inline void central_gradients(const ShadeGrid& g, const T* data, const float* px, const float* py,
                              const float* pz, float* gx, float* gy, float* gz, int n) {
    for (int l = 0; l < n; ++l) {
        float r[3];
        central_gradient(data, g.sy, g.sz, g.hi, g.cell, g.inv_sp, px[l], py[l], pz[l], r);
        gx[l] = r[0], gy[l] = r[1], gz[l] = r[2];
    }
}

#if LACUNA_SIMD_X86 && defined(__SSE4_1__)

// ---- SSE4.1: four lanes ------------------------------------------------------------------
template <class T>
inline __m128 trilinear4(const ShadeGrid& g, const T* data, __m128 x, __m128 y, __m128 z) {
    const __m128 zero = _mm_setzero_ps();
    __m128 p[3] = {x, y, z}, f[3];
    __m128i c[3];
    for (int a = 0; a < 3; ++a) {
        const __m128 q = _mm_max_ps(zero, _mm_min_ps(_mm_set1_ps(g.hi[a]), p[a]));
        c[a] = _mm_min_epi32(_mm_cvttps_epi32(q), _mm_set1_epi32(g.cell[a]));
        f[a] = _mm_sub_ps(q, _mm_cvtepi32_ps(c[a]));
    }
    const __m128i off = _mm_add_epi32(_mm_add_epi32(_mm_mullo_epi32(c[2], _mm_set1_epi32(g.sz)),
                                                    _mm_mullo_epi32(c[1], _mm_set1_epi32(g.sy))),
                                      c[0]);
    alignas(16) int32_t o[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(o), off);
    const ptrdiff_t sy = g.sy, sz = g.sz, syz = sy + sz;
    const T* p0 = data + o[0];
    const T* p1 = data + o[1];
    const T* p2 = data + o[2];
    const T* p3 = data + o[3];
    auto corner = [&](ptrdiff_t d) {
        return _mm_setr_ps(float(p0[d]), float(p1[d]), float(p2[d]), float(p3[d]));
    };
    auto lerp = [](__m128 a, __m128 b, __m128 w) {
        return _mm_add_ps(a, _mm_mul_ps(w, _mm_sub_ps(b, a)));
    };
    const __m128 c00 = lerp(corner(0), corner(1), f[0]);
    const __m128 c10 = lerp(corner(sy), corner(sy + 1), f[0]);
    const __m128 c01 = lerp(corner(sz), corner(sz + 1), f[0]);
    const __m128 c11 = lerp(corner(syz), corner(syz + 1), f[0]);
    const __m128 c0 = lerp(c00, c10, f[1]), c1 = lerp(c01, c11, f[1]);
    return lerp(c0, c1, f[2]);
}

// The positions of lattice samples k[0..3] into x, y, z, their trilinear values into v, their
// LUT entries (ValueToLut) into e; returns the mask of lanes whose TF opacity (g.alpha) is > 0.
template <class T>
inline int samples4(const ShadeGrid& g, const ShadeRay& r, const T* data, const int32_t* k,
                    float* x, float* y, float* z, float* v, int32_t* e) {
    const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f);
    const __m128 t = _mm_add_ps(
        _mm_set1_ps(r.t_base),
        _mm_mul_ps(
            _mm_add_ps(_mm_cvtepi32_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(k))), half),
            _mm_set1_ps(r.dt)));
    const __m128 px = _mm_add_ps(_mm_set1_ps(r.o[0]), _mm_mul_ps(t, _mm_set1_ps(r.d[0])));
    const __m128 py = _mm_add_ps(_mm_set1_ps(r.o[1]), _mm_mul_ps(t, _mm_set1_ps(r.d[1])));
    const __m128 pz = _mm_add_ps(_mm_set1_ps(r.o[2]), _mm_mul_ps(t, _mm_set1_ps(r.d[2])));
    _mm_storeu_ps(x, px), _mm_storeu_ps(y, py), _mm_storeu_ps(z, pz);
    if (g.cell_mask) {
        // The cells trilinear4 reads (its clamp and truncation), tested in the mask.
        __m128i c[3];
        const __m128 p[3] = {px, py, pz};
        for (int a = 0; a < 3; ++a)
            c[a] = _mm_min_epi32(
                _mm_cvttps_epi32(_mm_max_ps(zero, _mm_min_ps(_mm_set1_ps(g.hi[a]), p[a]))),
                _mm_set1_epi32(g.cell[a]));
        alignas(16) uint32_t o[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(o),
                        _mm_add_epi32(_mm_add_epi32(_mm_mullo_epi32(c[2], _mm_set1_epi32(g.sz)),
                                                    _mm_mullo_epi32(c[1], _mm_set1_epi32(g.sy))),
                                      c[0]));
        uint32_t any = 0;
        for (int l = 0; l < 4; ++l) any |= g.cell_mask[o[l] >> 5] >> (o[l] & 31);
        if (!(any & 1u)) return 0;
    }
    const __m128 val = trilinear4(g, data, px, py, pz);
    _mm_storeu_ps(v, val);
    __m128 u = _mm_add_ps(
        _mm_mul_ps(_mm_sub_ps(val, _mm_set1_ps(g.lut_offset)), _mm_set1_ps(g.lut_scale)), half);
    u = _mm_max_ps(zero, _mm_min_ps(_mm_set1_ps(g.lut_last), u));
    const __m128i ent = _mm_cvttps_epi32(u);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(e), ent);
    const __m128 a = _mm_setr_ps(g.alpha[4 * ptrdiff_t(_mm_extract_epi32(ent, 0))],
                                 g.alpha[4 * ptrdiff_t(_mm_extract_epi32(ent, 1))],
                                 g.alpha[4 * ptrdiff_t(_mm_extract_epi32(ent, 2))],
                                 g.alpha[4 * ptrdiff_t(_mm_extract_epi32(ent, 3))]);
    return _mm_movemask_ps(_mm_cmpgt_ps(a, zero));
}

// feature::gradient's on-the-fly branch (core/gradient.h), for 4 positions: lane by lane.
template <class T>
inline void gradients4(const ShadeGrid& g, const T* data, const float* px, const float* py,
                       const float* pz, float* gx, float* gy, float* gz) {
    central_gradients(g, data, px, py, pz, gx, gy, gz, 4);
}

// The precomputed gradient volume's three trilinear lookups (feature::gradient's first branch),
// 4 positions: float grids with the sampled grid's geometry.
inline void volume_gradients4(const ShadeGrid& g, const float* const grad[3], const float* px,
                              const float* py, const float* pz, float* gx, float* gy, float* gz) {
    const __m128 x = _mm_loadu_ps(px), y = _mm_loadu_ps(py), z = _mm_loadu_ps(pz);
    _mm_storeu_ps(gx, trilinear4(g, grad[0], x, y, z));
    _mm_storeu_ps(gy, trilinear4(g, grad[1], x, y, z));
    _mm_storeu_ps(gz, trilinear4(g, grad[2], x, y, z));
}

#endif  // SSE4.1

#if LACUNA_SIMD_X86

// ---- AVX2: eight lanes -------------------------------------------------------------------
// samples4's eight-lane twin.
template <class T>
LACUNA_AVX2 int samples8(const ShadeGrid& g, const ShadeRay& r, const T* data, const int32_t* k,
                         float* x, float* y, float* z, float* v, int32_t* e) {
    const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f);
    const __m256 t = _mm256_add_ps(
        _mm256_set1_ps(r.t_base),
        _mm256_mul_ps(
            _mm256_add_ps(
                _mm256_cvtepi32_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(k))), half),
            _mm256_set1_ps(r.dt)));
    const __m256 px =
        _mm256_add_ps(_mm256_set1_ps(r.o[0]), _mm256_mul_ps(t, _mm256_set1_ps(r.d[0])));
    const __m256 py =
        _mm256_add_ps(_mm256_set1_ps(r.o[1]), _mm256_mul_ps(t, _mm256_set1_ps(r.d[1])));
    const __m256 pz =
        _mm256_add_ps(_mm256_set1_ps(r.o[2]), _mm256_mul_ps(t, _mm256_set1_ps(r.d[2])));
    _mm256_storeu_ps(x, px), _mm256_storeu_ps(y, py), _mm256_storeu_ps(z, pz);
    if (g.cell_mask) {
        // The cells trilinear8 reads (its clamp and truncation), one gather from the mask.
        const __m256i ci = _mm256_min_epi32(
            _mm256_cvttps_epi32(_mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[0]), px))),
            _mm256_set1_epi32(g.cell[0]));
        const __m256i cj = _mm256_min_epi32(
            _mm256_cvttps_epi32(_mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[1]), py))),
            _mm256_set1_epi32(g.cell[1]));
        const __m256i ck = _mm256_min_epi32(
            _mm256_cvttps_epi32(_mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[2]), pz))),
            _mm256_set1_epi32(g.cell[2]));
        const __m256i off =
            _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(ck, _mm256_set1_epi32(g.sz)),
                                              _mm256_mullo_epi32(cj, _mm256_set1_epi32(g.sy))),
                             ci);
        const __m256i w = _mm256_i32gather_epi32(reinterpret_cast<const int*>(g.cell_mask),
                                                 _mm256_srli_epi32(off, 5), 4);
        const __m256i bit =
            _mm256_and_si256(_mm256_srlv_epi32(w, _mm256_and_si256(off, _mm256_set1_epi32(31))),
                             _mm256_set1_epi32(1));
        if (_mm256_testz_si256(bit, bit)) return 0;
    }
    const __m256 val = trilinear8(g, data, px, py, pz);
    _mm256_storeu_ps(v, val);
    __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(val, _mm256_set1_ps(g.lut_offset)),
                                           _mm256_set1_ps(g.lut_scale)),
                             half);
    u = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.lut_last), u));
    const __m256i ent = _mm256_cvttps_epi32(u);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(e), ent);
    const __m256 a = _mm256_i32gather_ps(g.alpha, _mm256_slli_epi32(ent, 2), 4);
    return _mm256_movemask_ps(_mm256_cmp_ps(a, zero, _CMP_GT_OQ));
}

LACUNA_AVX2 inline __attribute__((always_inline)) __m256i load8(const uint32_t* a) {
    return _mm256_load_si256(reinterpret_cast<const __m256i*>(a));
}
LACUNA_AVX2 inline __attribute__((always_inline)) __m256i load8(const uint16_t* a) {
    return _mm256_cvtepu16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(a)));
}
// a + t * (b - a), trilinear()'s lerp.
LACUNA_AVX2 inline __attribute__((always_inline)) __m256 lerp8(__m256 a, __m256 b, __m256 t) {
    return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}

// Field f (0-based) of each 32-bit lane, holding voxels of type T packed from low to high.
template <class T>
LACUNA_AVX2 inline __attribute__((always_inline)) __m256 voxel_field8(__m256i w, int f) {
    if constexpr (sizeof(T) == 1)
        return _mm256_cvtepi32_ps(
            _mm256_and_si256(_mm256_srli_epi32(w, 8 * f), _mm256_set1_epi32(0xff)));
    else if constexpr (std::is_signed_v<T>)
        return _mm256_cvtepi32_ps(f == 0 ? _mm256_srai_epi32(_mm256_slli_epi32(w, 16), 16)
                                         : _mm256_srai_epi32(w, 16));
    else
        return _mm256_cvtepi32_ps(f == 0 ? _mm256_and_si256(w, _mm256_set1_epi32(0xffff))
                                         : _mm256_srli_epi32(w, 16));
}

// gradients4's eight-lane twin: central_gradient's operations per lane. Integer voxels away
// from the grid's faces read their 32 voxels as packed rows (per corner row of the cell, the four
// voxels i-1..i+2 along x; two voxels past each y and z face of the cell); a batch with a lane
// on a face, and float voxels, go through central_gradient lane by lane.
template <class T>
LACUNA_AVX2 void gradients8(const ShadeGrid& g, const T* data, const float* px, const float* py,
                            const float* pz, float* gx, float* gy, float* gz, int n = 8) {
    if constexpr (sizeof(T) > 2) {
        central_gradients(g, data, px, py, pz, gx, gy, gz, n);
    } else {
        const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f);
        __m256 p[3] = {_mm256_loadu_ps(px), _mm256_loadu_ps(py), _mm256_loadu_ps(pz)}, f[3];
        __m256i c[3], inside = _mm256_set1_epi32(-1);
        for (int a = 0; a < 3; ++a) {
            p[a] = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[a]), p[a]));
            c[a] = _mm256_min_epi32(_mm256_cvttps_epi32(p[a]), _mm256_set1_epi32(g.cell[a]));
            f[a] = _mm256_sub_ps(p[a], _mm256_cvtepi32_ps(c[a]));
            // 1 <= c <= cell - 1: the rows c-1 .. c+2 are inside the grid.
            inside = _mm256_and_si256(inside, _mm256_cmpgt_epi32(c[a], _mm256_setzero_si256()));
            inside =
                _mm256_and_si256(inside, _mm256_cmpgt_epi32(_mm256_set1_epi32(g.cell[a]), c[a]));
        }
        // Lanes n.. are padding: whatever they hold, never the scalar path, and never read.
        inside = _mm256_and_si256(
            inside,
            _mm256_cmpgt_epi32(_mm256_set1_epi32(n), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
        // Lanes on a face: central_gradient at the end. Their rows are read at the first inside
        // lane's cell, whose rows are voxels the data holds: `data` may be a brick's voxels seen
        // as the whole grid (render/ownership.h brick_grid), where only the owned samples' rows
        // are in memory, so no fixed cell such as (1, 1, 1) is safe.
        const int in = _mm256_movemask_ps(_mm256_castsi256_ps(inside));
        const int faces = ~in & 0xff & ((1 << n) - 1);
        if (in == 0) {
            central_gradients(g, data, px, py, pz, gx, gy, gz, n);
            return;
        }
        const __m256i first = _mm256_set1_epi32(__builtin_ctz(unsigned(in)));
        for (int a = 0; a < 3; ++a)
            c[a] = _mm256_blendv_epi8(_mm256_permutevar8x32_epi32(c[a], first), c[a], inside);
        alignas(32) int32_t o[8];
        _mm256_store_si256(
            reinterpret_cast<__m256i*>(o),
            _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(c[2], _mm256_set1_epi32(g.sz)),
                                              _mm256_mullo_epi32(c[1], _mm256_set1_epi32(g.sy))),
                             c[0]));
        // Per lane: rows[r] = v(i-1 .. i+2) at (j + (r & 1), k + (r >> 1)) (16-bit voxels: the
        // low pair i-1, i in rows[r], the high pair i+1, i+2 in rows[4 + r]); the pairs v(i, i+1)
        // at y = j-1 (ym), j+2 (yp) for z = k, k+1 and at z = k-1 (zm), k+2 (zp) for y = j, j+1.
        constexpr bool kByte = sizeof(T) == 1;
        // Pairs: two voxels, 16-bit (byte voxels; widened after loading) or 32-bit.
        using Pair = std::conditional_t<kByte, uint16_t, uint32_t>;
        alignas(32) uint32_t rows[8][8];
        alignas(32) Pair ym[2][8], yp[2][8], zm[2][8], zp[2][8];
        const ptrdiff_t sy = g.sy, sz = g.sz;
        const ptrdiff_t row_at[4] = {0, sy, sz, sy + sz};
        for (int l = 0; l < 8; ++l) {
            const T* q = data + o[l];
            for (int r = 0; r < 4; ++r) {
                __builtin_memcpy(&rows[r][l], q + row_at[r] - 1, 4);
                if constexpr (!kByte) __builtin_memcpy(&rows[4 + r][l], q + row_at[r] + 1, 4);
            }
            __builtin_memcpy(&ym[0][l], q - sy, sizeof(Pair));
            __builtin_memcpy(&ym[1][l], q - sy + sz, sizeof(Pair));
            __builtin_memcpy(&yp[0][l], q + 2 * sy, sizeof(Pair));
            __builtin_memcpy(&yp[1][l], q + 2 * sy + sz, sizeof(Pair));
            __builtin_memcpy(&zm[0][l], q - sz, sizeof(Pair));
            __builtin_memcpy(&zm[1][l], q - sz + sy, sizeof(Pair));
            __builtin_memcpy(&zp[0][l], q + 2 * sz, sizeof(Pair));
            __builtin_memcpy(&zp[1][l], q + 2 * sz + sy, sizeof(Pair));
        }
        // R[r][m] = v(i - 1 + m) of row r, as floats.
        __m256 R[4][4];
        for (int r = 0; r < 4; ++r) {
            if constexpr (kByte) {
                const __m256i w = load8(rows[r]);
                for (int m = 0; m < 4; ++m) R[r][m] = voxel_field8<T>(w, m);
            } else {
                const __m256i lo = load8(rows[r]), hi = load8(rows[4 + r]);
                R[r][0] = voxel_field8<T>(lo, 0), R[r][1] = voxel_field8<T>(lo, 1);
                R[r][2] = voxel_field8<T>(hi, 0), R[r][3] = voxel_field8<T>(hi, 1);
            }
        }
        __m256 d[3][8];
        for (int q = 0; q < 8; ++q) {
            const int a = q & 1, b = q >> 1 & 1, cz = q >> 2;
            d[0][q] = _mm256_sub_ps(R[b + 2 * cz][a + 2], R[b + 2 * cz][a]);
            d[1][q] = b == 0
                          ? _mm256_sub_ps(R[1 + 2 * cz][a + 1], voxel_field8<T>(load8(ym[cz]), a))
                          : _mm256_sub_ps(voxel_field8<T>(load8(yp[cz]), a), R[2 * cz][a + 1]);
            d[2][q] = cz == 0 ? _mm256_sub_ps(R[b + 2][a + 1], voxel_field8<T>(load8(zm[b]), a))
                              : _mm256_sub_ps(voxel_field8<T>(load8(zp[b]), a), R[b][a + 1]);
        }
        float* out[3] = {gx, gy, gz};
        for (int e = 0; e < 3; ++e) {
            const __m256* v = d[e];
            const __m256 c00 = lerp8(v[0], v[1], f[0]), c10 = lerp8(v[2], v[3], f[0]);
            const __m256 c01 = lerp8(v[4], v[5], f[0]), c11 = lerp8(v[6], v[7], f[0]);
            const __m256 c0 = lerp8(c00, c10, f[1]), c1 = lerp8(c01, c11, f[1]);
            _mm256_storeu_ps(out[e], _mm256_mul_ps(_mm256_mul_ps(lerp8(c0, c1, f[2]), half),
                                                   _mm256_set1_ps(g.inv_sp[e])));
        }
        for (int m = faces; m; m &= m - 1) {
            const int l = __builtin_ctz(unsigned(m));
            central_gradients(g, data, px + l, py + l, pz + l, gx + l, gy + l, gz + l, 1);
        }
    }
}

// The precomputed gradient volume's three trilinear lookups (feature::gradient's first branch),
// 8 positions: float grids with the sampled grid's geometry.
LACUNA_AVX2 inline void volume_gradients8(const ShadeGrid& g, const float* const grad[3],
                                          const float* px, const float* py, const float* pz,
                                          float* gx, float* gy, float* gz) {
    const __m256 x = _mm256_loadu_ps(px), y = _mm256_loadu_ps(py), z = _mm256_loadu_ps(pz);
    _mm256_storeu_ps(gx, trilinear8(g, grad[0], x, y, z));
    _mm256_storeu_ps(gy, trilinear8(g, grad[1], x, y, z));
    _mm256_storeu_ps(gz, trilinear8(g, grad[2], x, y, z));
}

// ---- Shading of eight samples (AVX2) -----------------------------------------------------
// shading::normal_from_gradient, then shading::phong_h or shading::pbr_h, for a light whose
// direction l, intensity li and half vector h are the same for all lanes (head and directional
// lights, once per ray), with the view direction v. Lane by lane the operations of the scalar
// functions in their order (std::max(a, c) == max_ps(c, a); sqrt and div are correctly
// rounded); the specular power is shading::spec_pow's: an integer power by its multiplies in
// lanes (spec_pow8), any other by std::pow per lane (no vector pow is bit-exact). A lane whose
// gradient is zero keeps its colour. Lanes n..7 are computed but not pow'ed.
struct ShadeLight {
    float l[3], v[3], h[3];  // unit vectors: to the light, to the eye, half vector
    bool h_ok;               // |l + v| > 0 (phong: no specular otherwise; pbr: h = n per lane)
    float li;                // intensity
};
struct PhongLanes {
    float ambient, diffuse, specular, power;
};
struct PbrLanes {
    float roughness, metallic, ambient;
};

LACUNA_AVX2 inline __attribute__((always_inline)) __m256 dot8(__m256 ax, __m256 ay, __m256 az,
                                                              const float* b) {
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ax, _mm256_set1_ps(b[0])),
                                       _mm256_mul_ps(ay, _mm256_set1_ps(b[1]))),
                         _mm256_mul_ps(az, _mm256_set1_ps(b[2])));
}
// A direction per lane (SoA), or one for every lane (broadcast).
struct Dir8 {
    __m256 x, y, z;
};
LACUNA_AVX2 inline __attribute__((always_inline)) Dir8 dir8(const float* d) {
    return {_mm256_set1_ps(d[0]), _mm256_set1_ps(d[1]), _mm256_set1_ps(d[2])};
}
LACUNA_AVX2 inline __attribute__((always_inline)) __m256 dot8(__m256 ax, __m256 ay, __m256 az,
                                                              const Dir8& b) {
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ax, b.x), _mm256_mul_ps(ay, b.y)),
                         _mm256_mul_ps(az, b.z));
}

// The normals of normal_from_gradient, facing v; the mask of lanes with a non-zero gradient.
LACUNA_AVX2 inline __attribute__((always_inline)) __m256 normals8(const float* gx, const float* gy,
                                                                  const float* gz, const Dir8& v,
                                                                  __m256& nx, __m256& ny,
                                                                  __m256& nz) {
    const __m256 x = _mm256_loadu_ps(gx), y = _mm256_loadu_ps(gy), z = _mm256_loadu_ps(gz);
    const __m256 len2 =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, x), _mm256_mul_ps(y, y)), _mm256_mul_ps(z, z));
    const __m256 ok = _mm256_cmp_ps(len2, _mm256_setzero_ps(), _CMP_GT_OQ);
    const __m256 inv = _mm256_div_ps(_mm256_set1_ps(-1.f), _mm256_sqrt_ps(len2));
    nx = _mm256_mul_ps(x, inv), ny = _mm256_mul_ps(y, inv), nz = _mm256_mul_ps(z, inv);
    // Facing the viewer: n = -n where dot(n, v) < 0 (a sign flip, exact).
    const __m256 back = _mm256_cmp_ps(dot8(nx, ny, nz, v), _mm256_setzero_ps(), _CMP_LT_OQ);
    const __m256 sign = _mm256_and_ps(back, _mm256_set1_ps(-0.f));
    nx = _mm256_xor_ps(nx, sign), ny = _mm256_xor_ps(ny, sign), nz = _mm256_xor_ps(nz, sign);
    return ok;
}

// shading::spec_pow for an integer power, eight lanes: the same multiplies in the same order.
LACUNA_AVX2 inline __m256 spec_pow8(__m256 x, int power) {
    __m256 r = _mm256_set1_ps(1.f), b = x;
    for (int n = power;;) {
        if (n & 1) r = _mm256_mul_ps(r, b);
        n >>= 1;
        if (!n) return r;
        b = _mm256_mul_ps(b, b);
    }
}

// phong_h per lane: light l, view v and half vector h per lane, h_ok the lanes whose |l + v| > 0,
// intensity li for all; r, g, b in place (lanes < n get the specular power).
LACUNA_AVX2 inline void phong8(const PhongLanes& p, float li, const Dir8& l, const Dir8& v,
                               const Dir8& h, __m256 h_ok, const float* gx, const float* gy,
                               const float* gz, float* r, float* g, float* b, int n) {
    const __m256 zero = _mm256_setzero_ps();
    __m256 nx, ny, nz;
    const __m256 ok = normals8(gx, gy, gz, v, nx, ny, nz);
    const __m256 ndl = _mm256_max_ps(zero, dot8(nx, ny, nz, l));
    alignas(32) float spec[8] = {};
    if (_mm256_movemask_ps(h_ok)) {
        const __m256 vndh = _mm256_max_ps(zero, dot8(nx, ny, nz, h));
        const __m256 vlit =
            _mm256_and_ps(_mm256_and_ps(ok, h_ok), _mm256_cmp_ps(ndl, zero, _CMP_GT_OQ));
        if (integer_power(p.power)) {
            _mm256_store_ps(spec, _mm256_and_ps(vlit, spec_pow8(vndh, int(p.power))));
        } else {
            alignas(32) float ndh[8], lit[8];
            _mm256_store_ps(ndh, vndh);
            _mm256_store_ps(lit, vlit);
            for (int j = 0; j < n; ++j)
                if (lit[j] != 0.f) spec[j] = std::pow(ndh[j], p.power);
        }
    }
    const __m256 vli = _mm256_set1_ps(li);
    const __m256 k =
        _mm256_add_ps(_mm256_set1_ps(p.ambient),
                      _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(p.diffuse), vli), ndl));
    const __m256 sp =
        _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(p.specular), vli), _mm256_load_ps(spec));
    float* c[3] = {r, g, b};
    for (int i = 0; i < 3; ++i) {
        const __m256 in = _mm256_loadu_ps(c[i]);
        _mm256_storeu_ps(c[i], _mm256_blendv_ps(in, _mm256_add_ps(_mm256_mul_ps(in, k), sp), ok));
    }
}

// The same for one light and view for all lanes (one ray's samples).
LACUNA_AVX2 inline void phong8(const PhongLanes& p, const ShadeLight& L, const float* gx,
                               const float* gy, const float* gz, float* r, float* g, float* b,
                               int n) {
    const __m256 h_ok = L.h_ok ? _mm256_castsi256_ps(_mm256_set1_epi32(-1)) : _mm256_setzero_ps();
    phong8(p, L.li, dir8(L.l), dir8(L.v), dir8(L.h), h_ok, gx, gy, gz, r, g, b, n);
}

// pbr_h for a fixed half vector (callers fall back to the scalar pbr() when !L.h_ok).
LACUNA_AVX2 inline void pbr8(const PbrLanes& p, const ShadeLight& L, const float* gx,
                             const float* gy, const float* gz, float* r, float* g, float* b) {
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.f);
    __m256 nx, ny, nz;
    const __m256 ok = normals8(gx, gy, gz, dir8(L.v), nx, ny, nz);
    // Per-ray scalars, as pbr_h and its helpers compute them.
    const float rough = std::clamp(p.roughness, 0.02f, 1.f);
    const float alpha = rough * rough;
    const float ldh = std::max(L.l[0] * L.h[0] + L.l[1] * L.h[1] + L.l[2] * L.h[2], 0.f);
    const float fd90 = 0.5f + 2.f * ldh * ldh * rough;
    const float a2 = alpha * alpha;
    const float m = std::clamp(p.metallic, 0.f, 1.f);
    const __m256 ndl = _mm256_max_ps(zero, dot8(nx, ny, nz, L.l));
    const __m256 ndv = _mm256_max_ps(_mm256_set1_ps(1e-4f), dot8(nx, ny, nz, L.v));
    const __m256 ndh = _mm256_max_ps(zero, dot8(nx, ny, nz, L.h));
    // disney_diffuse
    const __m256 fd1 = _mm256_set1_ps(fd90 - 1.f);
    const __m256 lv = _mm256_sub_ps(one, ndl), vv = _mm256_sub_ps(one, ndv);
    __m256 fl = _mm256_mul_ps(fd1, lv), fv = _mm256_mul_ps(fd1, vv);
    for (int i = 0; i < 4; ++i) fl = _mm256_mul_ps(fl, lv), fv = _mm256_mul_ps(fv, vv);
    fl = _mm256_add_ps(one, fl), fv = _mm256_add_ps(one, fv);
    const __m256 vli = _mm256_set1_ps(L.li);
    const __m256 diffuse = _mm256_mul_ps(_mm256_mul_ps(vli, _mm256_mul_ps(fl, fv)), ndl);
    // ggx_d
    const __m256 d =
        _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(ndh, ndh), _mm256_set1_ps(a2 - 1.f)), one);
    const __m256 kpi = _mm256_set1_ps(3.14159265358979f);
    const __m256 D = _mm256_div_ps(
        _mm256_set1_ps(a2),
        _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(kpi, d), d), _mm256_set1_ps(1e-7f)));
    // smith_joint_ggx_v
    const __m256 one_a2 = _mm256_set1_ps(1.f - a2), va2 = _mm256_set1_ps(a2);
    const __m256 gl = _mm256_mul_ps(
        ndv, _mm256_sqrt_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(ndl, ndl), one_a2), va2)));
    const __m256 gv = _mm256_mul_ps(
        ndl, _mm256_sqrt_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(ndv, ndv), one_a2), va2)));
    const __m256 V = _mm256_div_ps(_mm256_set1_ps(0.5f),
                                   _mm256_add_ps(_mm256_add_ps(gl, gv), _mm256_set1_ps(1e-5f)));
    const __m256 spec_common =
        _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(vli, kpi), D), V), ndl);
    // Per channel: f0, kd, schlick.
    const __m256 vm = _mm256_set1_ps(m), one_m = _mm256_set1_ps(1.f - m);
    const __m256 f0c = _mm256_set1_ps(0.04f * (1.f - m));
    const __m256 sm = _mm256_set1_ps(1.f - ldh);
    const __m256 amb_diff = _mm256_add_ps(_mm256_set1_ps(p.ambient), diffuse);
    float* c[3] = {r, g, b};
    for (int i = 0; i < 3; ++i) {
        const __m256 in = _mm256_loadu_ps(c[i]);
        const __m256 f0 = _mm256_add_ps(f0c, _mm256_mul_ps(in, vm));
        const __m256 kd = _mm256_mul_ps(in, one_m);
        __m256 fs = _mm256_sub_ps(one, f0);
        for (int q = 0; q < 5; ++q) fs = _mm256_mul_ps(fs, sm);
        const __m256 F = _mm256_add_ps(f0, fs);
        const __m256 out =
            _mm256_add_ps(_mm256_mul_ps(kd, amb_diff), _mm256_mul_ps(spec_common, F));
        _mm256_storeu_ps(c[i], _mm256_blendv_ps(in, out, ok));
    }
}

// ---- AVX-512: the lattice batch in sixteen lanes -----------------------------------------
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// samples8's sixteen-lane twin: ShadedStream's whole lattice batch in one call on AVX-512 CPUs
// (march_lanes16's trilinear16; the same operations per lane).
template <class T>
LACUNA_AVX512 int samples16(const ShadeGrid& g, const ShadeRay& r, const T* data, const int32_t* k,
                            float* x, float* y, float* z, float* v, int32_t* e) {
    const __m512 zero = _mm512_setzero_ps(), half = _mm512_set1_ps(0.5f);
    const __m512 t =
        _mm512_add_ps(_mm512_set1_ps(r.t_base),
                      _mm512_mul_ps(_mm512_add_ps(_mm512_cvtepi32_ps(_mm512_loadu_si512(k)), half),
                                    _mm512_set1_ps(r.dt)));
    const __m512 px =
        _mm512_add_ps(_mm512_set1_ps(r.o[0]), _mm512_mul_ps(t, _mm512_set1_ps(r.d[0])));
    const __m512 py =
        _mm512_add_ps(_mm512_set1_ps(r.o[1]), _mm512_mul_ps(t, _mm512_set1_ps(r.d[1])));
    const __m512 pz =
        _mm512_add_ps(_mm512_set1_ps(r.o[2]), _mm512_mul_ps(t, _mm512_set1_ps(r.d[2])));
    _mm512_storeu_ps(x, px), _mm512_storeu_ps(y, py), _mm512_storeu_ps(z, pz);
    const __m512 cx = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[0]), px));
    const __m512 cy = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[1]), py));
    const __m512 cz = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[2]), pz));
    if (g.cell_mask) {
        // The cells trilinear16 reads, one gather from the mask.
        const __m512i ci = _mm512_min_epi32(_mm512_cvttps_epi32(cx), _mm512_set1_epi32(g.cell[0]));
        const __m512i cj = _mm512_min_epi32(_mm512_cvttps_epi32(cy), _mm512_set1_epi32(g.cell[1]));
        const __m512i ck = _mm512_min_epi32(_mm512_cvttps_epi32(cz), _mm512_set1_epi32(g.cell[2]));
        const __m512i off =
            _mm512_add_epi32(_mm512_add_epi32(_mm512_mullo_epi32(ck, _mm512_set1_epi32(g.sz)),
                                              _mm512_mullo_epi32(cj, _mm512_set1_epi32(g.sy))),
                             ci);
        const __m512i w = _mm512_i32gather_epi32(_mm512_srli_epi32(off, 5), g.cell_mask, 4);
        const __m512i bit =
            _mm512_and_si512(_mm512_srlv_epi32(w, _mm512_and_si512(off, _mm512_set1_epi32(31))),
                             _mm512_set1_epi32(1));
        if (!_mm512_test_epi32_mask(bit, bit)) return 0;
    }
    const __m512 val = trilinear16(g, data, cx, cy, cz, __mmask16(0xffff));
    _mm512_storeu_ps(v, val);
    __m512 u = _mm512_add_ps(_mm512_mul_ps(_mm512_sub_ps(val, _mm512_set1_ps(g.lut_offset)),
                                           _mm512_set1_ps(g.lut_scale)),
                             half);
    u = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.lut_last), u));
    const __m512i ent = _mm512_cvttps_epi32(u);
    _mm512_storeu_si512(e, ent);
    const __m512 a = _mm512_i32gather_ps(_mm512_slli_epi32(ent, 2), g.alpha, 4);
    return int(_mm512_cmp_ps_mask(a, zero, _CMP_GT_OQ));
}
#pragma GCC diagnostic pop

// ---- Shading across rays (AVX2): the shaded lane kernel ---------------------------------
// march_shaded_lanes8 is march_lanes8 (core/simd_lanes.h) for Phong-shaded composite rays with
// a head or directional light, one TF, no clipping, trilinear samples; the render side
// (src/render/feature_render.cpp) takes it with leaping on a refined grid, where it pays (alone,
// walking the grid, it measured no faster than ShadedStream). ShadedStream
// (src/render/feature_kernel.h) shades one ray at a time: a ray keeps ~25 samples, of which ~4 are
// visible, so its lattice and its gradient batches run mostly empty lanes. Here lanes are rays, as
// in the unshaded kernel, and the visible samples of all lanes go to one queue, shaded eight at a
// time whoever they belong to.
//
// Bit-exactness. Per lane, the lattice positions, values and LUT entries are march_lanes8's
// (ShadedStream's, operation for operation), and the opacity chain w = 1 - A, A += w * a runs on
// every sample: a sample with a = 0 adds exactly +0 and keeps w, as ShadedStream, which skips it.
// ShadedStream pushes the samples whose TF opacity is > 0; here those whose step-corrected
// opacity a is > 0: a sample with TF opacity > 0 and a = 0 would add w * rgb * 0 = +0 to
// colours that are >= 0, so the bits agree. A queued sample keeps its ray's w and a, its ray
// (the record) and its position; shading is phong8 with that ray's l, v and h (the ones
// ShadedStream computes once per ray), and its colour goes into its ray's record by
// r += w * rgb * a in queue order, which is the ray's sample order. So every pixel has the bits
// of ShadedStream's, hence of composite_ray's.
inline constexpr int kShadeRecords = 64;  // rays in flight: the lanes (32) plus the deferred pixels
// Per ray: colour accumulators, the ray's view v, half vector h and |l + v| > 0 (its light l is
// the frame's: ShadeFrame), and how many of its samples wait in the queue.
struct ShadeRecords {
    alignas(32) float r[kShadeRecords], g[kShadeRecords], b[kShadeRecords];
    alignas(32) float v[3][kShadeRecords], h[3][kShadeRecords];
    alignas(32) int32_t h_ok[kShadeRecords];
    alignas(32) int32_t pending[kShadeRecords];
};
// The visible samples waiting for shading, in the order they were composited. At most 7 wait
// when a lane set pushes (the kernels shade every full eight at once), so 32 hold 7 + 16 plus a
// batch's padding.
inline constexpr int kShadeQueue = 32;
struct ShadeQueue {
    alignas(64) float x[kShadeQueue], y[kShadeQueue], z[kShadeQueue], w[kShadeQueue],
        a[kShadeQueue];
    alignas(64) int32_t e[kShadeQueue], rec[kShadeQueue];
    int n = 0;
};
// What shading needs besides the samples: the grid, the straight-colour LUT (RGBA floats), the
// gradient volume (null: central differences), Phong and the light's intensity.
struct ShadeFrame {
    ShadeGrid g;
    const float* raw;
    const float* const* grad;
    PhongLanes phong;
    float li;
    // The light's direction l of every record: a directional light's (`dir`), or, for a head
    // light (head), the record's own view v, so neither is gathered.
    bool head = true;
    float dir[3] = {0.f, 0.f, 0.f};
};

// The per-ray half vectors of eight rays of a RayBatch8 (the shaded lanes' records), with
// shading::half_vector's operations lane by lane: v = -w, l = `ldir` (a head light: v),
// h = (l + v) / |l + v| and ok = -1 where |l + v| > 0, else h = (0, 0, 1) and ok = 0.
LACUNA_AVX2 inline void half_vectors8(const RayBatch8& rb, bool head, const float ldir[3],
                                      float (*h)[8], int32_t* ok) {
    const __m256 sign = _mm256_set1_ps(-0.f);
    const __m256 v[3] = {_mm256_xor_ps(_mm256_load_ps(rb.wx), sign),
                         _mm256_xor_ps(_mm256_load_ps(rb.wy), sign),
                         _mm256_xor_ps(_mm256_load_ps(rb.wz), sign)};
    __m256 s[3];
    for (int a = 0; a < 3; ++a) s[a] = _mm256_add_ps(head ? v[a] : _mm256_set1_ps(ldir[a]), v[a]);
    const __m256 len = _mm256_sqrt_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(s[0], s[0]), _mm256_mul_ps(s[1], s[1])),
                      _mm256_mul_ps(s[2], s[2])));
    const __m256 good = _mm256_cmp_ps(len, _mm256_setzero_ps(), _CMP_GT_OQ);
    const float unit[3] = {0.f, 0.f, 1.f};
    for (int a = 0; a < 3; ++a)
        _mm256_store_ps(h[a],
                        _mm256_blendv_ps(_mm256_set1_ps(unit[a]), _mm256_div_ps(s[a], len), good));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(ok), _mm256_castps_si256(good));
}

// The directions d[.][rec[l]] of eight records.
LACUNA_AVX2 inline Dir8 gather_dir8(const float (*d)[kShadeRecords], __m256i rec) {
    return {_mm256_i32gather_ps(d[0], rec, 4), _mm256_i32gather_ps(d[1], rec, 4),
            _mm256_i32gather_ps(d[2], rec, 4)};
}

// Shades the n <= 8 queued samples from i0 on into their records (lanes past n are padding,
// computed and never used).
template <class T>
LACUNA_AVX2 void shade_run8(const ShadeFrame& f, const T* data, ShadeQueue& q, int i0, int n,
                            ShadeRecords& R) {
    float *qx = q.x + i0, *qy = q.y + i0, *qz = q.z + i0;
    int32_t* qrec = q.rec + i0;
    for (int j = n; j < 8; ++j)
        qx[j] = qx[n - 1], qy[j] = qy[n - 1], qz[j] = qz[n - 1], qrec[j] = qrec[n - 1];
    alignas(32) float gx[8] = {}, gy[8] = {}, gz[8] = {};  // (padding lanes may stay 0)
    if (f.grad)
        volume_gradients8(f.g, f.grad, qx, qy, qz, gx, gy, gz);
    else
        gradients8(f.g, data, qx, qy, qz, gx, gy, gz, n);
    alignas(32) float r[8], g[8], b[8];
    for (int j = 0; j < 8; ++j) {
        const float* c = f.raw + 4 * ptrdiff_t(q.e[i0 + std::min(j, n - 1)]);
        r[j] = c[0], g[j] = c[1], b[j] = c[2];
    }
    const __m256i rec = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(qrec));
    const __m256 h_ok =
        _mm256_castsi256_ps(_mm256_i32gather_epi32(reinterpret_cast<const int*>(R.h_ok), rec, 4));
    const Dir8 v = gather_dir8(R.v, rec);
    const Dir8 l =
        f.head ? v
               : Dir8{_mm256_set1_ps(f.dir[0]), _mm256_set1_ps(f.dir[1]), _mm256_set1_ps(f.dir[2])};
    phong8(f.phong, f.li, l, v, gather_dir8(R.h, rec), h_ok, gx, gy, gz, r, g, b, n);
    for (int j = 0; j < n; ++j) {
        const int i = qrec[j];
        const float w = q.w[i0 + j], a = q.a[i0 + j];
        R.r[i] += w * r[j] * a;
        R.g[i] += w * g[j] * a;
        R.b[i] += w * b[j] * a;
        --R.pending[i];
    }
}
// Drops the first m queued samples (shaded) from the queue.
inline void queue_drop(ShadeQueue& q, int m) {
    q.n -= m;
    for (int j = 0; j < q.n; ++j) {
        q.x[j] = q.x[m + j], q.y[j] = q.y[m + j], q.z[j] = q.z[m + j];
        q.w[j] = q.w[m + j], q.a[j] = q.a[m + j], q.e[j] = q.e[m + j], q.rec[j] = q.rec[m + j];
    }
}
// Shades the first min(q.n, 8) queued samples into their records and drops them from the queue.
template <class T>
LACUNA_AVX2 void shade_queue8(const ShadeFrame& f, const T* data, ShadeQueue& q, ShadeRecords& R) {
    const int n = std::min(q.n, 8);
    if (n == 0) return;
    shade_run8(f, data, q, 0, n, R);
    queue_drop(q, n);
}
// Shades every full eight of the queue, front to back; fewer than eight stay.
template <class T>
LACUNA_AVX2 void shade_full8(const ShadeFrame& f, const T* data, ShadeQueue& q, ShadeRecords& R) {
    int i0 = 0;
    for (; q.n - i0 >= 8; i0 += 8) shade_run8(f, data, q, i0, 8, R);
    queue_drop(q, i0);
}

// march_lanes8's contract (refill, the lanes' state in `s`), with `lut` the step-corrected LUT
// (RGBA floats, entry g.zero_entry all zero) for the opacity chain, `rec[l]` lane l's record;
// s.r, s.g, s.b are not used (colours live in the records). Samples go to `q` and are shaded
// whenever eight wait; the caller shades what is left after the kernel returns.
template <class T, class Refill, bool kLeap = false>
LACUNA_AVX2 void march_shaded_lanes8(Lanes& s, const LaneGrid& g, const T* data, const float* lut,
                                     const ShadeFrame& f, ShadeQueue& q, ShadeRecords& R,
                                     const int32_t* rec, Refill& refill) {
    const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f), one = _mm256_set1_ps(1.f);
    const __m256 vdt = _mm256_set1_ps(g.dt), vert = _mm256_set1_ps(g.ert);
    const __m256 voff = _mm256_set1_ps(g.lut_offset), vscale = _mm256_set1_ps(g.lut_scale),
                 vlast = _mm256_set1_ps(g.lut_last);
    const __m256i vzero_entry = _mm256_set1_epi32(g.zero_entry);
    __m256 ox, oy, oz, dx, dy, dz, tb, aa;
    __m256i kend, active, k, n, kcheck = _mm256_setzero_si256();
#define LACUNA_LOAD_LANES                                                            \
    ox = _mm256_load_ps(s.ox), oy = _mm256_load_ps(s.oy), oz = _mm256_load_ps(s.oz); \
    dx = _mm256_load_ps(s.dx), dy = _mm256_load_ps(s.dy), dz = _mm256_load_ps(s.dz); \
    tb = _mm256_load_ps(s.t_base);                                                   \
    kend = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.kend));              \
    active = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.active));          \
    k = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.k));                    \
    n = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.n));                    \
    aa = _mm256_load_ps(s.a);                                                        \
    active_mask = _mm256_movemask_ps(_mm256_castsi256_ps(active));                   \
    if constexpr (kLeap) {                                                           \
        leap_inverse8(dx, dy, dz, g.leap_octant, linv);                              \
        kcheck = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.kcheck));      \
    }
    LeapInverse linv;  // leaping: 1 / dir per lane
    const __m256 inv_dt = _mm256_set1_ps(1.f / g.dt);
    int active_mask, waiting = 0;
    LACUNA_LOAD_LANES
    int need;
    for (;;) {
        const __m256i valid = _mm256_cmpgt_epi32(kend, k);
        const __m256 t =
            _mm256_add_ps(tb, _mm256_mul_ps(_mm256_add_ps(_mm256_cvtepi32_ps(k), half), vdt));
        const __m256 x = _mm256_add_ps(ox, _mm256_mul_ps(t, dx));
        const __m256 y = _mm256_add_ps(oy, _mm256_mul_ps(t, dy));
        const __m256 z = _mm256_add_ps(oz, _mm256_mul_ps(t, dz));
        const __m256 v = trilinear8(g, data, x, y, z);
        // The leap test only when a valid lane has left its box of fully visible bricks
        // (kcheck, as in march_lanes8).
        __m256i taken = valid, adv = _mm256_set1_epi32(1);
        if constexpr (kLeap) {
            const __m256i test = _mm256_andnot_si256(_mm256_cmpgt_epi32(kcheck, k), valid);
            if (!_mm256_testz_si256(test, test)) {
                __m256i inside;
                leap8(g, x, y, z, valid, inv_dt, linv, taken, adv, &inside);
                kcheck = _mm256_blendv_epi8(kcheck, _mm256_add_epi32(k, inside),
                                            _mm256_cmpgt_epi32(inside, _mm256_setzero_si256()));
            }
        }
        prefetch_ahead8(g, data, t, ox, oy, oz, dx, dy, dz, taken);  // (simd_lanes.h)
        __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(v, voff), vscale), half);
        u = _mm256_max_ps(zero, _mm256_min_ps(vlast, u));
        const __m256i entry = _mm256_blendv_epi8(vzero_entry, _mm256_cvttps_epi32(u), taken);
        const __m256 ca = _mm256_i32gather_ps(lut + 3, _mm256_slli_epi32(entry, 2), 4);
        const __m256 w = _mm256_sub_ps(one, aa);
        aa = _mm256_add_ps(aa, _mm256_mul_ps(w, ca));
        // The visible samples (a > 0; invalid lanes read the zero entry) join the queue.
        if (int vis = _mm256_movemask_ps(_mm256_cmp_ps(ca, zero, _CMP_GT_OQ))) {
            alignas(32) float px[8], py[8], pz[8], pw[8], pa[8];
            alignas(32) int32_t pe[8];
            _mm256_store_ps(px, x), _mm256_store_ps(py, y), _mm256_store_ps(pz, z);
            _mm256_store_ps(pw, w), _mm256_store_ps(pa, ca);
            _mm256_store_si256(reinterpret_cast<__m256i*>(pe), entry);
            do {
                const int l = __builtin_ctz(unsigned(vis));
                vis &= vis - 1;
                const int j = q.n++;
                q.x[j] = px[l], q.y[j] = py[l], q.z[j] = pz[l];
                q.w[j] = pw[l], q.a[j] = pa[l], q.e[j] = pe[l], q.rec[j] = rec[l];
                ++R.pending[rec[l]];
            } while (vis);
            if (q.n >= 8) shade_queue8(f, data, q, R);
        }
        n = _mm256_sub_epi32(n, taken);
        k = advance8<kLeap>(k, kend, valid, adv);
        const __m256i over = _mm256_or_si256(
            _mm256_cmpeq_epi32(k, kend), _mm256_castps_si256(_mm256_cmp_ps(aa, vert, _CMP_GE_OS)));
        kend = _mm256_blendv_epi8(kend, k, over);
        need = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_and_si256(over, active)));
        waiting |= need;
        if (__builtin_popcount(unsigned(waiting)) >= 2 || waiting == active_mask) {
            need = waiting;
            waiting = 0;
            _mm256_store_si256(reinterpret_cast<__m256i*>(s.kend), kend);
            _mm256_store_si256(reinterpret_cast<__m256i*>(s.k), k);
            _mm256_store_si256(reinterpret_cast<__m256i*>(s.n), n);
            _mm256_store_ps(s.a, aa);
            if constexpr (kLeap) _mm256_store_si256(reinterpret_cast<__m256i*>(s.kcheck), kcheck);
            if (!refill(need)) return;
            LACUNA_LOAD_LANES
        }
    }
#undef LACUNA_LOAD_LANES
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// ---- Shading across rays (AVX-512): sixteen lanes
// ------------------------------------------------ march_shaded_lanes8 with march_lanes16's lane
// set (sixteen rays, trilinear16, leap16): per lane the same operations, so the same bits. The
// visible samples of a lane set enter the queue by compression in lane order (a ray's samples stay
// in its sample order: one per lane and iteration), and every full eight is shaded by shade_run8.
// Two groups of sixteen lanes are in flight, as in march_lanes16 (simd_lanes.h, Group16: two
// independent leap chains); a ray's samples still enter the queue in its own order, one per step of
// its group.
template <class T>
struct ShadedGroup16 {
    __m512 ox, oy, oz, dx, dy, dz, tb, aa;
    __m512i kend, k, n, vrec, kcheck;
    __mmask16 active;

    LACUNA_AVX512 inline __attribute__((always_inline)) void load(const Lanes& s, int b,
                                                                  const LaneGrid& g,
                                                                  const int32_t* rec,
                                                                  LeapInverse& li) {
        ox = _mm512_load_ps(s.ox + b), oy = _mm512_load_ps(s.oy + b), oz = _mm512_load_ps(s.oz + b);
        dx = _mm512_load_ps(s.dx + b), dy = _mm512_load_ps(s.dy + b), dz = _mm512_load_ps(s.dz + b);
        tb = _mm512_load_ps(s.t_base + b);
        kend = _mm512_load_si512(s.kend + b);
        active = _mm512_cmpneq_epi32_mask(_mm512_load_si512(s.active + b), _mm512_setzero_si512());
        k = _mm512_load_si512(s.k + b);
        n = _mm512_load_si512(s.n + b);
        kcheck = _mm512_load_si512(s.kcheck + b);
        aa = _mm512_load_ps(s.a + b);
        vrec = _mm512_loadu_si512(rec + b);  // the lanes' records (a refill may change them)
        leap_inverse16(dx, dy, dz, g.leap_octant, li, b);
    }
    LACUNA_AVX512 inline __attribute__((always_inline)) void store(Lanes& s, int b) const {
        _mm512_store_si512(s.kend + b, kend);
        _mm512_store_si512(s.k + b, k);
        _mm512_store_si512(s.n + b, n);
        _mm512_store_si512(s.kcheck + b, kcheck);
        _mm512_store_ps(s.a + b, aa);
    }
    // One sample (or leap) per valid lane, its visible samples queued; returns the active lanes
    // whose run is over.
    LACUNA_AVX512 inline __attribute__((always_inline)) __mmask16 step(
        const LaneGrid& g, const T* data, const float* lut, const ShadeFrame& f, ShadeQueue& q,
        ShadeRecords& R, const int32_t* rec, const LeapInverse& li, int b) {
        const __m512 zero = _mm512_setzero_ps(), half = _mm512_set1_ps(0.5f),
                     one = _mm512_set1_ps(1.f);
        const __m512i ione = _mm512_set1_epi32(1);
        const __mmask16 valid = _mm512_cmplt_epi32_mask(k, kend);
        const __m512 t = _mm512_add_ps(
            tb, _mm512_mul_ps(_mm512_add_ps(_mm512_cvtepi32_ps(k), half), _mm512_set1_ps(g.dt)));
        const __m512 px = _mm512_add_ps(ox, _mm512_mul_ps(t, dx));
        const __m512 py = _mm512_add_ps(oy, _mm512_mul_ps(t, dy));
        const __m512 pz = _mm512_add_ps(oz, _mm512_mul_ps(t, dz));
        const __m512 x = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[0]), px));
        const __m512 y = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[1]), py));
        const __m512 z = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[2]), pz));
        // The leap test only when a valid lane has left its box of fully visible bricks
        // (simd_lanes.h leap16_outside), and the corner loads as in march_lanes16.
        __mmask16 taken = valid;
        __m512i adv = ione;
        leap16_outside(g, x, y, z, valid, li, b, k, kcheck, taken, adv);
        prefetch_ahead16(g, data, t, ox, oy, oz, dx, dy, dz, taken);  // (simd_lanes.h)
        const __m512 v = leap_trilinear16(g, data, x, y, z, taken, active);
        __m512 u = _mm512_add_ps(_mm512_mul_ps(_mm512_sub_ps(v, _mm512_set1_ps(g.lut_offset)),
                                               _mm512_set1_ps(g.lut_scale)),
                                 half);
        u = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.lut_last), u));
        const __m512i entry =
            _mm512_mask_blend_epi32(taken, _mm512_set1_epi32(g.zero_entry), _mm512_cvttps_epi32(u));
        const __m512 ca = _mm512_i32gather_ps(_mm512_slli_epi32(entry, 2), lut + 3, 4);
        const __m512 w = _mm512_sub_ps(one, aa);
        aa = _mm512_add_ps(aa, _mm512_mul_ps(w, ca));
        // The visible samples (a > 0; invalid lanes read the zero entry) join the queue, with
        // the positions before clamping (march_shaded_lanes8's).
        if (const __mmask16 vis = _mm512_cmp_ps_mask(ca, zero, _CMP_GT_OQ)) {
            const int j = q.n;
            _mm512_storeu_ps(q.x + j, _mm512_maskz_compress_ps(vis, px));
            _mm512_storeu_ps(q.y + j, _mm512_maskz_compress_ps(vis, py));
            _mm512_storeu_ps(q.z + j, _mm512_maskz_compress_ps(vis, pz));
            _mm512_storeu_ps(q.w + j, _mm512_maskz_compress_ps(vis, w));
            _mm512_storeu_ps(q.a + j, _mm512_maskz_compress_ps(vis, ca));
            _mm512_storeu_si512(q.e + j, _mm512_maskz_compress_epi32(vis, entry));
            _mm512_storeu_si512(q.rec + j, _mm512_maskz_compress_epi32(vis, vrec));
            q.n = j + __builtin_popcount(unsigned(vis));
            for (unsigned m = vis; m; m &= m - 1) ++R.pending[rec[b + __builtin_ctz(m)]];
            if (q.n >= 8) shade_full8(f, data, q, R);
        }
        n = _mm512_mask_add_epi32(n, taken, n, ione);
        k = _mm512_min_epi32(_mm512_mask_add_epi32(k, valid, k, adv), kend);
        const __mmask16 over = _mm512_cmpeq_epi32_mask(k, kend) |
                               _mm512_cmp_ps_mask(aa, _mm512_set1_ps(g.ert), _CMP_GE_OS);
        kend = _mm512_mask_mov_epi32(kend, over, k);
        return over & active;
    }
};

template <class T, class Refill, int kGroups = 2>
LACUNA_AVX512 void march_shaded_lanes16(Lanes& s, const LaneGrid& g, const T* data,
                                        const float* lut, const ShadeFrame& f, ShadeQueue& q,
                                        ShadeRecords& R, const int32_t* rec, Refill& refill) {
    static_assert(kGroups >= 1 && 16 * kGroups <= kMaxLanes);
    ShadedGroup16<T> G[kGroups];
    LeapInverse linv;
    uint32_t active = 0, waiting = 0;
    for (int i = 0; i < kGroups; ++i) {
        G[i].load(s, 16 * i, g, rec, linv);
        active |= uint32_t(G[i].active) << (16 * i);
    }
    for (;;) {
#pragma GCC unroll 2
        for (int i = 0; i < kGroups; ++i)
            waiting |= uint32_t(G[i].step(g, data, lut, f, q, R, rec, linv, 16 * i)) << (16 * i);
        if (__builtin_popcount(waiting) >= 4 * kGroups || waiting == active) {
            for (int i = 0; i < kGroups; ++i) G[i].store(s, 16 * i);
            if (!refill(waiting)) return;
            waiting = 0, active = 0;
            for (int i = 0; i < kGroups; ++i) {
                G[i].load(s, 16 * i, g, rec, linv);
                active |= uint32_t(G[i].active) << (16 * i);
            }
        }
    }
}
#pragma GCC diagnostic pop

#endif  // LACUNA_SIMD_X86

}  // namespace lacuna::simd
