// The ray marcher's lane kernels: W rays in lockstep, one per SIMD lane, for SSE4.1 (W = 4, the
// x86-64-v2 baseline), AVX2 (W = 8) and AVX-512 (W = 16), chosen at run time (active_isa()). The
// only file with intrinsics (STYLE.md: SIMD in one place).
//
// Why lanes are rays. Front-to-back compositing is a serial chain per ray (w = 1 - a, then
// a += w * c: a subtract, a multiply and an add of latency, ~10 cycles a sample), so one ray at a
// time cannot go faster than that however wide its sampling is. W rays advance W chains in one
// set of instructions, and wider registers make every other step (positions, corner loads,
// lerps, LUT fetches) W samples per instruction.
//
// Bit-exactness. Each lane performs exactly the scalar operations of its own ray (trilinear(),
// ValueToLut, the compositing of kernel::RayStream) in its own sample order: mul and add stay
// separate (no FMA: -ffp-contract=off, no fma intrinsics), min/max return their second operand
// on ties and NaN in every width, int conversions truncate. So every path gives the same bits.
//
// One portable binary. The AVX2 and AVX-512 kernels carry __attribute__((target(...))) rather
// than per-file -m flags, so nothing else is compiled for those ISAs (no inline function of a
// shared header can be emitted with AVX2 code and picked by the linker for everyone); they run
// only after a CPUID check. No lambdas inside them (a lambda does not inherit the target).
//
// Leaping (kLeap, the refined grid; the scheduler then hands each lane its whole ray as one run).
// Each lane looks up the leap map at its sample's clamped position q (the fine brick b of q's
// trilinear cell c, 4^3 cells) in the map of its ray's octant (which of dir's components are
// negative: one map per octant, BrickGrid::leap_map): distance d = 0, the sample is composited as
// always; d >= 1, every fine brick of the box reaching d - 1 bricks from b toward the octant is
// empty, [4 b_a, 4(b_a + d)) cells on an axis with dir_a >= 0, [4(b_a - d + 1), 4 b_a + 4) with
// dir_a < 0, so the ray may skip every sample before it leaves that box. (A box behind the ray
// is never entered: per axis the clamped position only moves toward the octant, so only the
// bricks ahead need be empty, and a ray leaving an occupied region leaps at once across the
// empty space in front of it, which a symmetric distance, held to 1 by the bricks just behind,
// would not let it.) Along axis a the ray leaves the box through the face ahead of it,
//     face_a = 4 b_a + (dir_a < 0 ? 4 - 4d : 4d),   T_a = (face_a - q_a) / dir_a,
// and the lane skips s = floor(min_a T_a / dt) + 1 samples (T = min_a T_a >= 0, since
// q_a lies in [4 b_a, 4 b_a + 4]): samples k .. k + s - 1 have (s - 1) dt <= T. The next sample
// taken is the lattice's k + s. At d = 0 the entry's high byte says which of the brick's eight
// sub-bricks of 2^3 cells (with their own one-cell apron) may read a visible entry; in a clear
// one the lane leaves that sub-brick the same way, with edge 2 and D = 1:
//     face_a = (c_a & -2) + (dir_a < 0 ? 0 : 2).
// A high byte of 0xff (every sub-brick set, "fully visible") turns the low byte into the inside
// distance e >= 1: nothing is skipped, and the same face formula with D = e gives kcheck, the
// first sample past the box of fully visible bricks, before which the group needs no test
// (Group16; only a skip needs the test, so kcheck cannot change a bit of the image).
// Why this is exact. (1) Clamping only helps: where the clamped trajectory differs from the ray
// it stays on the volume's boundary, which moves it no faster toward a face ahead than q + t dir
// does, and never backward (each coordinate, o_a + t dir_a rounded then clamped, is monotone in
// k: every operation of it is monotone), so it stays in the octant's box until it crosses a face
// ahead. (2) Float error (T's rounding, the skipped samples' own positions, a few ulps of
// coordinates below 2^13) moves a skipped sample past the face by far less than one cell, and
// the bricks' ranges include a one-cell apron, so its trilinear cell still reads only entries the
// box's boundary bricks cover. 1 / dir is clamped to +-1e30 (a zero direction, +0 or -0, gives a
// face never reached: T_a huge, finite), so no product is inf or NaN.
// The walk and its runs are gone: one leap per look-up, in the lanes. (An earlier form skipped
// floor((d - 1) 4 / (dt max|dir|)) + 1 samples, the L-infinity ball of radius (d - 1) 4 cells
// around q: inside the box, so never more; ch2 skin took 34.5 iterations per ray for 16.1 samples.)
//
// State lives in arrays (the scheduler in render/ray_marcher.cpp reads and refills single lanes)
// and in registers while a kernel runs. A lane is valid while k < kend; an invalid lane
// composites the all-zero LUT entry `zero_entry` (C + w * 0 = C exactly), so it changes nothing
// and is not counted.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define LACUNA_SIMD_X86 1
#endif

namespace lacuna::simd {

// Kernel paths, narrowest first. Scalar = one ray at a time with plain loops (kernel::RayStream);
// the others march lanes of rays. Volumes of 2^31 voxels or more always march one ray at a time
// (64-bit offsets, plain loops).
enum class Isa { Scalar, Sse41, Avx2, Avx512 };
std::string to_string(Isa i);
// Throws lacuna::Error for an unknown name ("scalar", "sse4.1", "avx2", "avx512").
Isa parse_isa(const std::string& name);
bool isa_supported(Isa i);
// The widest supported path, or what set_isa / the LACUNA_ISA environment variable chose
// (clamped to what this CPU runs).
Isa active_isa();
void set_isa(Isa i);
int lanes_of(Isa i);

inline constexpr int kMaxLanes = 32;  // two groups of sixteen (march_lanes16)

struct Lanes {
    alignas(64) float ox[kMaxLanes], oy[kMaxLanes], oz[kMaxLanes];
    alignas(64) float dx[kMaxLanes], dy[kMaxLanes], dz[kMaxLanes];
    alignas(64) float t_base[kMaxLanes];
    alignas(64) int32_t k[kMaxLanes], kend[kMaxLanes];
    alignas(64) float r[kMaxLanes], g[kMaxLanes], b[kMaxLanes], a[kMaxLanes];
    alignas(64) int32_t n[kMaxLanes];       // samples composited
    alignas(64) int32_t active[kMaxLanes];  // -1: the lane holds a ray; 0: idle
    // Leaping kernels: samples below kcheck lie in a box of fully visible bricks (no leap test).
    alignas(64) int32_t kcheck[kMaxLanes];
};

struct LaneGrid {
    float dt;
    float hi[3];
    int cell[3];
    int32_t sy, sz;
    float lut_offset, lut_scale, lut_last;
    int32_t zero_entry;
    float ert;
    // Leaping (kernels with kLeap): the grid's leap map (accel/brick_grid.h leap_map: per fine
    // brick the distance d and, where d = 0, the sub-bricks' bits) and its strides in fine bricks.
    const uint16_t* leap = nullptr;
    int32_t leap_sy = 0, leap_sz = 0;
    int32_t leap_octant = 0;  // entries per octant map (bricks of the grid)
};

// Eight camera rays at once, for the scheduler's ray set-up: Camera::generate, the move into
// index space and kernel::intersect_box, each lane with exactly their scalar operations (same
// order, IEEE div and sqrt, min/max with std::min/std::max's tie rule).
struct CameraView {
    float eye[3], forward[3], right[3], up[3];
    float half_h, width, height;
    bool ortho;
};
struct RayBatch8 {
    alignas(32) float ox[8], oy[8], oz[8], dx[8], dy[8], dz[8], t_near[8], t_far[8];
    alignas(32) float wx[8], wy[8], wz[8];  // the world direction (Camera::generate's Ray::dir)
    alignas(32) int32_t hit[8];             // -1: the ray meets the box [0, hi]
};

#if LACUNA_SIMD_X86

// Nearest sampling (kNearest, lacuna/accel.h Interpolation): each lane reads the one voxel
// floor(p + 0.5) of its clamped position p, kernel::nearest()'s operations; the loads go through a
// small table (exact int -> float conversions, as float(v) in the scalar path).
template <class T, int W>
inline void nearest_values(const T* data, const int32_t* ofs, float* v) {
    for (int l = 0; l < W; ++l) v[l] = float(data[ofs[l]]);
}

// ---- SSE4.1: four lanes (the baseline) -------------------------------------------------------
#if defined(__SSE4_1__)
// Marches the active lanes. When some need the scheduler (their run ended: k == kend, or they
// turned opaque: a >= ert), the state goes back to `s`, refill(mask) (bit l = lane l) updates
// those lanes and returns whether any lane is still active, and marching resumes with the
// state reloaded. `lut` holds RGBA entries (premultiplied, step-corrected), entry zero_entry all
// zero. The same contract for every width below.
template <bool kNearest, class T, class Refill>
inline void march_lanes4(Lanes& s, const LaneGrid& g, const T* data, const float* lut,
                         Refill& refill) {
    const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f), one = _mm_set1_ps(1.f);
    const __m128 vdt = _mm_set1_ps(g.dt), vert = _mm_set1_ps(g.ert);
    const __m128 vhi[3] = {_mm_set1_ps(g.hi[0]), _mm_set1_ps(g.hi[1]), _mm_set1_ps(g.hi[2])};
    const __m128i vcell[3] = {_mm_set1_epi32(g.cell[0]), _mm_set1_epi32(g.cell[1]),
                              _mm_set1_epi32(g.cell[2])};
    const __m128i vsy = _mm_set1_epi32(g.sy), vsz = _mm_set1_epi32(g.sz);
    const __m128 voff = _mm_set1_ps(g.lut_offset), vscale = _mm_set1_ps(g.lut_scale),
                 vlast = _mm_set1_ps(g.lut_last);
    const __m128i vzero_entry = _mm_set1_epi32(g.zero_entry);
    __m128 o[3], d[3], tb, ar, ag, ab, aa;
    __m128i kend, active, k, n;
#define LACUNA_LOAD_LANES                                                         \
    o[0] = _mm_load_ps(s.ox), o[1] = _mm_load_ps(s.oy), o[2] = _mm_load_ps(s.oz); \
    d[0] = _mm_load_ps(s.dx), d[1] = _mm_load_ps(s.dy), d[2] = _mm_load_ps(s.dz); \
    tb = _mm_load_ps(s.t_base);                                                   \
    kend = _mm_load_si128(reinterpret_cast<const __m128i*>(s.kend));              \
    active = _mm_load_si128(reinterpret_cast<const __m128i*>(s.active));          \
    k = _mm_load_si128(reinterpret_cast<const __m128i*>(s.k));                    \
    n = _mm_load_si128(reinterpret_cast<const __m128i*>(s.n));                    \
    ar = _mm_load_ps(s.r), ag = _mm_load_ps(s.g), ab = _mm_load_ps(s.b), aa = _mm_load_ps(s.a);
    LACUNA_LOAD_LANES
    const ptrdiff_t sy = g.sy, sz = g.sz, syz = ptrdiff_t(g.sy) + g.sz;
    int need;
    for (;;) {
        const __m128i valid = _mm_cmplt_epi32(k, kend);
        // 1. Positions t_k = t_base + (k + 0.5) * dt; cells, fractions, offsets.
        const __m128 t = _mm_add_ps(tb, _mm_mul_ps(_mm_add_ps(_mm_cvtepi32_ps(k), half), vdt));
        __m128 v;
        if constexpr (kNearest) {
            __m128i c[3];
            for (int a = 0; a < 3; ++a) {
                __m128 x = _mm_add_ps(o[a], _mm_mul_ps(t, d[a]));
                x = _mm_max_ps(zero, _mm_min_ps(vhi[a], x));
                c[a] = _mm_cvttps_epi32(_mm_add_ps(x, half));
            }
            const __m128i off = _mm_and_si128(
                _mm_add_epi32(_mm_add_epi32(_mm_mullo_epi32(c[2], vsz), _mm_mullo_epi32(c[1], vsy)),
                              c[0]),
                active);
            alignas(16) int32_t ofs[4];
            alignas(16) float vals[4];
            _mm_store_si128(reinterpret_cast<__m128i*>(ofs), off);
            nearest_values<T, 4>(data, ofs, vals);
            v = _mm_load_ps(vals);
        } else {
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
            // 2. Corners as pairs: one 16-bit (uint8), 32-bit (16-bit) or 64-bit (float) load each.
            __m128 lo[4], hi[4];
            if constexpr (sizeof(T) == 1) {
                __m128i v01 = _mm_setzero_si128(), v23 = _mm_setzero_si128();
                auto pair = [](const T* p) {
                    uint16_t w;
                    __builtin_memcpy(&w, p, 2);
                    return int(w);
                };
#define LACUNA_PAIRS(l)                                    \
    do {                                                   \
        const T* p = data + ofs[l];                        \
        v01 = _mm_insert_epi16(v01, pair(p), l);           \
        v01 = _mm_insert_epi16(v01, pair(p + sy), 4 + l);  \
        v23 = _mm_insert_epi16(v23, pair(p + sz), l);      \
        v23 = _mm_insert_epi16(v23, pair(p + syz), 4 + l); \
    } while (0)
                LACUNA_PAIRS(0);
                LACUNA_PAIRS(1);
                LACUNA_PAIRS(2);
                LACUNA_PAIRS(3);
#undef LACUNA_PAIRS
                const __m128i m_lo0 =
                    _mm_setr_epi8(0, -1, -1, -1, 2, -1, -1, -1, 4, -1, -1, -1, 6, -1, -1, -1);
                const __m128i m_hi0 =
                    _mm_setr_epi8(1, -1, -1, -1, 3, -1, -1, -1, 5, -1, -1, -1, 7, -1, -1, -1);
                const __m128i m_lo1 =
                    _mm_setr_epi8(8, -1, -1, -1, 10, -1, -1, -1, 12, -1, -1, -1, 14, -1, -1, -1);
                const __m128i m_hi1 =
                    _mm_setr_epi8(9, -1, -1, -1, 11, -1, -1, -1, 13, -1, -1, -1, 15, -1, -1, -1);
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
    do {                                                 \
        const T* p = data + ofs[l];                      \
        v[0] = _mm_insert_epi32(v[0], pair(p), l);       \
        v[1] = _mm_insert_epi32(v[1], pair(p + sy), l);  \
        v[2] = _mm_insert_epi32(v[2], pair(p + sz), l);  \
        v[3] = _mm_insert_epi32(v[3], pair(p + syz), l); \
    } while (0)
                LACUNA_PAIRS(0);
                LACUNA_PAIRS(1);
                LACUNA_PAIRS(2);
                LACUNA_PAIRS(3);
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
            v = lerp(c0, c1, f[2]);
        }
        __m128 u = _mm_add_ps(_mm_mul_ps(_mm_sub_ps(v, voff), vscale), half);
        u = _mm_max_ps(zero, _mm_min_ps(vlast, u));
        const __m128i entry = _mm_blendv_epi8(vzero_entry, _mm_cvttps_epi32(u), valid);
        // 4. Composite one sample per lane: RGBA of the 4 entries, transposed to SoA.
        alignas(16) int32_t e[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(e), entry);
        __m128 cr = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[0])),
               cg = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[1]));
        __m128 cb = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[2])),
               ca = _mm_loadu_ps(lut + 4 * ptrdiff_t(e[3]));
        _MM_TRANSPOSE4_PS(cr, cg, cb, ca);
        const __m128 w = _mm_sub_ps(one, aa);
        ar = _mm_add_ps(ar, _mm_mul_ps(w, cr));
        ag = _mm_add_ps(ag, _mm_mul_ps(w, cg));
        ab = _mm_add_ps(ab, _mm_mul_ps(w, cb));
        aa = _mm_add_ps(aa, _mm_mul_ps(w, ca));
        n = _mm_sub_epi32(n, valid);
        k = _mm_sub_epi32(k, valid);  // k + 1 on valid lanes
        // 5. A lane needs the scheduler when its run is over or it is opaque.
        const __m128i over =
            _mm_or_si128(_mm_cmpeq_epi32(k, kend), _mm_castps_si128(_mm_cmpge_ps(aa, vert)));
        need = _mm_movemask_ps(_mm_castsi128_ps(_mm_and_si128(over, active)));
        if (need) {
            _mm_store_si128(reinterpret_cast<__m128i*>(s.k), k);
            _mm_store_si128(reinterpret_cast<__m128i*>(s.n), n);
            _mm_store_ps(s.r, ar);
            _mm_store_ps(s.g, ag);
            _mm_store_ps(s.b, ab);
            _mm_store_ps(s.a, aa);
            if (!refill(need)) return;
            LACUNA_LOAD_LANES
        }
    }
#undef LACUNA_LOAD_LANES
}

#endif

// ---- AVX2: eight lanes ---------------------------------------------------------------------
#define LACUNA_AVX2 __attribute__((target("avx2")))

// Trilinear values at eight index-space points (clamped into [0, hi] first, as trilinear()
// does), trilinear()'s operations in its order. G has hi[3], cell[3], sy, sz. Corners: uint8
// pairs by 16-bit scalar loads (cheaper than gathers here), wider types by 32-bit gathers.
template <class T, class G>
LACUNA_AVX2 inline __attribute__((always_inline)) __m256 trilinear8(const G& g, const T* data,
                                                                    __m256 x, __m256 y, __m256 z) {
    const __m256 zero = _mm256_setzero_ps();
    x = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[0]), x));
    y = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[1]), y));
    z = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[2]), z));
    const __m256i ci = _mm256_min_epi32(_mm256_cvttps_epi32(x), _mm256_set1_epi32(g.cell[0]));
    const __m256i cj = _mm256_min_epi32(_mm256_cvttps_epi32(y), _mm256_set1_epi32(g.cell[1]));
    const __m256i ck = _mm256_min_epi32(_mm256_cvttps_epi32(z), _mm256_set1_epi32(g.cell[2]));
    const __m256 fx = _mm256_sub_ps(x, _mm256_cvtepi32_ps(ci));
    const __m256 fy = _mm256_sub_ps(y, _mm256_cvtepi32_ps(cj));
    const __m256 fz = _mm256_sub_ps(z, _mm256_cvtepi32_ps(ck));
    const __m256i off =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(ck, _mm256_set1_epi32(g.sz)),
                                          _mm256_mullo_epi32(cj, _mm256_set1_epi32(g.sy))),
                         ci);
    constexpr bool kByte = sizeof(T) == 1;
    const __m256i o1 = _mm256_add_epi32(off, _mm256_set1_epi32(kByte ? g.sy - 2 : g.sy));
    const __m256i o2 = _mm256_add_epi32(off, _mm256_set1_epi32(kByte ? g.sz - 2 : g.sz));
    const __m256i o3 =
        _mm256_add_epi32(off, _mm256_set1_epi32(kByte ? g.sy + g.sz - 2 : g.sy + g.sz));
    __m256 c000, c100, c010, c110, c001, c101, c011, c111;
    if constexpr (kByte) {
        // Corner pairs by 16-bit scalar loads into a small table (cheaper than four gathers
        // here), then widened: low byte voxel i, high byte voxel i + 1.
        alignas(32) int32_t o[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(o), off);
        alignas(16) uint16_t w[4][8];
        const ptrdiff_t sy = g.sy, sz = g.sz, syz = sy + sz;
        for (int l = 0; l < 8; ++l) {
            const T* p = data + o[l];
            __builtin_memcpy(&w[0][l], p, 2);
            __builtin_memcpy(&w[1][l], p + sy, 2);
            __builtin_memcpy(&w[2][l], p + sz, 2);
            __builtin_memcpy(&w[3][l], p + syz, 2);
        }
        const __m256i m = _mm256_set1_epi32(0xff);
        const __m256i w0 =
            _mm256_cvtepu16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(w[0])));
        const __m256i w1 =
            _mm256_cvtepu16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(w[1])));
        const __m256i w2 =
            _mm256_cvtepu16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(w[2])));
        const __m256i w3 =
            _mm256_cvtepu16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(w[3])));
        c000 = _mm256_cvtepi32_ps(_mm256_and_si256(w0, m));
        c100 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w0, 8));
        c010 = _mm256_cvtepi32_ps(_mm256_and_si256(w1, m));
        c110 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w1, 8));
        c001 = _mm256_cvtepi32_ps(_mm256_and_si256(w2, m));
        c101 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w2, 8));
        c011 = _mm256_cvtepi32_ps(_mm256_and_si256(w3, m));
        c111 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w3, 8));
    } else if constexpr (sizeof(T) == 2) {
        // 16-bit voxels: each corner pair is one 32-bit scalar load, into a table.
        alignas(32) int32_t o[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(o), off);
        alignas(32) int32_t wq[4][8];
        const ptrdiff_t sy = g.sy, sz = g.sz, syz = sy + sz;
        for (int l = 0; l < 8; ++l) {
            const T* p = data + o[l];
            __builtin_memcpy(&wq[0][l], p, 4);
            __builtin_memcpy(&wq[1][l], p + sy, 4);
            __builtin_memcpy(&wq[2][l], p + sz, 4);
            __builtin_memcpy(&wq[3][l], p + syz, 4);
        }
        const __m256i w0 = _mm256_load_si256(reinterpret_cast<const __m256i*>(wq[0]));
        const __m256i w1 = _mm256_load_si256(reinterpret_cast<const __m256i*>(wq[1]));
        const __m256i w2 = _mm256_load_si256(reinterpret_cast<const __m256i*>(wq[2]));
        const __m256i w3 = _mm256_load_si256(reinterpret_cast<const __m256i*>(wq[3]));
        if constexpr (std::is_signed_v<T>) {
            c000 = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(w0, 16), 16));
            c010 = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(w1, 16), 16));
            c001 = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(w2, 16), 16));
            c011 = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(w3, 16), 16));
            c100 = _mm256_cvtepi32_ps(_mm256_srai_epi32(w0, 16));
            c110 = _mm256_cvtepi32_ps(_mm256_srai_epi32(w1, 16));
            c101 = _mm256_cvtepi32_ps(_mm256_srai_epi32(w2, 16));
            c111 = _mm256_cvtepi32_ps(_mm256_srai_epi32(w3, 16));
        } else {
            const __m256i m = _mm256_set1_epi32(0xffff);
            c000 = _mm256_cvtepi32_ps(_mm256_and_si256(w0, m));
            c010 = _mm256_cvtepi32_ps(_mm256_and_si256(w1, m));
            c001 = _mm256_cvtepi32_ps(_mm256_and_si256(w2, m));
            c011 = _mm256_cvtepi32_ps(_mm256_and_si256(w3, m));
            c100 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w0, 16));
            c110 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w1, 16));
            c101 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w2, 16));
            c111 = _mm256_cvtepi32_ps(_mm256_srli_epi32(w3, 16));
        }
    } else {
        static_assert(std::is_same_v<T, float>, "voxel types: uint8, int16, uint16, float");
        const float* base = data;
        c000 = _mm256_i32gather_ps(base, off, 4);
        c100 = _mm256_i32gather_ps(base + 1, off, 4);
        c010 = _mm256_i32gather_ps(base, o1, 4);
        c110 = _mm256_i32gather_ps(base + 1, o1, 4);
        c001 = _mm256_i32gather_ps(base, o2, 4);
        c101 = _mm256_i32gather_ps(base + 1, o2, 4);
        c011 = _mm256_i32gather_ps(base, o3, 4);
        c111 = _mm256_i32gather_ps(base + 1, o3, 4);
    }
    const __m256 c00 = _mm256_add_ps(c000, _mm256_mul_ps(fx, _mm256_sub_ps(c100, c000)));
    const __m256 c10 = _mm256_add_ps(c010, _mm256_mul_ps(fx, _mm256_sub_ps(c110, c010)));
    const __m256 c01 = _mm256_add_ps(c001, _mm256_mul_ps(fx, _mm256_sub_ps(c101, c001)));
    const __m256 c11 = _mm256_add_ps(c011, _mm256_mul_ps(fx, _mm256_sub_ps(c111, c011)));
    const __m256 c0 = _mm256_add_ps(c00, _mm256_mul_ps(fy, _mm256_sub_ps(c10, c00)));
    const __m256 c1 = _mm256_add_ps(c01, _mm256_mul_ps(fy, _mm256_sub_ps(c11, c01)));
    return _mm256_add_ps(c0, _mm256_mul_ps(fz, _mm256_sub_ps(c1, c0)));
}

// Nearest values at eight index-space points: clamped as trilinear8 clamps, then the voxel
// floor(p + 0.5) (kernel::nearest()'s operations). Float voxels by one gather, integers by scalar
// loads into a table.
template <class T, class G>
LACUNA_AVX2 inline __attribute__((always_inline)) __m256 nearest8(const G& g, const T* data,
                                                                  __m256 x, __m256 y, __m256 z) {
    const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f);
    x = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[0]), x));
    y = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[1]), y));
    z = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[2]), z));
    const __m256i ci = _mm256_cvttps_epi32(_mm256_add_ps(x, half));
    const __m256i cj = _mm256_cvttps_epi32(_mm256_add_ps(y, half));
    const __m256i ck = _mm256_cvttps_epi32(_mm256_add_ps(z, half));
    const __m256i off =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(ck, _mm256_set1_epi32(g.sz)),
                                          _mm256_mullo_epi32(cj, _mm256_set1_epi32(g.sy))),
                         ci);
    if constexpr (std::is_same_v<T, float>) {
        return _mm256_i32gather_ps(data, off, 4);
    } else {
        alignas(32) int32_t o[8];
        alignas(32) float v[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(o), off);
        nearest_values<T, 8>(data, o, v);
        return _mm256_load_ps(v);
    }
}

// Leaping's per-lane set-up: 1 / dir per axis, clamped to +-1e30, and the offset of the lane's
// octant map, octant (sign bits of the three inverses) times the octant stride (see "Leaping").
struct LeapInverse {
    alignas(64) float inv[3][kMaxLanes];
    alignas(64) int32_t octant[kMaxLanes];
};
LACUNA_AVX2 inline __attribute__((always_inline)) void leap_inverse8(__m256 dx, __m256 dy,
                                                                     __m256 dz, int32_t stride,
                                                                     LeapInverse& li) {
    const __m256 big = _mm256_set1_ps(1e30f), one = _mm256_set1_ps(1.f);
    const __m256 d[3] = {dx, dy, dz};
    __m256i oct = _mm256_setzero_si256();
    for (int a = 0; a < 3; ++a) {
        const __m256 inv = _mm256_max_ps(_mm256_sub_ps(_mm256_setzero_ps(), big),
                                         _mm256_min_ps(big, _mm256_div_ps(one, d[a])));
        _mm256_store_ps(li.inv[a], inv);
        oct = _mm256_or_si256(
            oct, _mm256_slli_epi32(_mm256_srli_epi32(_mm256_castps_si256(inv), 31), a));
    }
    _mm256_store_si256(reinterpret_cast<__m256i*>(li.octant),
                       _mm256_mullo_epi32(oct, _mm256_set1_epi32(stride)));
}
// The valid lanes' next sample: k + 1, or leaping k + adv (at most kend).
template <bool kLeap>
LACUNA_AVX2 inline __attribute__((always_inline)) __m256i advance8(__m256i k, __m256i kend,
                                                                   __m256i valid, __m256i adv) {
    if constexpr (kLeap)
        return _mm256_min_epi32(_mm256_add_epi32(k, _mm256_and_si256(adv, valid)), kend);
    else
        return _mm256_sub_epi32(k, valid);
}

// Leaping, eight lanes (see "Leaping" above): for the valid lanes whose sample (x, y, z, not
// yet clamped) lies in an empty fine brick, taken loses the lane and adv becomes its skip.
LACUNA_AVX2 inline __attribute__((always_inline)) void leap8(const LaneGrid& g, __m256 x, __m256 y,
                                                             __m256 z, __m256i valid, __m256 inv_dt,
                                                             const LeapInverse& li, __m256i& taken,
                                                             __m256i& adv,
                                                             __m256i* inside = nullptr) {
    const __m256 zero = _mm256_setzero_ps();
    const __m256 p[3] = {x, y, z};
    __m256 q[3];
    __m256i c[3], f[3];
    for (int a = 0; a < 3; ++a) {
        q[a] = _mm256_max_ps(zero, _mm256_min_ps(_mm256_set1_ps(g.hi[a]), p[a]));
        c[a] = _mm256_min_epi32(_mm256_cvttps_epi32(q[a]), _mm256_set1_epi32(g.cell[a]));
        f[a] = _mm256_srli_epi32(c[a], 2);
    }
    const __m256i idx = _mm256_add_epi32(
        _mm256_add_epi32(_mm256_mullo_epi32(f[2], _mm256_set1_epi32(g.leap_sz)),
                         _mm256_mullo_epi32(f[1], _mm256_set1_epi32(g.leap_sy))),
        _mm256_add_epi32(f[0], _mm256_load_si256(reinterpret_cast<const __m256i*>(li.octant))));
    const __m256i w = _mm256_mask_i32gather_epi32(
        _mm256_setzero_si256(), reinterpret_cast<const int*>(g.leap), idx, valid, 2);
    const __m256i d = _mm256_and_si256(w, _mm256_set1_epi32(0xff));
    const __m256i one_i = _mm256_set1_epi32(1), zero_i = _mm256_setzero_si256();
    // d = 0: the bit of c's sub-brick, (c_x & 2) / 2 + (c_y & 2) + (c_z & 2) * 2.
    const __m256i two = _mm256_set1_epi32(2);
    const __m256i sub =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_srli_epi32(_mm256_and_si256(c[0], two), 1),
                                          _mm256_and_si256(c[1], two)),
                         _mm256_slli_epi32(_mm256_and_si256(c[2], two), 1));
    const __m256i sub_bits = _mm256_srli_epi32(_mm256_and_si256(w, _mm256_set1_epi32(0xff00)), 8);
    const __m256i sub_vis = _mm256_and_si256(_mm256_srlv_epi32(sub_bits, sub), one_i);
    // d >= 1: an empty box to skip, or (every sub-brick set) a fully visible one to sample.
    const __m256i coarse = _mm256_xor_si256(_mm256_cmpeq_epi32(d, zero_i), _mm256_set1_epi32(-1));
    const __m256i full = _mm256_cmpeq_epi32(sub_bits, _mm256_set1_epi32(0xff));
    const __m256i skip = _mm256_and_si256(
        _mm256_or_si256(_mm256_andnot_si256(full, coarse), _mm256_cmpeq_epi32(sub_vis, zero_i)),
        valid);
    taken = _mm256_andnot_si256(skip, valid);
    // The exit of the box: bricks within d - 1 (edge 4), or the sub-brick (edge 2, D = 1):
    // face_a = (c_a & -edge) + (dir_a < 0 ? (1 - D) edge : D edge), min_a (face_a - q_a) / dir_a.
    const __m256i D = _mm256_blendv_epi8(one_i, d, coarse);
    const __m256i sh = _mm256_blendv_epi8(one_i, two, coarse);
    const __m256i fwd = _mm256_sllv_epi32(D, sh),
                  back = _mm256_sllv_epi32(_mm256_sub_epi32(one_i, D), sh);
    const __m256i lo = _mm256_blendv_epi8(_mm256_set1_epi32(~1), _mm256_set1_epi32(~3), coarse);
    __m256 exit_t = _mm256_set1_ps(16777216.f);
    for (int a = 0; a < 3; ++a) {
        const __m256 inv = _mm256_load_ps(li.inv[a]);
        const __m256i ahead = _mm256_castps_si256(
            _mm256_blendv_ps(_mm256_castsi256_ps(fwd), _mm256_castsi256_ps(back), inv));
        const __m256 face = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_and_si256(c[a], lo), ahead));
        exit_t = _mm256_min_ps(exit_t, _mm256_mul_ps(_mm256_sub_ps(face, q[a]), inv));
    }
    // (capped at 2^24 samples, far past any ray's end: cvtt stays in range; T >= 0 up to -0)
    const __m256i leap =
        _mm256_add_epi32(_mm256_cvttps_epi32(_mm256_min_ps(_mm256_mul_ps(exit_t, inv_dt),
                                                           _mm256_set1_ps(16777216.f))),
                         one_i);
    adv = _mm256_blendv_epi8(one_i, leap, skip);
    if (inside) *inside = _mm256_and_si256(_mm256_and_si256(full, valid), leap);
}

// The leap test only where it may skip: when a valid lane has reached its kcheck (the first
// sample past its box of fully visible bricks, see "Leaping" above); a test that finds a lane
// in a fully visible brick moves that lane's kcheck past the new box. Otherwise taken and adv
// stay as given (every valid lane takes its sample).
LACUNA_AVX2 inline __attribute__((always_inline)) void leap8_outside(
    const LaneGrid& g, __m256 x, __m256 y, __m256 z, __m256i valid, __m256 inv_dt,
    const LeapInverse& li, __m256i k, __m256i& kcheck, __m256i& taken, __m256i& adv) {
    const __m256i test = _mm256_andnot_si256(_mm256_cmpgt_epi32(kcheck, k), valid);
    if (_mm256_testz_si256(test, test)) return;
    __m256i inside;
    leap8(g, x, y, z, valid, inv_dt, li, taken, adv, &inside);
    kcheck = _mm256_blendv_epi8(kcheck, _mm256_add_epi32(k, inside),
                                _mm256_cmpgt_epi32(inside, _mm256_setzero_si256()));
}

// Prefetch: a ray's samples walk through the volume at half a voxel per step, each step in
// other voxel rows, in an order no hardware prefetcher follows; once the volume outgrows the
// caches (ch2better, 35 MB; tree512, 128 MB) a step waits on its corner rows. Each lane that
// takes its sample (all valid lanes; in the leaping kernels those not leaping) therefore asks for
// the cell of its sample kPrefetchSteps steps ahead: its rows (j, k) and (j + 1, k + 1), two of
// the four lines, early enough to arrive in time and late enough to stay in L1. Measured on
// ch2better 384², --accel none --ert 1, one thread, AVX-512 (docs/benchmarks.md): 8 steps -20%,
// 12-16 steps -25%, 24 steps -22%; one row or four no better than two; the cache-resident ch2
// within noise. A hint only: no value depends on it.
constexpr int kPrefetchSteps = 12;
template <class T>
LACUNA_AVX2 inline __attribute__((always_inline)) void prefetch_ahead8(
    const LaneGrid& g, const T* data, __m256 t, __m256 ox, __m256 oy, __m256 oz, __m256 dx,
    __m256 dy, __m256 dz, __m256i lanes) {
    const __m256 zero = _mm256_setzero_ps();
    const __m256 ta = _mm256_add_ps(t, _mm256_set1_ps(float(kPrefetchSteps) * g.dt));
    const __m256 x = _mm256_max_ps(
        zero, _mm256_min_ps(_mm256_set1_ps(g.hi[0]), _mm256_add_ps(ox, _mm256_mul_ps(ta, dx))));
    const __m256 y = _mm256_max_ps(
        zero, _mm256_min_ps(_mm256_set1_ps(g.hi[1]), _mm256_add_ps(oy, _mm256_mul_ps(ta, dy))));
    const __m256 z = _mm256_max_ps(
        zero, _mm256_min_ps(_mm256_set1_ps(g.hi[2]), _mm256_add_ps(oz, _mm256_mul_ps(ta, dz))));
    const __m256i off = _mm256_and_si256(
        lanes,
        _mm256_add_epi32(
            _mm256_add_epi32(_mm256_mullo_epi32(_mm256_cvttps_epi32(z), _mm256_set1_epi32(g.sz)),
                             _mm256_mullo_epi32(_mm256_cvttps_epi32(y), _mm256_set1_epi32(g.sy))),
            _mm256_cvttps_epi32(x)));
    alignas(32) int32_t o[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(o), off);
    // (addresses as integers: the diagonal row of the last cell lies past the volume's end,
    // which a prefetch may name but pointer arithmetic may not)
    const uintptr_t base = reinterpret_cast<uintptr_t>(data),
                    diag = (uintptr_t(g.sy) + g.sz) * sizeof(T);
    for (int l = 0; l < 8; ++l) {
        const uintptr_t a = base + uintptr_t(o[l]) * sizeof(T);
        __builtin_prefetch(reinterpret_cast<const void*>(a), 0, 3);
        __builtin_prefetch(reinterpret_cast<const void*>(a + diag), 0, 3);
    }
}

template <bool kNearest, class T, class Refill, bool kLeap = false>
LACUNA_AVX2 void march_lanes8(Lanes& s, const LaneGrid& g, const T* data, const float* lut,
                              Refill& refill) {
    static_assert(!(kLeap && kNearest), "leaping is for trilinear samples");
    const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f), one = _mm256_set1_ps(1.f);
    const __m256 vdt = _mm256_set1_ps(g.dt), vert = _mm256_set1_ps(g.ert);
    const __m256 voff = _mm256_set1_ps(g.lut_offset), vscale = _mm256_set1_ps(g.lut_scale),
                 vlast = _mm256_set1_ps(g.lut_last);
    const __m256i vzero_entry = _mm256_set1_epi32(g.zero_entry);
    __m256 ox, oy, oz, dx, dy, dz, tb, ar, ag, ab, aa;
    __m256i kend, active, k, n, kcheck = _mm256_setzero_si256();
#define LACUNA_LOAD_LANES                                                            \
    ox = _mm256_load_ps(s.ox), oy = _mm256_load_ps(s.oy), oz = _mm256_load_ps(s.oz); \
    dx = _mm256_load_ps(s.dx), dy = _mm256_load_ps(s.dy), dz = _mm256_load_ps(s.dz); \
    tb = _mm256_load_ps(s.t_base);                                                   \
    kend = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.kend));              \
    active = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.active));          \
    k = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.k));                    \
    n = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.n));                    \
    ar = _mm256_load_ps(s.r), ag = _mm256_load_ps(s.g), ab = _mm256_load_ps(s.b);    \
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
        __m256 x = _mm256_add_ps(ox, _mm256_mul_ps(t, dx));
        __m256 y = _mm256_add_ps(oy, _mm256_mul_ps(t, dy));
        __m256 z = _mm256_add_ps(oz, _mm256_mul_ps(t, dz));
        __m256 v;
        if constexpr (kNearest)
            v = nearest8(g, data, x, y, z);
        else
            v = trilinear8(g, data, x, y, z);
        // Leaping: the lanes whose sample lies in an empty fine brick skip ahead instead; the
        // test only when a valid lane has left its box of fully visible bricks (kcheck, as in
        // march_lanes16's Group16).
        __m256i taken = valid, adv = _mm256_set1_epi32(1);
        if constexpr (kLeap) leap8_outside(g, x, y, z, valid, inv_dt, linv, k, kcheck, taken, adv);
        if constexpr (!kNearest) prefetch_ahead8(g, data, t, ox, oy, oz, dx, dy, dz, taken);
        __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(v, voff), vscale), half);
        u = _mm256_max_ps(zero, _mm256_min_ps(vlast, u));
        const __m256i entry = _mm256_blendv_epi8(vzero_entry, _mm256_cvttps_epi32(u), taken);
        // Composite one sample per lane (RGBA gathered from the LUT, SoA).
        // RGBA of the 8 entries: eight 16-byte loads and a 4x4 transpose per 128-bit lane (lane
        // j of q4[i] holds lane 4j + i's entry, so the channels come out in lane order).
        alignas(32) int32_t e[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(e), entry);
        __m256 q4[4];
        for (int i = 0; i < 4; ++i)
            q4[i] = _mm256_insertf128_ps(
                _mm256_castps128_ps256(_mm_loadu_ps(lut + 4 * ptrdiff_t(e[i]))),
                _mm_loadu_ps(lut + 4 * ptrdiff_t(e[4 + i])), 1);
        const __m256 t0 = _mm256_unpacklo_ps(q4[0], q4[1]), t1 = _mm256_unpackhi_ps(q4[0], q4[1]);
        const __m256 t2 = _mm256_unpacklo_ps(q4[2], q4[3]), t3 = _mm256_unpackhi_ps(q4[2], q4[3]);
        const __m256 cr =
            _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(t0), _mm256_castps_pd(t2)));
        const __m256 cg =
            _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(t0), _mm256_castps_pd(t2)));
        const __m256 cb =
            _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(t1), _mm256_castps_pd(t3)));
        const __m256 ca =
            _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(t1), _mm256_castps_pd(t3)));
        const __m256 w = _mm256_sub_ps(one, aa);
        ar = _mm256_add_ps(ar, _mm256_mul_ps(w, cr));
        ag = _mm256_add_ps(ag, _mm256_mul_ps(w, cg));
        ab = _mm256_add_ps(ab, _mm256_mul_ps(w, cb));
        aa = _mm256_add_ps(aa, _mm256_mul_ps(w, ca));
        n = _mm256_sub_epi32(n, taken);
        k = advance8<kLeap>(k, kend, valid, adv);
        const __m256i over = _mm256_or_si256(
            _mm256_cmpeq_epi32(k, kend), _mm256_castps_si256(_mm256_cmp_ps(aa, vert, _CMP_GE_OS)));
        // A lane whose run is over, or which is opaque, waits (kend = k makes it invalid) until
        // a quarter of the lanes wait or all do: one refill then serves several lanes.
        kend = _mm256_blendv_epi8(kend, k, over);
        need = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_and_si256(over, active)));
        waiting |= need;
        if (__builtin_popcount(unsigned(waiting)) >= 2 || waiting == active_mask) {
            need = waiting;
            waiting = 0;
            _mm256_store_si256(reinterpret_cast<__m256i*>(s.kend), kend);
            _mm256_store_si256(reinterpret_cast<__m256i*>(s.k), k);
            _mm256_store_si256(reinterpret_cast<__m256i*>(s.n), n);
            _mm256_store_ps(s.r, ar);
            _mm256_store_ps(s.g, ag);
            _mm256_store_ps(s.b, ab);
            _mm256_store_ps(s.a, aa);
            if constexpr (kLeap) _mm256_store_si256(reinterpret_cast<__m256i*>(s.kcheck), kcheck);
            if (!refill(need)) return;
            LACUNA_LOAD_LANES
        }
    }
#undef LACUNA_LOAD_LANES
}

// ---- AVX-512: sixteen lanes ------------------------------------------------------------------
// GCC 12's avx512fintrin.h seeds unmasked intrinsics with _mm512_undefined_ps(), which
// -Wuninitialized reports inside target("avx512f") functions: a false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define LACUNA_AVX512 __attribute__((target("avx512f")))

// The corner-pair rows of sixteen cells at voxel offsets `ofs` into w[row][lane]: row r holds the
// pair (i, i + 1) at (j + (r & 1), k + (r >> 1)); a Word is two voxels (uint16_t for bytes,
// int32_t for 16-bit voxels). kSparse: only the `live` lanes load, the others read 0.
template <class Word, class T>
LACUNA_AVX512 inline __attribute__((always_inline)) void load_pair_rows(const T* p, int l,
                                                                        ptrdiff_t psy,
                                                                        ptrdiff_t psz,
                                                                        Word (*w)[16]) {
    __builtin_memcpy(&w[0][l], p, sizeof(Word));
    __builtin_memcpy(&w[1][l], p + psy, sizeof(Word));
    __builtin_memcpy(&w[2][l], p + psz, sizeof(Word));
    __builtin_memcpy(&w[3][l], p + psy + psz, sizeof(Word));
}
template <bool kSparse, class Word, class T>
LACUNA_AVX512 inline __attribute__((always_inline)) void corner_pairs16(
    const T* data, const int32_t* ofs, __mmask16 live, ptrdiff_t psy, ptrdiff_t psz,
    Word (*w)[16]) {
    if constexpr (kSparse) {
        for (size_t b = 0; b < sizeof(Word) * 4 * 16; b += 64)
            _mm512_store_si512(reinterpret_cast<char*>(w) + b, _mm512_setzero_si512());
        for (unsigned mk = live; mk; mk &= mk - 1)
            load_pair_rows(data + ofs[__builtin_ctz(mk)], __builtin_ctz(mk), psy, psz, w);
    } else {
        for (int l = 0; l < 16; ++l) load_pair_rows(data + ofs[l], l, psy, psz, w);
    }
}

// Trilinear values at sixteen index-space points already clamped into [0, hi] (trilinear8's
// operations in its order); lanes outside `live` read voxel 0's cell, their values unused. G has
// cell[3], sy, sz. kSparse (integer voxels): only the `live` lanes load their corners, one by
// one (the others see corners of 0): the leaping kernels, where most lanes leap in empty space
// on most steps and a step's loads would otherwise cost as much as sixteen samples.
template <class T, class G, bool kSparse = false>
LACUNA_AVX512 inline __attribute__((always_inline)) __m512 trilinear16(const G& g, const T* data,
                                                                       __m512 x, __m512 y, __m512 z,
                                                                       __mmask16 live) {
    constexpr bool kByte = sizeof(T) == 1;
    const __m512i ci = _mm512_min_epi32(_mm512_cvttps_epi32(x), _mm512_set1_epi32(g.cell[0]));
    const __m512i cj = _mm512_min_epi32(_mm512_cvttps_epi32(y), _mm512_set1_epi32(g.cell[1]));
    const __m512i ck = _mm512_min_epi32(_mm512_cvttps_epi32(z), _mm512_set1_epi32(g.cell[2]));
    const __m512 fx = _mm512_sub_ps(x, _mm512_cvtepi32_ps(ci));
    const __m512 fy = _mm512_sub_ps(y, _mm512_cvtepi32_ps(cj));
    const __m512 fz = _mm512_sub_ps(z, _mm512_cvtepi32_ps(ck));
    __m512i off =
        _mm512_add_epi32(_mm512_add_epi32(_mm512_mullo_epi32(ck, _mm512_set1_epi32(g.sz)),
                                          _mm512_mullo_epi32(cj, _mm512_set1_epi32(g.sy))),
                         ci);
    off = _mm512_maskz_mov_epi32(live, off);  // other lanes read voxel 0
    __m512 c000, c100, c010, c110, c001, c101, c011, c111;
    if constexpr (kByte) {
        // Corner pairs by 16-bit scalar loads into a table (trilinear8's way; cheaper than
        // four sixteen-lane gathers here), widened: low byte voxel i, high byte voxel i + 1.
        alignas(64) int32_t ofs[16];
        alignas(64) uint16_t wp[4][16];
        _mm512_store_si512(ofs, off);
        corner_pairs16<kSparse>(data, ofs, live, g.sy, g.sz, wp);
        const __m512i m = _mm512_set1_epi32(0xff);
        const __m512i w0 =
            _mm512_cvtepu16_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(wp[0])));
        const __m512i w1 =
            _mm512_cvtepu16_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(wp[1])));
        const __m512i w2 =
            _mm512_cvtepu16_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(wp[2])));
        const __m512i w3 =
            _mm512_cvtepu16_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(wp[3])));
        c000 = _mm512_cvtepi32_ps(_mm512_and_si512(w0, m));
        c100 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w0, 8));
        c010 = _mm512_cvtepi32_ps(_mm512_and_si512(w1, m));
        c110 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w1, 8));
        c001 = _mm512_cvtepi32_ps(_mm512_and_si512(w2, m));
        c101 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w2, 8));
        c011 = _mm512_cvtepi32_ps(_mm512_and_si512(w3, m));
        c111 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w3, 8));
    } else if constexpr (sizeof(T) == 2) {
        // 16-bit voxels: each corner pair is one 32-bit scalar load, into a table.
        alignas(64) int32_t ofs[16];
        alignas(64) int32_t wq[4][16];
        _mm512_store_si512(ofs, off);
        corner_pairs16<kSparse>(data, ofs, live, g.sy, g.sz, wq);
        const __m512i w0 = _mm512_load_si512(wq[0]), w1 = _mm512_load_si512(wq[1]);
        const __m512i w2 = _mm512_load_si512(wq[2]), w3 = _mm512_load_si512(wq[3]);
        if constexpr (std::is_signed_v<T>) {
            c000 = _mm512_cvtepi32_ps(_mm512_srai_epi32(_mm512_slli_epi32(w0, 16), 16));
            c010 = _mm512_cvtepi32_ps(_mm512_srai_epi32(_mm512_slli_epi32(w1, 16), 16));
            c001 = _mm512_cvtepi32_ps(_mm512_srai_epi32(_mm512_slli_epi32(w2, 16), 16));
            c011 = _mm512_cvtepi32_ps(_mm512_srai_epi32(_mm512_slli_epi32(w3, 16), 16));
            c100 = _mm512_cvtepi32_ps(_mm512_srai_epi32(w0, 16));
            c110 = _mm512_cvtepi32_ps(_mm512_srai_epi32(w1, 16));
            c101 = _mm512_cvtepi32_ps(_mm512_srai_epi32(w2, 16));
            c111 = _mm512_cvtepi32_ps(_mm512_srai_epi32(w3, 16));
        } else {
            const __m512i m = _mm512_set1_epi32(0xffff);
            c000 = _mm512_cvtepi32_ps(_mm512_and_si512(w0, m));
            c010 = _mm512_cvtepi32_ps(_mm512_and_si512(w1, m));
            c001 = _mm512_cvtepi32_ps(_mm512_and_si512(w2, m));
            c011 = _mm512_cvtepi32_ps(_mm512_and_si512(w3, m));
            c100 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w0, 16));
            c110 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w1, 16));
            c101 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w2, 16));
            c111 = _mm512_cvtepi32_ps(_mm512_srli_epi32(w3, 16));
        }
    } else {
        const float* base = reinterpret_cast<const float*>(data);
        const __m512i o1 = _mm512_add_epi32(off, _mm512_set1_epi32(g.sy)),
                      o2 = _mm512_add_epi32(off, _mm512_set1_epi32(g.sz)),
                      o3 = _mm512_add_epi32(off, _mm512_set1_epi32(g.sy + g.sz));
        c000 = _mm512_i32gather_ps(off, base, 4);
        c100 = _mm512_i32gather_ps(off, base + 1, 4);
        c010 = _mm512_i32gather_ps(o1, base, 4);
        c110 = _mm512_i32gather_ps(o1, base + 1, 4);
        c001 = _mm512_i32gather_ps(o2, base, 4);
        c101 = _mm512_i32gather_ps(o2, base + 1, 4);
        c011 = _mm512_i32gather_ps(o3, base, 4);
        c111 = _mm512_i32gather_ps(o3, base + 1, 4);
    }
    const __m512 c00 = _mm512_add_ps(c000, _mm512_mul_ps(fx, _mm512_sub_ps(c100, c000)));
    const __m512 c10 = _mm512_add_ps(c010, _mm512_mul_ps(fx, _mm512_sub_ps(c110, c010)));
    const __m512 c01 = _mm512_add_ps(c001, _mm512_mul_ps(fx, _mm512_sub_ps(c101, c001)));
    const __m512 c11 = _mm512_add_ps(c011, _mm512_mul_ps(fx, _mm512_sub_ps(c111, c011)));
    const __m512 c0 = _mm512_add_ps(c00, _mm512_mul_ps(fy, _mm512_sub_ps(c10, c00)));
    const __m512 c1 = _mm512_add_ps(c01, _mm512_mul_ps(fy, _mm512_sub_ps(c11, c01)));
    return _mm512_add_ps(c0, _mm512_mul_ps(fz, _mm512_sub_ps(c1, c0)));
}

// Leaping kernels, integer voxels: with few lanes taking a sample, only theirs load corners
// (one by one, trilinear16's kSparse); with kDenseLoads or more, all sixteen load without the
// per-lane branches (the others at voxel 0), 5% faster on ch2 inside the head and no slower on
// the sparse tree (docs/benchmarks.md, fifteenth session).
inline constexpr int kDenseLoads = 4;

// Leaping, sixteen lanes: leap8's operations on positions already clamped into [0, hi].
LACUNA_AVX512 inline __attribute__((always_inline)) void leap16(
    const LaneGrid& g, __m512 x, __m512 y, __m512 z, __mmask16 valid, __m512 inv_dt,
    const LeapInverse& li, __mmask16& taken, __m512i& adv, int b = 0,
    __mmask16* full_lanes = nullptr, __m512i* inside = nullptr) {
    const __m512 zero = _mm512_setzero_ps();
    const __m512i ione = _mm512_set1_epi32(1);
    const __m512 q[3] = {x, y, z};
    __m512i c[3];
    for (int a = 0; a < 3; ++a)
        c[a] = _mm512_min_epi32(_mm512_cvttps_epi32(q[a]), _mm512_set1_epi32(g.cell[a]));
    const __m512i idx = _mm512_add_epi32(
        _mm512_add_epi32(
            _mm512_mullo_epi32(_mm512_srli_epi32(c[2], 2), _mm512_set1_epi32(g.leap_sz)),
            _mm512_mullo_epi32(_mm512_srli_epi32(c[1], 2), _mm512_set1_epi32(g.leap_sy))),
        _mm512_add_epi32(_mm512_srli_epi32(c[0], 2), _mm512_load_si512(li.octant + b)));
    const __m512i w = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), valid, idx, g.leap, 2);
    const __m512i d = _mm512_and_si512(w, _mm512_set1_epi32(0xff));
    const __m512i two = _mm512_set1_epi32(2);
    const __m512i sub =
        _mm512_add_epi32(_mm512_add_epi32(_mm512_srli_epi32(_mm512_and_si512(c[0], two), 1),
                                          _mm512_and_si512(c[1], two)),
                         _mm512_slli_epi32(_mm512_and_si512(c[2], two), 1));
    const __m512i sub_bits = _mm512_srli_epi32(_mm512_and_si512(w, _mm512_set1_epi32(0xff00)), 8);
    // d >= 1: an empty box to skip, or (every sub-brick set) a fully visible one to sample.
    const __mmask16 coarse = _mm512_test_epi32_mask(d, d);
    const __mmask16 full = _mm512_cmpeq_epi32_mask(sub_bits, _mm512_set1_epi32(0xff));
    const __mmask16 sub_vis = _mm512_test_epi32_mask(_mm512_srlv_epi32(sub_bits, sub), ione);
    const __mmask16 skip = valid & ((coarse & ~full) | ~sub_vis);
    taken = valid & ~skip;
    // The exit of the box (leap8's form): bricks within d - 1, or the sub-brick.
    const __m512i D = _mm512_mask_blend_epi32(coarse, ione, d);
    const __m512i sh = _mm512_mask_blend_epi32(coarse, ione, two);
    const __m512i fwd = _mm512_sllv_epi32(D, sh),
                  back = _mm512_sllv_epi32(_mm512_sub_epi32(ione, D), sh);
    const __m512i lo =
        _mm512_mask_blend_epi32(coarse, _mm512_set1_epi32(~1), _mm512_set1_epi32(~3));
    __m512 exit_t = _mm512_set1_ps(16777216.f);
    for (int a = 0; a < 3; ++a) {
        const __m512 inv = _mm512_load_ps(li.inv[a] + b);
        const __m512i ahead =
            _mm512_mask_blend_epi32(_mm512_cmp_ps_mask(inv, zero, _CMP_LT_OQ), fwd, back);
        const __m512 face = _mm512_cvtepi32_ps(_mm512_add_epi32(_mm512_and_si512(c[a], lo), ahead));
        exit_t = _mm512_min_ps(exit_t, _mm512_mul_ps(_mm512_sub_ps(face, q[a]), inv));
    }
    // (capped at 2^24 samples, far past any ray's end: cvtt stays in range)
    const __m512i leap =
        _mm512_add_epi32(_mm512_cvttps_epi32(_mm512_min_ps(_mm512_mul_ps(exit_t, inv_dt),
                                                           _mm512_set1_ps(16777216.f))),
                         ione);
    adv = _mm512_mask_blend_epi32(skip, ione, leap);
    if (full_lanes) *full_lanes = valid & full, *inside = leap;
}

// leap8_outside for sixteen lanes.
LACUNA_AVX512 inline __attribute__((always_inline)) void leap16_outside(
    const LaneGrid& g, __m512 x, __m512 y, __m512 z, __mmask16 valid, const LeapInverse& li, int b,
    __m512i k, __m512i& kcheck, __mmask16& taken, __m512i& adv) {
    if (!(_mm512_cmpge_epi32_mask(k, kcheck) & valid)) return;
    __mmask16 full;
    __m512i inside;
    leap16(g, x, y, z, valid, _mm512_set1_ps(1.f / g.dt), li, taken, adv, b, &full, &inside);
    kcheck = _mm512_mask_add_epi32(kcheck, full, k, inside);
}

// The leaping kernels' trilinear values of the lanes in `taken` (kDenseLoads); float voxels
// load every active lane (gathers).
template <class T>
LACUNA_AVX512 inline __attribute__((always_inline)) __m512 leap_trilinear16(const LaneGrid& g,
                                                                            const T* data, __m512 x,
                                                                            __m512 y, __m512 z,
                                                                            __mmask16 taken,
                                                                            __mmask16 active) {
    if constexpr (std::is_integral_v<T>) {
        if (__builtin_popcount(taken) >= kDenseLoads)
            return trilinear16<T, LaneGrid, false>(g, data, x, y, z, taken);
        return trilinear16<T, LaneGrid, true>(g, data, x, y, z, taken);
    } else {
        return trilinear16<T, LaneGrid, false>(g, data, x, y, z, active);
    }
}
// leap_inverse8's clamped 1 / dir, sixteen lanes.
LACUNA_AVX512 inline __attribute__((always_inline)) void leap_inverse16(__m512 dx, __m512 dy,
                                                                        __m512 dz, int32_t stride,
                                                                        LeapInverse& li,
                                                                        int b = 0) {
    const __m512 big = _mm512_set1_ps(1e30f), nbig = _mm512_set1_ps(-1e30f),
                 one = _mm512_set1_ps(1.f);
    const __m512 d[3] = {dx, dy, dz};
    __m512i oct = _mm512_setzero_si512();
    for (int a = 0; a < 3; ++a) {
        const __m512 inv = _mm512_max_ps(nbig, _mm512_min_ps(big, _mm512_div_ps(one, d[a])));
        _mm512_store_ps(li.inv[a] + b, inv);
        oct = _mm512_or_si512(
            oct, _mm512_slli_epi32(_mm512_srli_epi32(_mm512_castps_si512(inv), 31), unsigned(a)));
    }
    _mm512_store_si512(li.octant + b, _mm512_mullo_epi32(oct, _mm512_set1_epi32(stride)));
}

// prefetch_ahead8 for sixteen lanes.
template <class T>
LACUNA_AVX512 inline __attribute__((always_inline)) void prefetch_ahead16(
    const LaneGrid& g, const T* data, __m512 t, __m512 ox, __m512 oy, __m512 oz, __m512 dx,
    __m512 dy, __m512 dz, __mmask16 active) {
    const __m512 zero = _mm512_setzero_ps();
    const __m512 ta = _mm512_add_ps(t, _mm512_set1_ps(float(kPrefetchSteps) * g.dt));
    const __m512 x = _mm512_max_ps(
        zero, _mm512_min_ps(_mm512_set1_ps(g.hi[0]), _mm512_add_ps(ox, _mm512_mul_ps(ta, dx))));
    const __m512 y = _mm512_max_ps(
        zero, _mm512_min_ps(_mm512_set1_ps(g.hi[1]), _mm512_add_ps(oy, _mm512_mul_ps(ta, dy))));
    const __m512 z = _mm512_max_ps(
        zero, _mm512_min_ps(_mm512_set1_ps(g.hi[2]), _mm512_add_ps(oz, _mm512_mul_ps(ta, dz))));
    const __m512i off = _mm512_maskz_mov_epi32(
        active,
        _mm512_add_epi32(
            _mm512_add_epi32(_mm512_mullo_epi32(_mm512_cvttps_epi32(z), _mm512_set1_epi32(g.sz)),
                             _mm512_mullo_epi32(_mm512_cvttps_epi32(y), _mm512_set1_epi32(g.sy))),
            _mm512_cvttps_epi32(x)));
    alignas(64) int32_t o[16];
    _mm512_store_si512(o, off);
    // (addresses as integers: the diagonal row of the last cell lies past the volume's end,
    // which a prefetch may name but pointer arithmetic may not)
    const uintptr_t base = reinterpret_cast<uintptr_t>(data),
                    diag = (uintptr_t(g.sy) + g.sz) * sizeof(T);
    for (int l = 0; l < 16; ++l) {
        const uintptr_t a = base + uintptr_t(o[l]) * sizeof(T);
        __builtin_prefetch(reinterpret_cast<const void*>(a), 0, 3);
        __builtin_prefetch(reinterpret_cast<const void*>(a + diag), 0, 3);
    }
}

// Sixteen lanes, in kGroups groups of sixteen (Lanes holds 16 kGroups rays).
//
// Why two groups. A leaping lane's step is one dependency chain: k gives the sample's position,
// the position the leap-map entry (a gather), the entry the leap, the leap the next k. About a
// hundred cycles of latency, against some forty of throughput work hanging off it (corner
// loads, LUT loads, compositing); profiles put a quarter of the kernel's time on the instruction
// after the gather. Two groups of sixteen rays, stepped one after the other in one loop, are
// two independent chains, and the core overlaps one group's wait with the other's work. Each
// lane still performs exactly its own ray's operations in its own order, so the bits do not
// change (nothing is shared between lanes but the loop). The groups refill together: once a
// quarter of all lanes wait, or every active lane does.
template <bool kNearest, class T, bool kLeap>
struct Group16 {
    __m512 ox, oy, oz, dx, dy, dz, tb, ar, ag, ab, aa;
    __m512i kend, k, n, kcheck;
    __mmask16 active;

    LACUNA_AVX512 inline __attribute__((always_inline)) void load(const Lanes& s, int b,
                                                                  const LaneGrid& g,
                                                                  LeapInverse& li) {
        ox = _mm512_load_ps(s.ox + b), oy = _mm512_load_ps(s.oy + b), oz = _mm512_load_ps(s.oz + b);
        dx = _mm512_load_ps(s.dx + b), dy = _mm512_load_ps(s.dy + b), dz = _mm512_load_ps(s.dz + b);
        tb = _mm512_load_ps(s.t_base + b);
        kend = _mm512_load_si512(s.kend + b);
        active = _mm512_cmpneq_epi32_mask(_mm512_load_si512(s.active + b), _mm512_setzero_si512());
        k = _mm512_load_si512(s.k + b);
        n = _mm512_load_si512(s.n + b);
        if constexpr (kLeap) kcheck = _mm512_load_si512(s.kcheck + b);
        ar = _mm512_load_ps(s.r + b), ag = _mm512_load_ps(s.g + b), ab = _mm512_load_ps(s.b + b);
        aa = _mm512_load_ps(s.a + b);
        if constexpr (kLeap) leap_inverse16(dx, dy, dz, g.leap_octant, li, b);
    }
    LACUNA_AVX512 inline __attribute__((always_inline)) void store(Lanes& s, int b) const {
        _mm512_store_si512(s.kend + b, kend);
        _mm512_store_si512(s.k + b, k);
        _mm512_store_si512(s.n + b, n);
        if constexpr (kLeap) _mm512_store_si512(s.kcheck + b, kcheck);
        _mm512_store_ps(s.r + b, ar);
        _mm512_store_ps(s.g + b, ag);
        _mm512_store_ps(s.b + b, ab);
        _mm512_store_ps(s.a + b, aa);
    }
    // One sample (or one leap) per valid lane; returns the active lanes whose run is over.
    LACUNA_AVX512 inline __attribute__((always_inline)) __mmask16 step(
        const LaneGrid& g, const T* data, const float* lut, const LeapInverse& li, int b) {
        const __m512 zero = _mm512_setzero_ps(), half = _mm512_set1_ps(0.5f),
                     one = _mm512_set1_ps(1.f);
        const __m512i ione = _mm512_set1_epi32(1);
        const __mmask16 valid = _mm512_cmplt_epi32_mask(k, kend);
        const __m512 t = _mm512_add_ps(
            tb, _mm512_mul_ps(_mm512_add_ps(_mm512_cvtepi32_ps(k), half), _mm512_set1_ps(g.dt)));
        __m512 x = _mm512_add_ps(ox, _mm512_mul_ps(t, dx));
        __m512 y = _mm512_add_ps(oy, _mm512_mul_ps(t, dy));
        __m512 z = _mm512_add_ps(oz, _mm512_mul_ps(t, dz));
        x = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[0]), x));
        y = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[1]), y));
        z = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.hi[2]), z));
        __m512 v;
        if constexpr (kNearest) {
            const __m512i ni = _mm512_cvttps_epi32(_mm512_add_ps(x, half));
            const __m512i nj = _mm512_cvttps_epi32(_mm512_add_ps(y, half));
            const __m512i nk = _mm512_cvttps_epi32(_mm512_add_ps(z, half));
            const __m512i off = _mm512_maskz_mov_epi32(
                active,
                _mm512_add_epi32(_mm512_add_epi32(_mm512_mullo_epi32(nk, _mm512_set1_epi32(g.sz)),
                                                  _mm512_mullo_epi32(nj, _mm512_set1_epi32(g.sy))),
                                 ni));
            if constexpr (std::is_same_v<T, float>) {
                v = _mm512_i32gather_ps(off, reinterpret_cast<const float*>(data), 4);
            } else {
                alignas(64) int32_t ofs[16];
                alignas(64) float vals[16];
                _mm512_store_si512(ofs, off);
                nearest_values<T, 16>(data, ofs, vals);
                v = _mm512_load_ps(vals);
            }
        } else if constexpr (!kLeap) {
            v = trilinear16(g, data, x, y, z, active);
            prefetch_ahead16(g, data, t, ox, oy, oz, dx, dy, dz, active);
        }
        // Leaping: the lanes whose sample lies in an empty fine brick skip ahead instead; only
        // the others load their corners.
        //
        // Inside a box of fully visible bricks the leap test has nothing to skip, yet costs a
        // gather and some thirty instructions a step. So a test that finds a lane in a fully
        // visible brick also gives, from the leap map's inside distance, the first sample past
        // that box (kcheck); while every valid lane of the group is below its kcheck, the step
        // takes their samples without the test. Exactness does not depend on kcheck at all: a
        // sample taken without the test is the reference's own sample (a transparent one adds
        // exact zeros); only skips need the test, and those still go through leap16.
        __mmask16 taken = valid;
        __m512i adv = ione;
        if constexpr (kLeap) {
            leap16_outside(g, x, y, z, valid, li, b, k, kcheck, taken, adv);
            prefetch_ahead16(g, data, t, ox, oy, oz, dx, dy, dz, taken);
            v = leap_trilinear16(g, data, x, y, z, taken, active);
        }
        // A step on which every lane leaps composites nothing (their entries would be the
        // zero entry, which adds exact zeros): the LUT loads are skipped.
        if (!kLeap || taken) {
            __m512 u = _mm512_add_ps(_mm512_mul_ps(_mm512_sub_ps(v, _mm512_set1_ps(g.lut_offset)),
                                                   _mm512_set1_ps(g.lut_scale)),
                                     half);
            u = _mm512_max_ps(zero, _mm512_min_ps(_mm512_set1_ps(g.lut_last), u));
            const __m512i entry = _mm512_mask_blend_epi32(taken, _mm512_set1_epi32(g.zero_entry),
                                                          _mm512_cvttps_epi32(u));
            // RGBA of the 16 entries: sixteen 16-byte loads and a 4x4 transpose per 128-bit lane
            // (gathers cost ~1.4 cycles per element here; this is ~1.5 shuffles per sample). Lane j
            // of q4[i] holds lane 4j + i's entry, so the transpose leaves the channels in lane
            // order.
            alignas(64) int32_t e[16];
            _mm512_store_si512(e, entry);
            __m512 q4[4];
            for (int i = 0; i < 4; ++i) {
                __m512 r = _mm512_castps128_ps512(_mm_loadu_ps(lut + 4 * ptrdiff_t(e[i])));
                r = _mm512_insertf32x4(r, _mm_loadu_ps(lut + 4 * ptrdiff_t(e[4 + i])), 1);
                r = _mm512_insertf32x4(r, _mm_loadu_ps(lut + 4 * ptrdiff_t(e[8 + i])), 2);
                q4[i] = _mm512_insertf32x4(r, _mm_loadu_ps(lut + 4 * ptrdiff_t(e[12 + i])), 3);
            }
            const __m512 t0 = _mm512_unpacklo_ps(q4[0], q4[1]),
                         t1 = _mm512_unpackhi_ps(q4[0], q4[1]);
            const __m512 t2 = _mm512_unpacklo_ps(q4[2], q4[3]),
                         t3 = _mm512_unpackhi_ps(q4[2], q4[3]);
            const __m512 cr =
                _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(t0), _mm512_castps_pd(t2)));
            const __m512 cg =
                _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(t0), _mm512_castps_pd(t2)));
            const __m512 cb =
                _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(t1), _mm512_castps_pd(t3)));
            const __m512 ca =
                _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(t1), _mm512_castps_pd(t3)));
            const __m512 w = _mm512_sub_ps(one, aa);
            ar = _mm512_add_ps(ar, _mm512_mul_ps(w, cr));
            ag = _mm512_add_ps(ag, _mm512_mul_ps(w, cg));
            ab = _mm512_add_ps(ab, _mm512_mul_ps(w, cb));
            aa = _mm512_add_ps(aa, _mm512_mul_ps(w, ca));
        }
        n = _mm512_mask_add_epi32(n, taken, n, ione);
        if constexpr (kLeap)
            k = _mm512_min_epi32(_mm512_mask_add_epi32(k, valid, k, adv), kend);
        else
            k = _mm512_mask_add_epi32(k, valid, k, ione);
        const __mmask16 over = _mm512_cmpeq_epi32_mask(k, kend) |
                               _mm512_cmp_ps_mask(aa, _mm512_set1_ps(g.ert), _CMP_GE_OS);
        kend = _mm512_mask_mov_epi32(kend, over, k);  // a waiting lane takes no step
        return over & active;
    }
};

template <bool kNearest, class T, class Refill, bool kLeap = false, int kGroups = 1>
LACUNA_AVX512 void march_lanes16(Lanes& s, const LaneGrid& g, const T* data, const float* lut,
                                 Refill& refill) {
    static_assert(!(kLeap && kNearest), "leaping is for trilinear samples");
    static_assert(kGroups >= 1 && 16 * kGroups <= kMaxLanes);
    Group16<kNearest, T, kLeap> G[kGroups];
    LeapInverse linv;  // leaping: 1 / dir per lane
    uint32_t active = 0, waiting = 0;
    for (int i = 0; i < kGroups; ++i) {
        G[i].load(s, 16 * i, g, linv);
        active |= uint32_t(G[i].active) << (16 * i);
    }
    for (;;) {
#pragma GCC unroll 2
        for (int i = 0; i < kGroups; ++i)
            waiting |= uint32_t(G[i].step(g, data, lut, linv, 16 * i)) << (16 * i);
        // Waiting lanes, as in the AVX2 kernel: refill once a quarter of the lanes wait.
        if (__builtin_popcount(waiting) >= 4 * kGroups || waiting == active) {
            for (int i = 0; i < kGroups; ++i) G[i].store(s, 16 * i);
            if (!refill(waiting)) return;
            waiting = 0, active = 0;
            for (int i = 0; i < kGroups; ++i) {
                G[i].load(s, 16 * i, g, linv);
                active |= uint32_t(G[i].active) << (16 * i);
            }
        }
    }
}

#pragma GCC diagnostic pop

// ---- Ray set-up, eight pixels (AVX2) ------------------------------------------------------------
LACUNA_AVX2 inline void setup_rays8(const CameraView& c, const float* px, const float* py,
                                    const float inv_sp[3], const float hi[3], RayBatch8& out) {
    const __m256 one = _mm256_set1_ps(1.f), two = _mm256_set1_ps(2.f), half = _mm256_set1_ps(0.5f);
    const __m256 w = _mm256_set1_ps(c.width), h = _mm256_set1_ps(c.height);
    const __m256 aspect = _mm256_set1_ps(c.width / c.height), hh = _mm256_set1_ps(c.half_h);
    // sx = (2 * (px + 0.5) / W - 1) * aspect * half_h;  sy = (1 - 2 * (py + 0.5) / H) * half_h
    const __m256 sx = _mm256_mul_ps(
        _mm256_mul_ps(
            _mm256_sub_ps(
                _mm256_div_ps(_mm256_mul_ps(two, _mm256_add_ps(_mm256_loadu_ps(px), half)), w),
                one),
            aspect),
        hh);
    const __m256 sy = _mm256_mul_ps(
        _mm256_sub_ps(
            one, _mm256_div_ps(_mm256_mul_ps(two, _mm256_add_ps(_mm256_loadu_ps(py), half)), h)),
        hh);
    __m256 o[3], d[3];
    for (int a = 0; a < 3; ++a) {
        const __m256 r = _mm256_set1_ps(c.right[a]), u = _mm256_set1_ps(c.up[a]);
        if (c.ortho) {
            o[a] = _mm256_add_ps(_mm256_add_ps(_mm256_set1_ps(c.eye[a]), _mm256_mul_ps(r, sx)),
                                 _mm256_mul_ps(u, sy));
            d[a] = _mm256_set1_ps(c.forward[a]);
        } else {
            o[a] = _mm256_set1_ps(c.eye[a]);
            d[a] = _mm256_add_ps(_mm256_add_ps(_mm256_set1_ps(c.forward[a]), _mm256_mul_ps(r, sx)),
                                 _mm256_mul_ps(u, sy));
        }
    }
    if (!c.ortho) {  // normalize: v / sqrt(x*x + y*y + z*z)
        const __m256 len = _mm256_sqrt_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(d[0], d[0]), _mm256_mul_ps(d[1], d[1])),
                          _mm256_mul_ps(d[2], d[2])));
        for (int a = 0; a < 3; ++a) d[a] = _mm256_div_ps(d[a], len);
    }
    _mm256_store_ps(out.wx, d[0]), _mm256_store_ps(out.wy, d[1]), _mm256_store_ps(out.wz, d[2]);
    __m256 t0 = _mm256_setzero_ps(), t1 = _mm256_set1_ps(__builtin_inff());
    __m256 miss = _mm256_setzero_ps();
    for (int a = 0; a < 3; ++a) {
        o[a] = _mm256_mul_ps(o[a], _mm256_set1_ps(inv_sp[a]));
        d[a] = _mm256_mul_ps(d[a], _mm256_set1_ps(inv_sp[a]));
        const __m256 vhi = _mm256_set1_ps(hi[a]);
        const __m256 flat = _mm256_cmp_ps(d[a], _mm256_setzero_ps(), _CMP_EQ_OQ);
        // d == 0: a miss if the origin lies outside [0, hi] on this axis; no slab otherwise.
        miss = _mm256_or_ps(
            miss,
            _mm256_and_ps(flat, _mm256_or_ps(_mm256_cmp_ps(o[a], _mm256_setzero_ps(), _CMP_LT_OQ),
                                             _mm256_cmp_ps(o[a], vhi, _CMP_GT_OQ))));
        const __m256 inv = _mm256_div_ps(one, d[a]);
        const __m256 ta = _mm256_mul_ps(_mm256_sub_ps(_mm256_setzero_ps(), o[a]), inv);
        const __m256 tb = _mm256_mul_ps(_mm256_sub_ps(vhi, o[a]), inv);
        const __m256 sw = _mm256_cmp_ps(ta, tb, _CMP_GT_OQ);
        const __m256 lo = _mm256_blendv_ps(ta, tb, sw), up = _mm256_blendv_ps(tb, ta, sw);
        // t0 = std::max(t0, lo) = t0 < lo ? lo : t0;  t1 = std::min(t1, up) = up < t1 ? up : t1
        t0 = _mm256_blendv_ps(t0, _mm256_blendv_ps(t0, lo, _mm256_cmp_ps(t0, lo, _CMP_LT_OQ)),
                              _mm256_xor_ps(flat, _mm256_castsi256_ps(_mm256_set1_epi32(-1))));
        t1 = _mm256_blendv_ps(t1, _mm256_blendv_ps(t1, up, _mm256_cmp_ps(up, t1, _CMP_LT_OQ)),
                              _mm256_xor_ps(flat, _mm256_castsi256_ps(_mm256_set1_epi32(-1))));
    }
    const __m256 hit = _mm256_andnot_ps(miss, _mm256_cmp_ps(t0, t1, _CMP_LT_OQ));
    _mm256_store_ps(out.ox, o[0]), _mm256_store_ps(out.oy, o[1]), _mm256_store_ps(out.oz, o[2]);
    _mm256_store_ps(out.dx, d[0]), _mm256_store_ps(out.dy, d[1]), _mm256_store_ps(out.dz, d[2]);
    _mm256_store_ps(out.t_near, t0), _mm256_store_ps(out.t_far, t1);
    _mm256_store_si256(reinterpret_cast<__m256i*>(out.hit), _mm256_castps_si256(hit));
}

#endif  // LACUNA_SIMD_X86

}  // namespace lacuna::simd
