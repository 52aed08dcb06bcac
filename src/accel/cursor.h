// The one generic ray cursor (STYLE.md habit 1): turns a structure's Region answers into the
// stretches [t0, t1] of a ray that may hold visible samples, front to back.
//
// Exactness argument. The cursor only ever removes open intervals (s0, s1) that lie strictly
// inside an empty region's box, shrunk by kMargin voxels on every side that has a neighbour
// cell; positions computed in float for any t there stay inside the box (float error <<
// kMargin), so their trilinear cell is one of the region's empty cells. A face on the grid's
// border needs no margin: the sampler clamps positions into the grid, so a position past that
// face still reads the border cell, which is the region's. (Without this, every ray kept about
// one sample at each end of the volume even when the whole volume is empty.) Everything else of
// [t_near, t_far] is returned, so the ray marcher (which rounds segments outward to lattice
// samples) takes every sample the reference takes that could be visible. How the cursor walks
// (nudges, minimum advances) affects speed, never the image.
#pragma once
#include <algorithm>
#include <cmath>

#include "accel/region.h"

namespace lacuna {

struct Segment {
    float t0, t1;  // world ray parameters; samples outside all segments are provably invisible
};

// Structure S provides: Region region(const int cell[3], int& hint) const;  and
// const int* cells() const (cells per axis, dims - 1).
template <class S>
class RegionCursor {
  public:
    static constexpr float kMargin = 0.05f;  // voxels

    // min_skip: empty stretches shorter than this (world units) are not cut out; the renderer
    // passes about one sample spacing, below which a cut saves no sample but splits a segment.
    //
    // chunk: an occupied stretch is handed out once it is this long (world units; 0 = only at
    // the next empty region or the ray's end). The marcher may stop early (early ray
    // termination), and walking the structure far beyond where it stops costs region queries
    // for nothing: through a head, every leaf up to the far side.
    RegionCursor(const S& s, const IndexRay& r, float t_near, float t_far, float min_skip = 0.f,
                 float chunk = 0.f)
        : m_s(s),
          m_r(r),
          m_t(t_near),
          m_far(t_far),
          m_seg_start(t_near),
          m_min_skip(min_skip),
          m_chunk(chunk > 0.f ? chunk : INFINITY) {
        float dmax = 0;
        for (int a = 0; a < 3; ++a) dmax = std::max(dmax, std::abs(r.d(a)));
        m_margin_t = kMargin / dmax;
        m_nudge_t = 1e-3f / dmax;
        const int* n = s.cells();
        for (int a = 0; a < 3; ++a) {
            m_hi[a] = float(n[a]);
            m_cells[a] = n[a];
            m_last[a] = n[a] - 1;
            m_inv[a] = r.d(a) == 0.f ? 0.f : 1.f / r.d(a);
        }
    }

    // Next stretch that may hold visible samples; false when the ray is done.
    bool next(Segment& out) {
        while (m_t < m_far) {
            // 1. The cell just past the current parameter (clamped like the sampler clamps).
            const float tq = m_t + m_nudge_t;
            int cell[3];
            for (int a = 0; a < 3; ++a) {
                float p = m_r.o(a) + tq * m_r.d(a);
                p = p < 0.f ? 0.f : (p > m_hi[a] ? m_hi[a] : p);
                cell[a] = std::min(int(p), m_last[a]);
            }
            // 2. Ask the structure; intersect the ray with the region's box.
            const Region reg = m_s.region(cell, m_hint);
            // A face on the grid border is never crossed into another cell (positions clamp):
            // its parameter is -inf (entry) or +inf (exit).
            float ta = -INFINITY, tb = INFINITY;
            for (int a = 0; a < 3; ++a) {
                if (m_r.d(a) == 0.f) continue;
                const bool up = m_r.d(a) > 0.f;
                const float t_lo = reg.box.lo[a] <= 0
                                       ? (up ? -INFINITY : INFINITY)
                                       : (float(reg.box.lo[a]) - m_r.o(a)) * m_inv[a];
                const float t_hi = reg.box.hi[a] >= m_cells[a]
                                       ? (up ? INFINITY : -INFINITY)
                                       : (float(reg.box.hi[a]) - m_r.o(a)) * m_inv[a];
                ta = std::max(ta, std::min(t_lo, t_hi));
                tb = std::min(tb, std::max(t_lo, t_hi));
            }
            const float t_next = std::max(tb, m_t + m_nudge_t);
            // 3. Empty: cut the interval strictly inside the box out of the ray.
            if (reg.empty) {
                const float s0 = std::min(std::max(ta + m_margin_t, m_t), m_far);
                const float s1 = tb - m_margin_t;
                m_t = t_next;
                if (s1 - s0 > m_min_skip) {
                    const Segment seg{m_seg_start, s0};
                    m_seg_start = s1;
                    if (seg.t1 > seg.t0) {
                        out = seg;
                        return true;
                    }
                }
                continue;
            }
            // 4. Occupied: march on through it; hand out a long enough stretch now.
            m_t = t_next;
            if (m_t - m_seg_start >= m_chunk && m_t < m_far) {
                out = {m_seg_start, m_t};
                m_seg_start = m_t;
                return true;
            }
        }
        if (m_done) return false;
        m_done = true;
        out = {m_seg_start, m_far};
        return out.t1 > out.t0;
    }

  private:
    const S& m_s;
    IndexRay m_r;
    float m_t, m_far, m_seg_start;
    float m_min_skip, m_chunk;
    float m_margin_t, m_nudge_t;
    float m_hi[3], m_inv[3];
    int m_last[3], m_cells[3];
    int m_hint = -1;
    bool m_done = false;
};

}  // namespace lacuna
