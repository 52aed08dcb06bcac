// src/dist/decomposition.h: the bricks partition the cells, balance, the binary-swap shape and
// the visibility order.
#include "dist/decomposition.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "accel/summed_volume_table.h"
#include "common/rng.h"
#include "lacuna/synthetic.h"

namespace lacuna::dist {
namespace {

// Every cell in exactly one brick.
void expect_partition(const Decomposition& d) {
    const Vec3i n{d.dims.x - 1, d.dims.y - 1, d.dims.z - 1};
    std::vector<int> owner(size_t(n.x) * n.y * n.z, 0);
    for (const CellBox& b : d.bricks) {
        for (int a = 0; a < 3; ++a) ASSERT_LT(b.lo[a], b.hi[a]) << to_string(d);
        for (int k = b.lo[2]; k < b.hi[2]; ++k)
            for (int j = b.lo[1]; j < b.hi[1]; ++j)
                for (int i = b.lo[0]; i < b.hi[0]; ++i) ++owner[(size_t(k) * n.y + j) * n.x + i];
    }
    for (int c : owner) ASSERT_EQ(c, 1) << to_string(d);
}

TEST(Decomposition, BricksPartitionTheCellsForOneToNineRanks) {
    for (int n = 1; n <= 9; ++n)
        for (Vec3i dims : {Vec3i{17, 9, 33}, Vec3i{64, 64, 64}, Vec3i{5, 40, 6}}) {
            const Decomposition d = decompose_voxels(dims, n);
            ASSERT_EQ(d.ranks(), n);
            expect_partition(d);
        }
}

TEST(Decomposition, VoxelBalanceWithinOneSlab) {
    for (int n : {2, 3, 4, 7, 8}) {
        const Decomposition d = decompose_voxels({129, 97, 65}, n);
        const double mean = 128.0 * 96 * 64 / n;
        for (const CellBox& b : d.bricks)
            EXPECT_NEAR(double(box_volume(b)), mean, 0.1 * mean) << n << ": " << to_string(d);
    }
}

TEST(Decomposition, VisibleBalanceSplitsTheVisibleCells) {
    SyntheticOptions o;
    o.dims = {48, 40, 56};
    Volume v = generate(SyntheticKind::Sphere, o);
    TransferLut lut;
    lut.vis = v.vis_range();
    lut.entries.assign(kDefaultLutSize, Rgba{});
    for (size_t e = kDefaultLutSize / 2; e < lut.entries.size(); ++e)
        lut.entries[e] = {1, 1, 1, 0.5f};
    for (int n : {2, 4, 7}) {
        const Decomposition d = decompose_visible(v, lut, n, 1);
        expect_partition(d);
        // The visible cells of each brick, brute force.
        std::vector<double> counts;
        double total = 0;
        const ValueToLut map = lut.map();
        for (const CellBox& b : d.bricks) {
            double c = 0;
            for (int k = b.lo[2]; k < b.hi[2]; ++k)
                for (int j = b.lo[1]; j < b.hi[1]; ++j)
                    for (int i = b.lo[0]; i < b.hi[0]; ++i) {
                        float lo = INFINITY, hi = -INFINITY;
                        for (int q = 0; q < 8; ++q) {
                            const float x = v.value(i + (q & 1), j + (q >> 1 & 1), k + (q >> 2));
                            lo = std::min(lo, x), hi = std::max(hi, x);
                        }
                        bool vis = false;
                        for (int e = map(lo); e <= map(hi); ++e)
                            vis = vis || lut.entries[size_t(e)].a > 0;
                        c += vis;
                    }
            counts.push_back(c);
            total += c;
        }
        ASSERT_GT(total, 0);
        for (double c : counts)
            EXPECT_NEAR(c, total / n, 0.2 * total / n) << n << ": " << to_string(d);
    }
}

// Binary swap's shape: slot nodes exist and hold the ranks the compositor pairs.
TEST(Decomposition, SlotNodesArePairsOfSubtrees) {
    for (int n = 1; n <= 9; ++n) {
        const Decomposition d = decompose_voxels({40, 40, 40}, n);
        const int p = swap_ranks(n);
        EXPECT_LE(p, n);
        EXPECT_GT(2 * p, n);
        auto ranks_below = [&](int id) {
            std::vector<int> out, stack{id};
            while (!stack.empty()) {
                const KdNode& k = d.nodes[size_t(stack.back())];
                stack.pop_back();
                if (k.axis < 0)
                    out.push_back(k.rank);
                else
                    stack.push_back(k.children[0]), stack.push_back(k.children[1]);
            }
            std::sort(out.begin(), out.end());
            return out;
        };
        for (int bit = 1; bit < p; bit *= 2)
            for (int a = 0; a < p; a += 2 * bit) {
                const int id = slot_node(d, a, a + 2 * bit);
                ASSERT_GE(id, 0) << n << " " << a << " " << bit;
                // Child 0 holds slots [a, a + bit) and their extras, child 1 the rest.
                for (int c = 0; c < 2; ++c)
                    for (int r : ranks_below(d.nodes[size_t(id)].children[c])) {
                        const int slot = r >= p ? r - p : r;
                        EXPECT_EQ(slot >= a + bit, c == 1) << n;
                    }
            }
        for (int s = 0; s < n - p; ++s) {
            const int id = slot_node(d, s, s + 1);
            ASSERT_GE(id, 0);
            EXPECT_EQ(ranks_below(d.nodes[size_t(id)].children[0]), std::vector<int>{s});
            EXPECT_EQ(ranks_below(d.nodes[size_t(id)].children[1]), std::vector<int>{p + s});
        }
    }
}

// Front to back: along random rays from the eye, the bricks a ray visits come in that order.
TEST(Decomposition, VisibilityOrderFollowsEveryRay) {
    test::Rng rng{3};
    for (int n : {2, 3, 5, 7, 8}) {
        const Decomposition d = decompose_voxels({30, 25, 20}, n);
        for (int it = 0; it < 50; ++it) {
            const bool ortho = it % 3 == 0;
            const Vec3f eye{-20.f + 70.f * rng.uniform(), -20.f + 65.f * rng.uniform(),
                            -20.f + 60.f * rng.uniform()};
            Vec3f dir{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f};
            const std::vector<int> order = visibility_order(d, eye, dir, ortho);
            std::vector<int> pos(static_cast<size_t>(n));
            for (int i = 0; i < n; ++i) pos[size_t(order[size_t(i)])] = i;
            ASSERT_EQ(order.size(), size_t(n));
            for (int ray = 0; ray < 20; ++ray) {
                Vec3f o = eye, dd;
                if (ortho) {
                    dd = dir;
                    o = {eye.x + 10.f * (rng.uniform() - 0.5f),
                         eye.y + 10.f * (rng.uniform() - 0.5f), eye.z};
                } else {
                    const Vec3f target{30.f * rng.uniform(), 25.f * rng.uniform(),
                                       20.f * rng.uniform()};
                    dd = target - eye;
                }
                int last = -1;
                for (int s = 0; s < 400; ++s) {
                    const Vec3f p = o + dd * (0.01f * float(s));
                    for (int r = 0; r < n; ++r) {
                        const BrickOwnership b = ownership(d, r);
                        bool in = true;
                        for (int a = 0; a < 3; ++a) in = in && p[a] >= b.lo[a] && p[a] < b.hi[a];
                        if (!in) continue;
                        ASSERT_GE(pos[size_t(r)], last) << "ray " << ray << " " << to_string(d);
                        last = pos[size_t(r)];
                    }
                }
            }
        }
    }
}

}  // namespace
}  // namespace lacuna::dist
