// --accel grid: a flat per-TF occupancy grid of bricks, walked by a two-level 3D DDA
// (Amanatides & Woo; the shape of pbrt-v4's DDAMajorantIterator and NanoVDB's HDDA).
//
// Why. The octrees answer "which region is the ray in" with a descent and six slab tests per
// region; on a head that is 6-9 queries a ray, each costing several samples' worth of time. A
// grid needs none of that: the next brick is the neighbour across the nearest of three planes,
// so a step is a compare, a subtract and a multiply, and the occupancy test is one bit.
//
// TF-independent part (built once per volume): per brick of B^3 cells (B = --leaf, 8) the
// LUT-entry range of its cells *and a one-cell apron* around them (apron_brick_ranges). Per TF:
// one bit per brick, whether [lo, hi] holds a visible entry (the min-max octree's prefix-count
// test, as one lookup: the first visible entry at or after lo is <= hi), packed in blocks of
// 4x4x4 bricks per uint64 (a zero word is an empty block: the DDA's coarse level, free),
// and per block the Chebyshev distance (in blocks) to the nearest block with a visible brick: in
// empty space the walk leaps out of the whole cube of empty blocks that distance guarantees
// (Deakin & Knackstedt's distance maps, on the block grid: a few thousand entries, so the map is
// recomputed with every TF in microseconds).
//
// Nearest sampling (AccelOptions::interpolation). A sample reads the voxel floor(p + 0.5); at
// any t the walk attributes to brick b, p lies within less than a voxel of b's box, so that voxel
// is one of the apron's voxels [B*b - 1, B*b + B + 1]. Built for Nearest, a brick also keeps the
// set of 64 LUT-entry bins those voxels fall in (bin = entry * 64 / lut size), and is occupied
// only if its range holds a visible entry *and* one of its bins holds one: value sets with holes,
// as in the bitfield paper, so an edge between dark and bright tissue skips a visible band of
// values in between.
//
// Exactness argument. Samples are skipped only in stretches of the ray that the DDA attributes to
// empty bricks, minus the outward rounding of for_each_lattice_run (every skipped sample lies more
// than one sample spacing inside such a stretch). The DDA computes every plane crossing directly
// as (plane - o) / d (never by accumulating t), so its crossing times are within a few ulps of
// the exact ones, and the sampler's positions o + t*d are within a few ulps of the exact ray: at
// any t the DDA attributes to brick b, the sampler's position is within far less than one voxel of
// b's box, hence its trilinear cell is one of b's cells or of its apron. An empty brick's apron
// range is invisible, so every skipped sample has TF opacity exactly zero. No margins, no nudges:
// the apron absorbs float disagreement, including rays that graze a corner shared by bricks the
// float walk and the exact ray order differently. (Faces on the grid border are never crossed:
// positions clamp into the border cells, which are the border brick's.)
#pragma once
#include <climits>
#include <cmath>
#include <cstdint>
#include <vector>

#include "accel/octree_base.h"

namespace lacuna {

class BrickGrid final : public OctreeBase {
  public:
    BrickGrid(const Volume& v, const AccelOptions& o);
    void set_transfer_function(const TransferLut& lut) override;
    // The fine level: the visible-cell mask of the current TF (visible_cell_mask in
    // accel/cell_ranges.h), over the cells of occupied bricks.
    void refine() override;
    // The mask once refine() has run for the current TF, else nullptr (the kernels then take
    // every sample of a run).
    const uint32_t* cell_mask() const { return m_mask_ready ? m_mask.data() : nullptr; }
    // Also made by refine(): the leap map, eight maps of one 16-bit entry per fine brick of 4^3
    // cells (kLeapLog2), octant-major (entry o * leap_octant_stride() + brick), x fastest over
    // leap_dims(), one entry of padding (the lane kernels read 32-bit words); nullptr until
    // refine() ran for the current TF. Octant o is the rays whose dir_a < 0 exactly for the axes
    // a of o's set bits (bit 0 x, 1 y, 2 z).
    //   low byte d: 0 if the brick's range with the bricks' one-cell apron may read a visible
    //     entry (in every octant), else the largest d (capped at 255) for which every brick of
    //     the box reaching d - 1 bricks from b toward the octant, per axis [b_a, b_a + d - 1],
    //     or [b_a - d + 1, b_a] where o's bit a is set, is empty (bricks past the grid are
    //     empty). A ray of that octant at a point of brick b with d >= 1 may skip every sample
    //     before it leaves that box: it cannot reach the bricks behind it, all ahead are empty,
    //     and float error is absorbed by the apron (core/simd_lanes.h, "Leaping").
    //   high byte, where d = 0: bit sx + 2 sy + 4 sz set iff the sub-brick of 2^3 cells at
    //     (sx, sy, sz) in b, with its own one-cell apron (cells 4b + 2s - 1 .. 4b + 2s + 2 per
    //     axis), holds a cell of the visible-cell mask (bits of sub-bricks past the grid, which
    //     hold no sample's cell, are free). A ray in a clear sub-brick may skip every sample
    //     before it leaves that sub-brick, by the same argument.
    //   Where every sub-brick is set (high byte 0xff, "fully visible"), the low byte is instead
    //     the inside distance: the largest e for which every brick of the box reaching e - 1
    //     bricks toward the octant is fully visible (bricks past the grid are not; so e >= 1).
    //     Nothing is skipped there; the leaping kernels take the box's samples without testing
    //     each one (core/simd_lanes.h, Group16). So a reader skips on d >= 1 only below 0xff.
    static constexpr int kLeapLog2 = 2;
    const uint16_t* leap_map() const { return m_mask_ready ? m_leap.data() : nullptr; }
    const int* leap_dims() const { return m_nf; }
    size_t leap_octant_stride() const {
        return size_t(m_nf[0]) * size_t(m_nf[1]) * size_t(m_nf[2]);
    }

    // Also made by refine(): the occupied bricks that have an unoccupied brick (or the grid's
    // border) among their 26 neighbours, as runs along x: bricks x0..x1 of row (y, z). A ray
    // from an eye outside the grid that comes within a brick of an occupied brick's box first
    // comes that close to one of these (render/screen_cover.h has the argument), so their boxes
    // alone bound the pixels whose rays can meet a visible sample. nullptr until refine() ran
    // for the current TF.
    struct BrickRun {
        uint16_t x0, x1, y, z;
    };
    const std::vector<BrickRun>* surface_runs() const {
        return m_mask_ready ? &m_surface : nullptr;
    }

    int brick_log2() const { return m_log2; }
    const int* bricks() const { return m_nb; }
    // Bit of brick (x, y, z) in its block's word.
    bool occupied(int x, int y, int z) const { return (word(x, y, z) >> bit(x, y, z)) & 1u; }
    uint64_t word(int x, int y, int z) const { return m_words[block_index(x, y, z)]; }
    // The block (word) holding brick (x, y, z), and its distance to the nearest occupied block.
    size_t block_index(int x, int y, int z) const {
        return (size_t(z >> 2) * m_nw[1] + size_t(y >> 2)) * m_nw[0] + size_t(x >> 2);
    }
    int block_distance(int x, int y, int z) const { return m_dist[block_index(x, y, z)]; }
    static int bit(int x, int y, int z) { return (x & 3) | (y & 3) << 2 | (z & 3) << 4; }
    // Brick (x, y, z)'s apron-inclusive LUT-entry range (tests).
    void brick_range(int x, int y, int z, int& lo, int& hi) const;
    // Built for Nearest: the bins (entry * 64 / lut size) of its apron voxels; else all (tests).
    uint64_t brick_bins(int x, int y, int z) const {
        return m_bins.empty() ? ~uint64_t(0) : m_bins[slot(x, y, z)];
    }

    // The generic Region answer for the brick holding `cell` (RegionCursor users, MIP windows).
    Region region(const int cell[3], int&) const {
        const int b[3] = {cell[0] >> m_log2, cell[1] >> m_log2, cell[2] >> m_log2};
        return {brick_box(b), !occupied(b[0], b[1], b[2])};
    }
    // MIP/MinIP skipping (src/accel/entry_window.h): empty when the brick's range misses [lo, hi].
    Region region_outside(const int cell[3], int&, int lo, int hi) const {
        const int b[3] = {cell[0] >> m_log2, cell[1] >> m_log2, cell[2] >> m_log2};
        const size_t i = slot(b[0], b[1], b[2]);
        return {brick_box(b), int(m_hi[i]) < lo || int(m_lo[i]) > hi};
    }

    class Cursor;

  private:
    void build();
    void compute_distances();
    size_t slot(int x, int y, int z) const {
        return ((size_t(z >> 2) * m_nw[1] + size_t(y >> 2)) * m_nw[0] + size_t(x >> 2)) * 64 +
               size_t(bit(x, y, z));
    }
    CellBox brick_box(const int b[3]) const {
        CellBox box;
        for (int a = 0; a < 3; ++a) {
            box.lo[a] = b[a] << m_log2;
            box.hi[a] = std::min((b[a] + 1) << m_log2, m_pyr.cells[a]);
        }
        return box;
    }
    int m_log2 = 3;
    int m_nb[3] = {0, 0, 0};  // bricks per axis
    int m_nw[3] = {0, 0, 0};  // blocks (words) per axis
    // Apron ranges in block order (slot()); bricks past the grid hold the empty range {1, 0}.
    std::vector<uint16_t> m_lo, m_hi;
    std::vector<uint64_t> m_words;
    std::vector<uint16_t> m_block_lo, m_block_hi;  // per block: union of its bricks' ranges
    std::vector<uint8_t> m_dist;  // per block: Chebyshev distance to an occupied block, 1..255
    std::vector<uint16_t> m_next_visible;    // per LUT entry: the first visible entry >= it
    std::vector<uint16_t> m_next_invisible;  // per LUT entry: the first invisible entry >= it
    // Built for Interpolation::Nearest: per brick (slot order) the set of 64 LUT-entry bins of its
    // apron voxels, and the bins of the TF's visible entries (see build_nearest_bins).
    std::vector<uint64_t> m_bins;
    uint64_t m_tf_bins = 0;
    void build_nearest_bins();
    std::vector<uint32_t> m_mask;
    bool m_mask_ready = false;
    std::vector<uint16_t> m_fine_lo, m_fine_hi;  // apron ranges of the fine bricks (leap map)
    int m_nf[3] = {0, 0, 0};
    std::vector<uint16_t> m_leap;
    std::vector<BrickRun> m_surface;
    void find_surface();
};

// Front-to-back walk of one ray through the grid; hands out the stretches that may hold visible
// samples (the RegionCursor interface). step() is the walk as the exactness argument states it
// (and as the tests inspect it); next() takes its brick steps through brick_run(), the same walk
// with the state in registers, tested to hand out the same stretches to the bit. Empty blocks
// are left in one leap.
class BrickGrid::Cursor {
  public:
    // min_skip: empty stretches not longer than this stay in the run (world units). chunk: an
    // occupied stretch is handed out once this long (0 = never), so early ray termination does
    // not pay for walking to the far side.
    Cursor(const BrickGrid& g, const IndexRay& r, float t_near, float t_far, float min_skip = 0.f,
           float chunk = 0.f)
        : m_g(g),
          m_t(t_near),
          m_far(t_far),
          m_min_skip(min_skip),
          m_chunk(chunk > 0.f ? chunk : INFINITY) {
        const int L = g.m_log2;
        for (int a = 0; a < 3; ++a) {
            m_o[a] = r.o(a);
            m_d[a] = r.d(a);
            m_inv[a] = r.d(a) == 0.f ? 0.f : 1.f / r.d(a);
            m_cells[a] = g.m_pyr.cells[a];
            m_nbm1[a] = g.m_nb[a] - 1;
            // Branch-free brick crossings: the exit plane of brick n is (n + m_up) << L, and it
            // is the border (never crossed: +inf) when it is <= m_lo_lim or >= m_hi_lim.
            const bool up = r.d(a) > 0.f, down = r.d(a) < 0.f;
            m_up[a] = up ? 1 : 0;
            m_step[a] = up ? 1 : -1;
            m_lo_lim[a] = up ? INT32_MIN : (down ? 0 : INT32_MAX);
            m_hi_lim[a] = up ? m_cells[a] : INT32_MAX;
            float p = m_o[a] + t_near * m_d[a];
            p = p < 0.f ? 0.f : (p > float(m_cells[a]) ? float(m_cells[a]) : p);
            m_b[a] = std::min(int(p) >> L, m_nbm1[a]);
        }
        for (int a = 0; a < 3; ++a) m_next[a] = crossing(a, m_b[a], L);
        const int64_t stride[3] = {1, g.m_nw[0], int64_t(g.m_nw[0]) * g.m_nw[1]};
        for (int a = 0; a < 3; ++a) {
            m_blk_delta[a] = m_step[a] * stride[a];
            m_bit_delta[a] = m_step[a] << (2 * a);
            m_bit_wrap[a] = m_step[a] > 0 ? -(3 << (2 * a)) : (3 << (2 * a));
        }
        locate();
    }

    // One step of the walk: the stretch [t0, t1] of the ray in the bricks lo..hi (inclusive):
    // one brick, or for a leap the cube of empty blocks around the ray's block. False once the
    // ray is done.
    struct Step {
        float t0, t1;
        int lo[3], hi[3];
        bool occupied, coarse;
    };
    // kBox: also report the step's brick box (tests); the renderer's walk skips that work.
    template <bool kBox = true>
    bool step(Step& s) {
        if (!(m_t < m_far)) return false;
        const int L = m_g.m_log2;
        const size_t blk = size_t(m_blk);
        const uint64_t w = m_g.m_words[blk];
        int a;
        float t_exit;
        s.coarse = w == 0;
        if (s.coarse) {
            // Every block within Chebyshev distance r - 1 of this one is empty: leave that cube
            // through its nearest face.
            const int r = m_g.m_dist[blk];
            int lo[3], hi[3];
            float tb[3];
            for (int c = 0; c < 3; ++c) {
                const int B = m_b[c] >> 2;
                lo[c] = B - r + 1;
                hi[c] = B + r;  // exclusive, in blocks
                tb[c] = leap_crossing(c, lo[c], hi[c], L + 2);
                s.lo[c] = std::max(0, lo[c] << 2);
                s.hi[c] = std::min(m_nbm1[c], (hi[c] << 2) - 1);
            }
            a = argmin(tb);
            t_exit = tb[a];
            s.occupied = false;
            s.t0 = m_t;
            s.t1 = std::max(std::min(t_exit, m_far), m_t);
            m_t = s.t1;
            reseed(a, s.lo, s.hi, L);
            return true;
        }
        a = argmin(m_next);
        t_exit = m_next[a];
        s.occupied = (w >> m_bit) & 1u;
        s.t0 = m_t;
        s.t1 = std::max(std::min(t_exit, m_far), m_t);
        if constexpr (kBox)
            for (int c = 0; c < 3; ++c) s.lo[c] = s.hi[c] = m_b[c];
        m_t = s.t1;
        // The next brick on axis a; its block and bit follow incrementally.
        const int nb = m_b[a] + m_step[a];
        if ((nb >> 2) != (m_b[a] >> 2)) {
            m_blk += m_blk_delta[a];
            m_bit += m_bit_wrap[a];
        } else {
            m_bit += m_bit_delta[a];
        }
        m_b[a] = nb;
        m_next[a] = crossing(a, nb, L);
        return true;
    }

    // kFast = false walks every brick through step() (tests: brick_run must give the same
    // stretches, to the bit).
    template <bool kFast = true>
    bool next(Segment& out) {
        Step s;
        while (m_t < m_far) {
            // Runs of brick steps inside non-empty blocks go through the register-resident
            // walk; an empty block (a leap) through step().
            if (kFast && m_g.m_words[size_t(m_blk)] != 0) {
                if (brick_run(out)) return true;
                continue;
            }
            step<false>(s);
            if (s.occupied) {
                bool emit = false;
                if (!m_open) {
                    m_open = true;
                    m_start = s.t0;
                } else if (m_gap && s.t0 - m_gap_start > m_min_skip) {
                    out = {m_start, m_gap_start};
                    m_start = s.t0;
                    emit = out.t1 > out.t0;
                }
                m_gap = false;
                if (!emit && s.t1 - m_start >= m_chunk && s.t1 < m_far) {
                    out = {m_start, s.t1};
                    m_start = s.t1;
                    emit = true;
                }
                if (emit) return true;
            } else if (m_open && !m_gap) {
                m_gap = true;
                m_gap_start = s.t0;
            }
        }
        if (!m_open) return false;
        m_open = false;
        out = {m_start, m_gap ? m_gap_start : m_far};
        return out.t1 > out.t0;
    }

    // Brick steps while the ray stays in non-empty blocks, with the walk state in registers and
    // the axis chosen without branches (the choice is data dependent: a branch on it
    // mispredicts about every other step). The same walk as step<false>() and the same
    // run/gap bookkeeping as next(); true when it hands out a segment.
    bool brick_run(Segment& out) {
        const int L = m_g.m_log2;
        const uint64_t* words = m_g.m_words.data();
        float t = m_t, n0 = m_next[0], n1 = m_next[1], n2 = m_next[2];
        int b0 = m_b[0], b1 = m_b[1], b2 = m_b[2], bit = m_bit;
        int64_t blk = m_blk;
        bool emit = false;
        while (t < m_far) {
            const uint64_t w = words[size_t(blk)];
            if (w == 0) break;
            const bool occupied = (w >> bit) & 1u;
            const bool x = n0 <= n1 && n0 <= n2, y = !x && n1 <= n2, z = !x && !y;
            const float te = x ? n0 : (y ? n1 : n2);
            const float t1 = std::max(std::min(te, m_far), t);
            if (occupied) {
                if (!m_open) {
                    m_open = true;
                    m_start = t;
                } else if (m_gap && t - m_gap_start > m_min_skip) {
                    out = {m_start, m_gap_start};
                    m_start = t;
                    emit = out.t1 > out.t0;
                }
                m_gap = false;
                if (!emit && t1 - m_start >= m_chunk && t1 < m_far) {
                    out = {m_start, t1};
                    m_start = t1;
                    emit = true;
                }
            } else if (m_open && !m_gap) {
                m_gap = true;
                m_gap_start = t;
            }
            t = t1;
            // Advance the chosen axis: brick, block, bit and its next crossing.
            const int a = x ? 0 : (y ? 1 : 2);
            const int ob = x ? b0 : (y ? b1 : b2), nb = ob + m_step[a];
            const bool wrap = (nb >> 2) != (ob >> 2);
            blk += wrap ? m_blk_delta[a] : 0;
            bit += wrap ? m_bit_wrap[a] : m_bit_delta[a];
            const float nt = crossing(a, nb, L);
            b0 = x ? nb : b0, b1 = y ? nb : b1, b2 = z ? nb : b2;
            n0 = x ? nt : n0, n1 = y ? nt : n1, n2 = z ? nt : n2;
            if (emit) break;
        }
        m_t = t;
        m_next[0] = n0, m_next[1] = n1, m_next[2] = n2;
        m_b[0] = b0, m_b[1] = b1, m_b[2] = b2;
        m_bit = bit;
        m_blk = blk;
        return emit;
    }

  private:
    static int argmin(const float t[3]) {
        const int a = t[1] < t[0] ? 1 : 0;
        return t[2] < t[a] ? 2 : a;
    }
    // Parameter at which the ray leaves node `n` (edge 2^shift cells) on axis a; +inf if it
    // never does (parallel ray, or the face is the grid border).
    float crossing(int a, int n, int shift) const {
        const int plane = (n + m_up[a]) << shift;
        const float t = (float(plane) - m_o[a]) * m_inv[a];
        return plane <= m_lo_lim[a] || plane >= m_hi_lim[a] ? INFINITY : t;
    }
    // Parameter at which the ray leaves the slab of nodes [lo, hi) (edge 2^shift cells) on axis
    // a; +inf if it never does (parallel ray, or the face is on or past the grid border).
    float leap_crossing(int a, int lo, int hi, int shift) const {
        if (m_d[a] > 0.f) {
            const int64_t plane = int64_t(hi) << shift;
            return plane >= m_cells[a] ? INFINITY : (float(plane) - m_o[a]) * m_inv[a];
        }
        if (m_d[a] < 0.f) {
            const int64_t plane = int64_t(lo) << shift;
            return plane <= 0 ? INFINITY : (float(plane) - m_o[a]) * m_inv[a];
        }
        return INFINITY;
    }
    // After a leap out of the brick box lo..hi across axis a's face at m_t: the brick past the
    // face on a; the other axes from the position at m_t, kept inside the box.
    void reseed(int a, const int lo[3], const int hi[3], int L) {
        for (int c = 0; c < 3; ++c) {
            if (c == a) continue;
            float p = m_o[c] + m_t * m_d[c];
            p = p < 0.f ? 0.f : (p > float(m_cells[c]) ? float(m_cells[c]) : p);
            m_b[c] = std::clamp(int(p) >> L, lo[c], hi[c]);
        }
        m_b[a] = m_d[a] > 0.f ? hi[a] + 1 : lo[a] - 1;
        for (int c = 0; c < 3; ++c) m_next[c] = crossing(c, m_b[c], L);
        locate();
    }
    // Block index and bit of the current brick (on a brick past the grid after the last leap,
    // the walk is over and they are never read).
    void locate() {
        m_blk = int64_t(m_g.block_index(m_b[0], m_b[1], m_b[2]));
        m_bit = bit(m_b[0], m_b[1], m_b[2]);
    }

    const BrickGrid& m_g;
    float m_o[3], m_d[3], m_inv[3];
    int m_cells[3], m_nbm1[3];
    int m_up[3], m_step[3], m_lo_lim[3], m_hi_lim[3];
    int m_b[3];
    int64_t m_blk = 0, m_blk_delta[3];
    int m_bit = 0, m_bit_delta[3], m_bit_wrap[3];
    float m_next[3];
    float m_t, m_far, m_min_skip, m_chunk;
    float m_start = 0.f, m_gap_start = 0.f;
    bool m_open = false, m_gap = false;
};

}  // namespace lacuna
