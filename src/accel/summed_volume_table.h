// The summed-volume table of the kd-tree paper (Section 2.1.2, Eqs. 3-6): O(1) counts of
// non-empty cells in any axis-aligned box of cells, and the bounding volume (BV) of the
// non-empty cells of a box by the boundary scan of Eq. 3.
//
// Layout: one Count per cell, x fastest, then y, then z, exactly the size of the classified grid
// (n[0] x n[1] x n[2] cells, no padding row). The same array holds, in turn,
//   V1(i,j,k)  1 if cell (i,j,k) is non-empty, else 0                    (step 1)
//   V2(i,j,k)  number of non-empty cells in [0,i] x [0,j] x [0,k]         (step 2, Eq. 4)
// and V2 is computed from V1 in place (Eq. 5), so the table is the only full-size allocation.
// Lookups with an index of -1 read 0 (the paper's "special cases").
//
// Count is uint32_t unless the grid has more than 2^32 - 1 cells (V2 of the last cell is the
// total, so 32 bits are enough exactly when the cell count fits); then uint64_t. Arithmetic is
// modular, so the differences of Eqs. 5 and 6 are exact even when intermediate terms wrap.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "accel/region.h"

namespace lacuna {

template <class Count>
class SummedVolumeTable {
    static_assert(std::is_same_v<Count, uint32_t> || std::is_same_v<Count, uint64_t>);

  public:
    // Sizes the grid (keeping the allocation when it is large enough); contents are undefined
    // until step 1 fills them.
    void resize(const int n[3]) {
        for (int a = 0; a < 3; ++a) m_n[a] = n[a];
        m_sy = size_t(n[0]);
        m_sz = size_t(n[0]) * size_t(n[1]);
        m_v.resize(m_sz * size_t(n[2]));
    }
    const int* dims() const { return m_n; }
    size_t cell_count() const { return m_v.size(); }
    size_t bytes() const { return m_v.capacity() * sizeof(Count); }
    size_t index(int i, int j, int k) const {
        return size_t(k) * m_sz + size_t(j) * m_sy + size_t(i);
    }
    // Row (0..n[0]-1, j, k): where step 1 writes its classification.
    Count* row(int j, int k) { return &m_v[index(0, j, k)]; }
    Count* data() { return m_v.data(); }

    // Step 2, literally: the rows hold V1; one sequential pass of Eq. 5 turns them into V2 in
    // place. The reference the fast path is tested against.
    void build_eq5();
    // Step 2, fast: step 1 has stored every row of V1 already summed along x,
    //     X(i,j,k) = sum_{u <= i} V1(u,j,k),
    // which is what the four "i - 1" terms of Eq. 5 add up to (they telescope along the row).
    // One pass in place completes Eq. 5 with the remaining three lookups:
    //     V2(i,j,k) = X(i,j,k) + V2(i,j-1,k) + V2(i,j,k-1) - V2(i,j-1,k-1).
    void build_from_row_sums();

    // V2(i,j,k); 0 when any index is -1.
    Count at(int i, int j, int k) const {
        if ((i | j | k) < 0) return 0;
        return m_v[index(i, j, k)];
    }
    // Eq. 6: non-empty cells in the box [lo, hi) with eight lookups (u1 = lo - 1, u2 = hi - 1).
    Count count(const CellBox& b) const {
        const int u1 = b.lo[0] - 1, u2 = b.hi[0] - 1, v1 = b.lo[1] - 1, v2 = b.hi[1] - 1,
                  w1 = b.lo[2] - 1, w2 = b.hi[2] - 1;
        return (at(u2, v2, w2) - at(u2, v2, w1)) - (at(u1, v2, w2) - at(u1, v2, w1)) -
               (at(u2, v1, w2) - at(u2, v1, w1)) + (at(u1, v1, w2) - at(u1, v1, w1));
    }
    bool empty(const CellBox& b) const { return count(b) == 0; }
    // The number of non-empty cells in the whole grid (V2 of the last cell).
    Count total() const { return m_v.empty() ? 0 : m_v.back(); }

  private:
    int m_n[3] = {0, 0, 0};
    size_t m_sy = 0, m_sz = 0;
    std::vector<Count> m_v;
};

extern template class SummedVolumeTable<uint32_t>;
extern template class SummedVolumeTable<uint64_t>;

inline int64_t box_volume(const CellBox& b) {
    return int64_t(b.hi[0] - b.lo[0]) * int64_t(b.hi[1] - b.lo[1]) * int64_t(b.hi[2] - b.lo[2]);
}

// Eq. 3 on one side of `box`: with R_i the part of `box` from its `side` face up to slab i
// (side 0: the low face, slabs lo..i; side 1: the high face, slabs i..hi-1), returns the first
// slab i, moving inward, for which R_i holds a non-empty cell. `box` must hold one.
//
// Count(R_i) grows with i, so "R_i is not empty" is monotone and the first such i can be found
// by a galloping search (steps 1, 2, 4, ... inward, then bisection) in O(log) table tests
// instead of the paper's one-slab-at-a-time scan; both give the same i (the tests compare them).
template <class Count>
int bv_scan(const SummedVolumeTable<Count>& t, const CellBox& box, int axis, int side) {
    const int lo = box.lo[axis], hi = box.hi[axis];
    CellBox r = box;
    // nonempty(m): R covering the first m slabs from the face (1 <= m <= hi - lo).
    auto nonempty = [&](int m) {
        if (side == 0)
            r.hi[axis] = lo + m;
        else
            r.lo[axis] = hi - m;
        return t.count(r) != 0;
    };
    const int len = hi - lo;
    int bad = 0, good = 1;  // R with `bad` slabs is empty, with `good` slabs is not
    while (good < len && !nonempty(good)) {
        bad = good;
        good = std::min(len, 2 * good);
    }
    while (good - bad > 1) {
        const int mid = bad + (good - bad) / 2;
        if (nonempty(mid))
            good = mid;
        else
            bad = mid;
    }
    return side == 0 ? lo + good - 1 : hi - good;
}

// The paper's plain scan of Eq. 3 (one slab per step); tests only.
template <class Count>
int bv_scan_linear(const SummedVolumeTable<Count>& t, const CellBox& box, int axis, int side) {
    CellBox r = box;
    if (side == 0) {
        for (int i = box.lo[axis]; i < box.hi[axis]; ++i) {
            r.hi[axis] = i + 1;
            if (t.count(r) != 0) return i;
        }
        return box.hi[axis];
    }
    for (int i = box.hi[axis] - 1; i >= box.lo[axis]; --i) {
        r.lo[axis] = i;
        if (t.count(r) != 0) return i;
    }
    return box.lo[axis] - 1;
}

// BV of the non-empty cells of `box` (Section 2.1.2): the boundaries i1, i2, j1, j2, k1, k2 by
// Eq. 3 on all six sides, each scan inside the box already shrunk by the previous ones (cells
// outside a found boundary are empty, so shrinking first changes no answer and shortens the
// later scans). Returns false, leaving `out` alone, when the box holds no non-empty cell.
template <class Count>
bool bounding_volume(const SummedVolumeTable<Count>& t, const CellBox& box, CellBox& out) {
    for (int a = 0; a < 3; ++a)
        if (box.lo[a] >= box.hi[a]) return false;
    if (t.empty(box)) return false;
    CellBox b = box;
    for (int a = 0; a < 3; ++a) {
        const int first = bv_scan(t, b, a, 0);
        b.lo[a] = first;
        b.hi[a] = bv_scan(t, b, a, 1) + 1;
    }
    out = b;
    return true;
}

}  // namespace lacuna
