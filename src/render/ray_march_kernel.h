// The ray-marching sample loop, templated on the voxel type so the hot loop sees one concrete
// type (STYLE.md habit 2). No allocation, no virtual calls, no exceptions inside.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "accel/region.h"
#include "lacuna/transfer_function.h"

#if defined(__GNUC__)
#define LACUNA_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define LACUNA_ALWAYS_INLINE inline
#endif

namespace lacuna::kernel {

// Everything a sample needs, in index space. Index is the type of voxel offsets: int32_t for
// grids under 2^31 voxels (vectorises well), int64_t above.
template <class T, class Index = int32_t>
struct Grid {
    const T* data;
    ptrdiff_t sy, sz;            // strides of j and k (i has stride 1)
    float hi_x, hi_y, hi_z;      // dims - 1 (the sampled box is [0, hi])
    int cell_x, cell_y, cell_z;  // dims - 2: largest cell index
};

// The grid of a volume's voxels (`dims` has .x, .y, .z), x fastest.
template <class Index = int32_t, class T, class D>
inline Grid<T, Index> make_grid(const T* data, const D& dims) {
    return Grid<T, Index>{data,
                          ptrdiff_t(dims.x),
                          ptrdiff_t(dims.x) * ptrdiff_t(dims.y),
                          float(dims.x - 1),
                          float(dims.y - 1),
                          float(dims.z - 1),
                          dims.x - 2,
                          dims.y - 2,
                          dims.z - 2};
}

// Trilinear interpolation at index-space point (x,y,z), clamped into the box so rounding at
// the box faces never reads outside the grid. The result lies between the min and max of the
// cell's 8 corners (for integer voxel types exactly; see docs/architecture.md for float32).
template <class T, class Index>
inline float trilinear(const Grid<T, Index>& g, float x, float y, float z) {
    x = std::clamp(x, 0.f, g.hi_x);
    y = std::clamp(y, 0.f, g.hi_y);
    z = std::clamp(z, 0.f, g.hi_z);
    const int i = std::min(int(x), g.cell_x), j = std::min(int(y), g.cell_y),
              k = std::min(int(z), g.cell_z);
    const float fx = x - float(i), fy = y - float(j), fz = z - float(k);
    const T* p = g.data + (ptrdiff_t(k) * g.sz + ptrdiff_t(j) * g.sy + i);
    const float c000 = float(p[0]), c100 = float(p[1]);
    const float c010 = float(p[g.sy]), c110 = float(p[g.sy + 1]);
    const float c001 = float(p[g.sz]), c101 = float(p[g.sz + 1]);
    const float c011 = float(p[g.sz + g.sy]), c111 = float(p[g.sz + g.sy + 1]);
    const float c00 = c000 + fx * (c100 - c000), c10 = c010 + fx * (c110 - c010);
    const float c01 = c001 + fx * (c101 - c001), c11 = c011 + fx * (c111 - c011);
    const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
}

// Nearest-neighbour sampling at index-space point (x,y,z): clamped into the box as trilinear()
// does, then the voxel floor(x + 0.5) per axis, in float (x + 0.5f rounds; int() truncates a
// non-negative value). Always a corner of the cell trilinear() would use, so every structure's
// per-cell ranges cover it (lacuna/accel.h, Interpolation).
template <class T, class Index>
inline float nearest(const Grid<T, Index>& g, float x, float y, float z) {
    x = std::clamp(x, 0.f, g.hi_x);
    y = std::clamp(y, 0.f, g.hi_y);
    z = std::clamp(z, 0.f, g.hi_z);
    const int i = int(x + 0.5f), j = int(y + 0.5f), k = int(z + 0.5f);
    return float(g.data[ptrdiff_t(k) * g.sz + ptrdiff_t(j) * g.sy + i]);
}

// The value of a sample under either interpolation.
template <bool kNearest, class T, class Index>
inline float sample(const Grid<T, Index>& g, float x, float y, float z) {
    if constexpr (kNearest)
        return nearest(g, x, y, z);
    else
        return trilinear(g, x, y, z);
}

// Front-to-back accumulation state of one ray (premultiplied colour).
struct Accum {
    float r = 0, g = 0, b = 0, a = 0;
};

// The index-space ray (accel/region.h).
using lacuna::IndexRay;

// Slab test of a ray against the index-space box [0, hi]. Returns false on a miss. Every
// consumer that must reproduce the reference's lattice (the marcher, the sample analysis) calls
// this one function, so t_near and t_far agree to the bit.
inline bool intersect_box(const IndexRay& r, const float hi[3], float& t0, float& t1) {
    t0 = 0.f;
    t1 = INFINITY;
    const float o[3] = {r.ox, r.oy, r.oz}, d[3] = {r.dx, r.dy, r.dz};
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.f) {
            if (o[a] < 0.f || o[a] > hi[a]) return false;
            continue;
        }
        const float inv = 1.f / d[a];
        float ta = (0.f - o[a]) * inv, tb = (hi[a] - o[a]) * inv;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 < t1;
}

// The sample stream of one ray: the lattice samples t_k = t_base + (k + 0.5)*dt of any number
// of runs [kb, ke), evaluated kBatch at a time *across run boundaries*, then composited front to
// back in k order with early termination at `ert`.
//
// Why a stream. Skipping splits a ray into a few short runs; a kernel that starts afresh per run
// runs its full batches only while kBatch samples remain and takes the rest one at a time, which
// on a head is a third to half of the surviving samples. Here a run only appends its indices; a
// batch is evaluated when kBatch indices are queued, whichever runs they came from, and the ray's
// last partial batch is padded (its extra lanes repeat the last index and are never composited).
//
// Every sample's position comes from its own k, with the arithmetic of trilinear() (same IEEE
// operations in the same order, no fma contraction, plain loops), so the result is that of one
// sample at a time, to the bit,
// however the runs fall. Samples of a batch past an early termination are computed but never
// composited or counted.
inline constexpr int kBatch = 8;

// The one-ray-at-a-time reference path (LACUNA_ISA=scalar, and volumes of 2^31 voxels or more);
// the SIMD paths run several rays per instruction instead (core/simd_lanes.h).
template <class T, class Index, bool kNearest = false>
class RayStream {
  public:
    RayStream(const Grid<T, Index>& g, const IndexRay& r, float t_base, float dt, const Rgba* lut,
              ValueToLut map, float ert, Accum& acc)
        : m_g(g),
          m_r(r),
          m_t_base(t_base),
          m_dt(dt),
          m_lut(lut),
          m_map(map),
          m_ert(ert),
          m_acc(acc) {}

    // Queues the samples [kb, ke) (after every sample queued before); false once the ray is
    // opaque, when further samples would be discarded.
    LACUNA_ALWAYS_INLINE bool add(int kb, int ke) {
        while (kb < ke) {
            const int take = std::min(ke - kb, kBatch - m_m);
            for (int l = 0; l < take; ++l) m_k[m_m + l] = int32_t(kb + l);
            m_m += take;
            kb += take;
            if (m_m == kBatch && !flush()) return false;
        }
        return !m_done;
    }
    // Evaluates what is still queued.
    LACUNA_ALWAYS_INLINE void finish() {
        if (m_m > 0 && !m_done) flush();
        m_m = 0;
    }
    uint32_t samples() const { return m_n; }
    bool done() const { return m_done; }

  private:
    // Evaluates the m_m queued samples (padding the batch), composites them; false when opaque.
    LACUNA_ALWAYS_INLINE bool flush() {
        for (int l = m_m; l < kBatch; ++l) m_k[l] = m_k[m_m - 1];
        int entry[kBatch];
        lut_entries(entry);
        const int m = m_m;
        m_m = 0;
        // The accumulators in locals: the compositing chain stays in registers even where the
        // compiler keeps flush() out of line.
        Accum a = m_acc;
        int l = 0;
        bool opaque = false;
        while (l < m) {
            const Rgba& c = m_lut[entry[l]];
            ++l;
            const float w = 1.f - a.a;
            a.r += w * c.r;
            a.g += w * c.g;
            a.b += w * c.b;
            a.a += w * c.a;
            if (a.a >= m_ert) {
                opaque = true;
                break;
            }
        }
        m_acc = a;
        m_n += uint32_t(l);
        m_done = opaque;
        return !opaque;
    }

    // LUT entries of the kBatch queued samples.
    LACUNA_ALWAYS_INLINE void lut_entries(int* entry) const {
        const Grid<T, Index>& g = m_g;
        const IndexRay& r = m_r;
        float fx[kBatch], fy[kBatch], fz[kBatch];
        Index off[kBatch];
        // 1. Lattice positions, clamped into the box; cell index and fractions (nearest: the
        // voxel floor(p + 0.5) and its LUT entry, nearest()'s operations, and nothing more).
        {
            for (int l = 0; l < kBatch; ++l) {
                const float t = m_t_base + (float(m_k[l]) + 0.5f) * m_dt;
                float x = r.ox + t * r.dx, y = r.oy + t * r.dy, z = r.oz + t * r.dz;
                x = x < 0.f ? 0.f : (x > g.hi_x ? g.hi_x : x);
                y = y < 0.f ? 0.f : (y > g.hi_y ? g.hi_y : y);
                z = z < 0.f ? 0.f : (z > g.hi_z ? g.hi_z : z);
                if constexpr (kNearest) {
                    const Index o = Index(int(z + 0.5f)) * Index(g.sz) +
                                    Index(int(y + 0.5f)) * Index(g.sy) + Index(int(x + 0.5f));
                    entry[l] = m_map(float(g.data[o]));
                    continue;
                }
                int i = int(x), j = int(y), k = int(z);
                i = i < g.cell_x ? i : g.cell_x;
                j = j < g.cell_y ? j : g.cell_y;
                k = k < g.cell_z ? k : g.cell_z;
                fx[l] = x - float(i);
                fy[l] = y - float(j);
                fz[l] = z - float(k);
                off[l] = Index(k) * Index(g.sz) + Index(j) * Index(g.sy) + Index(i);
            }
        }
        if constexpr (kNearest) return;
        // 2. The 8 corners of each sample's cell.
        float c000[kBatch], c100[kBatch], c010[kBatch], c110[kBatch], c001[kBatch], c101[kBatch],
            c011[kBatch], c111[kBatch];
        for (int l = 0; l < kBatch; ++l) {
            const T* p = g.data + off[l];
            c000[l] = float(p[0]);
            c100[l] = float(p[1]);
            c010[l] = float(p[g.sy]);
            c110[l] = float(p[g.sy + 1]);
            c001[l] = float(p[g.sz]);
            c101[l] = float(p[g.sz + 1]);
            c011[l] = float(p[g.sz + g.sy]);
            c111[l] = float(p[g.sz + g.sy + 1]);
        }
        // 3. Trilinear interpolation and the LUT entry.
        {
            for (int l = 0; l < kBatch; ++l) {
                const float c00 = c000[l] + fx[l] * (c100[l] - c000[l]);
                const float c10 = c010[l] + fx[l] * (c110[l] - c010[l]);
                const float c01 = c001[l] + fx[l] * (c101[l] - c001[l]);
                const float c11 = c011[l] + fx[l] * (c111[l] - c011[l]);
                const float c0 = c00 + fy[l] * (c10 - c00), c1 = c01 + fy[l] * (c11 - c01);
                entry[l] = m_map(c0 + fz[l] * (c1 - c0));
            }
        }
    }

    const Grid<T, Index>& m_g;
    IndexRay m_r;
    float m_t_base, m_dt;
    const Rgba* m_lut;
    ValueToLut m_map;
    float m_ert;
    Accum& m_acc;
    int32_t m_k[kBatch];
    int m_m = 0;
    uint32_t m_n = 0;
    bool m_done = false;
};

// Marches the samples k in [k0, k1) on their own (one run of a stream). Returns the number of
// samples taken; sets `done` once opacity reaches `ert`.
template <class T, class Index, bool kNearest = false>
inline uint32_t march(const Grid<T, Index>& g, const IndexRay& r, float t_base, float dt, int k0,
                      int k1, const Rgba* lut, ValueToLut map, float ert, Accum& acc, bool& done) {
    RayStream<T, Index, kNearest> s(g, r, t_base, dt, lut, map, ert, acc);
    s.add(k0, k1);
    s.finish();
    done = done || s.done();
    return s.samples();
}

}  // namespace lacuna::kernel
