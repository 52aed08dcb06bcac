#include "dist/decomposition.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "accel/cell_ranges.h"
#include "accel/summed_volume_table.h"
#include "lacuna/error.h"

namespace lacuna::dist {

std::string to_string(Balance b) {
    return b == Balance::Voxels ? "voxels" : "visible";
}

int swap_ranks(int ranks) {
    int p = 1;
    while (p * 2 <= ranks) p *= 2;
    return p;
}

namespace {

struct Builder {
    Decomposition& d;
    const CellWeight& weight;
    int p = 1, extras = 0;

    // Leaves below the slots [a, b): one per slot, two for slots < extras.
    int leaves(int a, int b) const { return (b - a) + std::max(0, std::min(b, extras) - a); }

    // The plane along `axis` of `box` with the low side's weight closest to `frac` of the box's,
    // keeping at least one cell on each side (the side's weight grows with the plane: bisection).
    int plane(const CellBox& box, int axis, double frac) const {
        const double total = weight(box);
        const double want = frac * total;
        auto low_weight = [&](int p) {
            CellBox b = box;
            b.hi[axis] = p;
            return weight(b);
        };
        int lo = box.lo[axis] + 1, hi = box.hi[axis] - 1;  // candidate planes
        if (!(total > 0)) {  // nothing to weigh: split the cells instead
            return std::clamp(box.lo[axis] + int(std::lround(frac * (box.hi[axis] - box.lo[axis]))),
                              lo, hi);
        }
        // First plane whose low weight reaches `want`, then the closer of it and the one before.
        int a = lo, b = hi + 1;
        while (a < b) {
            const int m = a + (b - a) / 2;
            if (low_weight(m) >= want)
                b = m;
            else
                a = m + 1;
        }
        int best = std::min(a, hi);
        if (best > lo && std::abs(low_weight(best - 1) - want) <= std::abs(low_weight(best) - want))
            best = best - 1;
        return best;
    }

    // A node over `box` holding the ranks of slots [a, b) (pair: the one slot's two ranks).
    int build(const CellBox& box, int a, int b) {
        const int id = int(d.nodes.size());
        d.nodes.push_back({});
        d.nodes[id].box = box;
        d.nodes[id].slot_lo = a;
        d.nodes[id].slot_hi = b;
        const bool pair = b - a == 1 && a < extras;
        if (b - a == 1 && !pair) {
            d.nodes[id].rank = a;
            d.bricks[size_t(a)] = box;
            return id;
        }
        // The longest axis in cells (lowest on ties); it has >= 2 cells unless the box is one cell.
        int axis = 0;
        for (int ax = 1; ax < 3; ++ax)
            if (box.hi[ax] - box.lo[ax] > box.hi[axis] - box.lo[axis]) axis = ax;
        if (box.hi[axis] - box.lo[axis] < 2)
            throw Error("decomposition", "ranks",
                        "more ranks than the grid has cells to split (" +
                            std::to_string(d.ranks()) + " ranks)");
        const int mid = pair ? a : a + (b - a) / 2;
        const double frac = pair ? 0.5 : double(leaves(a, mid)) / double(leaves(a, b));
        const int pl = plane(box, axis, frac);
        CellBox low = box, high = box;
        low.hi[axis] = pl;
        high.lo[axis] = pl;
        d.nodes[id].axis = axis;
        d.nodes[id].plane = pl;
        int c0, c1;
        if (pair) {
            c0 = build_leaf(low, a, a);
            c1 = build_leaf(high, a, p + a);
        } else {
            c0 = build(low, a, mid);
            c1 = build(high, mid, b);
        }
        d.nodes[id].children[0] = c0;
        d.nodes[id].children[1] = c1;
        return id;
    }
    int build_leaf(const CellBox& box, int slot, int rank) {
        const int id = int(d.nodes.size());
        d.nodes.push_back({});
        d.nodes[id].box = box;
        d.nodes[id].rank = rank;
        d.nodes[id].slot_lo = slot;
        d.nodes[id].slot_hi = slot + 1;
        d.bricks[size_t(rank)] = box;
        return id;
    }
};

}  // namespace

Decomposition decompose(Vec3i dims, int ranks, const CellWeight& weight) {
    if (ranks < 1) throw Error("decomposition", "ranks", "expected at least one");
    Decomposition d;
    d.dims = dims;
    d.bricks.resize(size_t(ranks));
    Builder b{d, weight};
    b.p = swap_ranks(ranks);
    b.extras = ranks - b.p;
    const CellBox all{{0, 0, 0}, {dims.x - 1, dims.y - 1, dims.z - 1}};
    b.build(all, 0, b.p);
    return d;
}

Decomposition decompose_voxels(Vec3i dims, int ranks) {
    return decompose(dims, ranks, [](const CellBox& b) { return double(box_volume(b)); });
}

namespace {
// Step 1 and Eq. 5 of the kd-tree paper's table over the cells of v: each row's visible flags
// summed along x (as src/accel/kdtree_partition.cpp classify_tf), then Eq. 5 in place.
template <class Count>
void visible_table(const Volume& v, const TransferLut& lut, int threads,
                   SummedVolumeTable<Count>& t) {
    int cells[3];
    cell_counts(v, cells);
    t.resize(cells);
    OpacityPrefix prefix;
    prefix.build(lut);
    for_each_cell_row(v, lut.map(), 8, threads, [&](const CellRow& r) {
        Count* row = t.row(r.j, r.k);
        Count s = 0;
        for (int i = 0; i < r.n; ++i) {
            s += Count(prefix.visible(r.lo[i], r.hi[i]));
            row[i] = s;
        }
    });
    t.build_from_row_sums();
}
}  // namespace

Decomposition decompose_visible(const Volume& v, const TransferLut& lut, int ranks, int threads) {
    SummedVolumeTable<uint64_t> t;
    visible_table(v, lut, threads, t);
    return decompose(v.dims(), ranks, [&t](const CellBox& b) { return double(t.count(b)); });
}

SlabCounts::SlabCounts(const Volume& slab, Vec3i offset, const CellBox& cells,
                       const TransferLut& lut, int threads)
    : m_cells(cells),
      m_offset(offset),
      m_narrow(uint64_t(slab.dims().x - 1) * uint64_t(slab.dims().y - 1) *
                   uint64_t(slab.dims().z - 1) <
               (uint64_t(1) << 32)) {
    if (m_narrow)
        visible_table(slab, lut, threads, m_t32);
    else
        visible_table(slab, lut, threads, m_t64);
}

uint64_t SlabCounts::count(const CellBox& b) const {
    CellBox c;  // b within this slab's own cells, in slab cells
    for (int a = 0; a < 3; ++a) {
        c.lo[a] = std::max(b.lo[a], m_cells.lo[a]) - m_offset[a];
        c.hi[a] = std::min(b.hi[a], m_cells.hi[a]) - m_offset[a];
        if (c.lo[a] >= c.hi[a]) return 0;
    }
    return m_narrow ? uint64_t(m_t32.count(c)) : uint64_t(m_t64.count(c));
}

Decomposition decompose_visible_slabs(Vec3i dims, const SlabCounts& mine, int ranks,
                                      const std::function<uint64_t(uint64_t)>& sum) {
    return decompose(dims, ranks, [&](const CellBox& b) { return double(sum(mine.count(b))); });
}

BrickOwnership ownership(const Decomposition& d, int rank) {
    const CellBox& c = d.bricks.at(size_t(rank));
    const int cells[3] = {d.dims.x - 1, d.dims.y - 1, d.dims.z - 1};
    BrickOwnership o;
    o.whole_dims = d.dims;
    o.offset = {std::max(c.lo[0] - 1, 0), std::max(c.lo[1] - 1, 0), std::max(c.lo[2] - 1, 0)};
    for (int a = 0; a < 3; ++a) {
        o.lo[a] = c.lo[a] == 0 ? -INFINITY : float(c.lo[a]);
        o.hi[a] = c.hi[a] == cells[a] ? INFINITY : float(c.hi[a]);
    }
    return o;
}

Vec3i brick_voxels(const Decomposition& d, int rank) {
    const CellBox& c = d.bricks.at(size_t(rank));
    const Vec3i o = ownership(d, rank).offset;
    return {std::min(c.hi[0] + 1, d.dims.x - 1) - o.x + 1,
            std::min(c.hi[1] + 1, d.dims.y - 1) - o.y + 1,
            std::min(c.hi[2] + 1, d.dims.z - 1) - o.z + 1};
}

bool low_in_front(const KdNode& n, Vec3f eye, Vec3f dir, bool orthographic) {
    // Orthographic: the rays travel along dir, so the low side is first when dir points up the
    // axis. Perspective: the eye's side first (on the plane itself either order is right: every
    // ray from there stays on one side).
    return orthographic ? dir[n.axis] >= 0.f : eye[n.axis] < float(n.plane);
}

std::vector<int> visibility_order(const Decomposition& d, Vec3f eye, Vec3f dir, bool orthographic) {
    std::vector<int> order;
    std::vector<int> stack{0};
    while (!stack.empty()) {
        const KdNode& n = d.nodes[size_t(stack.back())];
        stack.pop_back();
        if (n.axis < 0) {
            order.push_back(n.rank);
            continue;
        }
        const bool low = low_in_front(n, eye, dir, orthographic);
        stack.push_back(n.children[low ? 1 : 0]);  // the far child after
        stack.push_back(n.children[low ? 0 : 1]);
    }
    return order;
}

int slot_node(const Decomposition& d, int a, int b) {
    int id = 0;  // the root, over slots [0, P)
    for (;;) {
        const KdNode& n = d.nodes[size_t(id)];
        if (n.axis < 0) return -1;
        if (n.slot_lo == a && n.slot_hi == b) return id;
        if (n.slot_hi - n.slot_lo < 2) return -1;
        const int mid = n.slot_lo + (n.slot_hi - n.slot_lo) / 2;
        id = n.children[b <= mid ? 0 : 1];
    }
}

std::string to_string(const Decomposition& d) {
    std::string s = std::to_string(d.ranks()) + " bricks of " + std::to_string(d.dims.x) + "x" +
                    std::to_string(d.dims.y) + "x" + std::to_string(d.dims.z) + ":";
    for (int r = 0; r < d.ranks(); ++r) {
        const CellBox& c = d.bricks[size_t(r)];
        char buf[128];
        std::snprintf(buf, sizeof buf, " %d:[%d,%d)x[%d,%d)x[%d,%d)", r, c.lo[0], c.hi[0], c.lo[1],
                      c.hi[1], c.lo[2], c.hi[2]);
        s += buf;
    }
    return s;
}

}  // namespace lacuna::dist
