// Octree pyramid geometry and the region search shared by the min-max, bitfield and boolean
// octrees. The trees are stored as full pyramids (one flat array, level by level), as in the
// bitfield paper's 3D-texture layout.
//
// Level 0 holds leaves of `leaf` cells per axis; a level-l node covers leaf << l cells per axis
// and its children are the level-(l-1) nodes inside it. Node (x,y,z) of level l covers cells
// [x << s, min((x+1) << s, cells)) on each axis, s = log2(leaf) + l. Because a leaf's value
// range is the union of its cells' ranges, and a cell spans voxels c..c+1, a leaf's range covers
// the voxels one past its block edge.
#pragma once
#include <algorithm>
#include <cstddef>
#include <string>

#include "accel/region.h"
#include "lacuna/error.h"

namespace lacuna {

struct Pyramid {
    static constexpr int kMaxLevels = 24;
    int cells[3] = {0, 0, 0};
    int leaf_log2 = 3;
    int levels = 1;                      // level levels-1 is the root (1 node)
    int n[kMaxLevels][3] = {};           // nodes per axis
    size_t offset[kMaxLevels + 1] = {};  // first node of each level in the flat array

    void init(const int c[3], int leaf) {
        if (leaf < 2 || leaf > 64 || (leaf & (leaf - 1)))
            throw FrameError("structure.octree.leaf_cells",
                             "expected a power of two in 2..64, got " + std::to_string(leaf));
        leaf_log2 = 0;
        while ((1 << leaf_log2) < leaf) ++leaf_log2;
        for (int a = 0; a < 3; ++a) cells[a] = c[a];
        levels = 0;
        offset[0] = 0;
        for (;;) {
            const int s = leaf_log2 + levels;
            for (int a = 0; a < 3; ++a) n[levels][a] = int((int64_t(cells[a]) + (1 << s) - 1) >> s);
            offset[levels + 1] =
                offset[levels] + size_t(n[levels][0]) * n[levels][1] * n[levels][2];
            ++levels;
            if (n[levels - 1][0] == 1 && n[levels - 1][1] == 1 && n[levels - 1][2] == 1) break;
        }
    }
    size_t node_count() const { return offset[levels]; }
    size_t index(int level, int x, int y, int z) const {
        return offset[level] + (size_t(z) * size_t(n[level][1]) + size_t(y)) * size_t(n[level][0]) +
               size_t(x);
    }
    CellBox box(int level, int x, int y, int z) const {
        const int s = leaf_log2 + level;
        const int p[3] = {x, y, z};
        CellBox b;
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = p[a] << s;
            b.hi[a] = int(std::min<int64_t>(int64_t(p[a] + 1) << s, cells[a]));
        }
        return b;
    }
    // Calls f(child_index) for the up to 8 children of node (x,y,z) at level l >= 1.
    template <class F>
    void for_children(int l, int x, int y, int z, F&& f) const {
        for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
                for (int dx = 0; dx < 2; ++dx) {
                    const int cx = 2 * x + dx, cy = 2 * y + dy, cz = 2 * z + dz;
                    if (cx < n[l - 1][0] && cy < n[l - 1][1] && cz < n[l - 1][2])
                        f(index(l - 1, cx, cy, cz));
                }
    }
};

// Finds the coarsest empty node containing `cell`, searching from `start` (the initial level)
// down; returns the leaf as occupied if none is empty. Bidirectional search starts at the level
// of the previous answer (`hint`) and moves up while the parent is empty or down while the node
// is occupied (the bitfield paper's Figure 6); top-down search restarts at `start` every time.
// Emptiness is monotone (a parent is empty iff all its children are), so both searches give the
// same region; they differ only in how many nodes they test.
template <class EmptyFn>
inline Region octree_region(const Pyramid& p, const int cell[3], int& hint, int start,
                            bool bidirectional, EmptyFn&& empty) {
    auto node = [&](int l, int a) { return cell[a] >> (p.leaf_log2 + l); };
    auto test = [&](int l) { return empty(p.index(l, node(l, 0), node(l, 1), node(l, 2))); };
    auto answer = [&](int l, bool e) {
        return Region{p.box(l, node(l, 0), node(l, 1), node(l, 2)), e};
    };
    int l = bidirectional && hint >= 0 ? std::min(hint, start) : start;
    if (test(l)) {
        while (l < start && test(l + 1)) ++l;
        hint = l;
        return answer(l, true);
    }
    while (l > 0) {
        --l;
        if (test(l)) {
            hint = l;
            return answer(l, true);
        }
    }
    hint = 0;
    return answer(0, false);
}

}  // namespace lacuna
