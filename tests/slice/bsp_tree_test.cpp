// The orthogonal BSP tree (growing-boxes paper, Section 3.2): splitting keeps a tiling, merging
// keeps coverage, and every traversal is a visibility order (exact pairwise test).
#include "slice/bsp_tree.h"

#include <gtest/gtest.h>

#include "lacuna/error.h"
#include "slice/boxes_test_util.h"
#include "slice/growing_boxes.h"

namespace lacuna {
namespace {

using accel_test::Rng;
using namespace boxes_test;

// A random tiling of the room [0, n): at each uncovered cell (x fastest) a box of random size,
// shrunk until it only takes uncovered cells. Not guillotine in general.
std::vector<CellBox> random_tiling(const int n[3], Rng& rng, int max_edge) {
    std::vector<uint8_t> cov(size_t(n[0]) * n[1] * n[2], 0);
    auto at = [&](int i, int j, int k) -> uint8_t& {
        return cov[(size_t(k) * n[1] + j) * n[0] + i];
    };
    std::vector<CellBox> out;
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i) {
                if (at(i, j, k)) continue;
                CellBox b{{i, j, k}, {i + 1, j + 1, k + 1}};
                for (int a = 0; a < 3; ++a)
                    b.hi[a] = std::min(n[a], b.lo[a] + rng.range(1, max_edge));
                // Shrink x until the first row is free, then y and z layer by layer.
                for (int x = b.lo[0]; x < b.hi[0]; ++x)
                    if (at(x, j, k)) b.hi[0] = x;
                for (int y = b.lo[1] + 1; y < b.hi[1]; ++y)
                    for (int x = b.lo[0]; x < b.hi[0]; ++x)
                        if (at(x, y, k)) b.hi[1] = std::min(b.hi[1], y);
                for (int z = b.lo[2] + 1; z < b.hi[2]; ++z)
                    for (int y = b.lo[1]; y < b.hi[1]; ++y)
                        for (int x = b.lo[0]; x < b.hi[0]; ++x)
                            if (at(x, y, z)) b.hi[2] = std::min(b.hi[2], z);
                for (int z = b.lo[2]; z < b.hi[2]; ++z)
                    for (int y = b.lo[1]; y < b.hi[1]; ++y)
                        for (int x = b.lo[0]; x < b.hi[0]; ++x) at(x, y, z) = 1;
                out.push_back(b);
            }
    return out;
}

// The classic non-guillotine pinwheel (four boxes around a centre one), extruded in z: no plane
// through the room avoids cutting a box.
std::vector<CellBox> pinwheel(int depth) {
    return {CellBox{{0, 0, 0}, {2, 1, depth}}, CellBox{{2, 0, 0}, {3, 2, depth}},
            CellBox{{1, 2, 0}, {3, 3, depth}}, CellBox{{0, 1, 0}, {1, 3, depth}},
            CellBox{{1, 1, 0}, {2, 2, depth}}};
}

std::vector<CellBox> leaf_boxes(const BspTree& t) {
    std::vector<CellBox> out;
    for (int32_t id : t.leaves()) out.push_back(t.boxes()[size_t(id)].box);
    return out;
}

void check_tiling(const int n[3], const std::vector<CellBox>& boxes, const std::string& what) {
    for (int c : coverage(n, boxes)) ASSERT_EQ(c, 1) << what;
}

// Splitting: leaves tile the room, every leaf is an original box or a piece of one whose parent
// is that original (one level), and each cut adds exactly one box.
void check_split(const BspTree& t, const std::vector<CellBox>& input, const int n[3],
                 const std::string& what) {
    check_tiling(n, leaf_boxes(t), what);
    EXPECT_EQ(t.stats().leaves, input.size() + t.stats().cut) << what;
    for (int32_t id : t.leaves()) {
        const BspBox& b = t.boxes()[size_t(id)];
        ASSERT_GE(b.grown, 0) << what;
        ASSERT_TRUE(inside(b.box, input[size_t(b.grown)])) << what;
        if (size_t(id) < input.size()) {
            ASSERT_EQ(b.parent, -1) << what << ": an original has no parent";
        } else {
            ASSERT_EQ(b.parent, b.grown) << what << ": a piece's parent is its original";
            ASSERT_EQ(t.boxes()[size_t(b.parent)].parent, -1) << what << ": one level only";
        }
    }
    for (const BspNode& nd : t.nodes())
        if (nd.is_leaf() && nd.box >= 0) {
            ASSERT_EQ(to_string(nd.room), to_string(t.boxes()[size_t(nd.box)].box)) << what;
        }
}

void check_orders(const BspTree& t, const int n[3], Rng& rng, const std::string& what) {
    for (int view = 0; view < 8; ++view) {
        const bool is_dir = view % 2 == 1;
        double key[3];
        for (int a = 0; a < 3; ++a)
            key[a] = is_dir     ? double(rng.uniform() * 2 - 1)
                     : view < 4 ? double(n[a]) * double(rng.uniform())  // inside the room
                                : double(n[a]) * (double(rng.uniform()) * 10 - 5);
        if (is_dir && view == 7) key[rng.range(0, 2)] = 0;  // rays parallel to a plane
        if (view == 2)  // an eye on split planes (integer cell coordinates)
            for (int a = 0; a < 3; ++a) key[a] = double(rng.range(0, n[a]));
        const Vec3f k{float(key[0]), float(key[1]), float(key[2])};
        for (int a = 0; a < 3; ++a) key[a] = double(k[a]);
        std::vector<int32_t> ids;
        if (is_dir)
            t.order_along(k, ids);
        else
            t.order(k, ids);
        std::vector<CellBox> order;
        for (int32_t id : ids) order.push_back(t.boxes()[size_t(id)].box);
        ASSERT_EQ(order.size(), t.leaves().size()) << what;
        expect_visibility_order(order, key, is_dir, what);
    }
}

TEST(BspTree, SplittingTilesTheRoomWithOneLevelOfParents) {
    Rng rng{5};
    for (int iter = 0; iter < 60; ++iter) {
        const int n[3] = {rng.range(1, 10), rng.range(1, 10), rng.range(1, 10)};
        const std::vector<CellBox> in = random_tiling(n, rng, rng.range(2, 8));
        BspTree t;
        t.build(in, CellBox{{0, 0, 0}, {n[0], n[1], n[2]}});
        check_split(t, in, n, "iter " + std::to_string(iter));
        check_orders(t, n, rng, "iter " + std::to_string(iter));
    }
}

TEST(BspTree, PinwheelNeedsExactlyOneCut) {
    const std::vector<CellBox> in = pinwheel(2);
    const int n[3] = {3, 3, 2};
    BspTree t;
    t.build(in, CellBox{{0, 0, 0}, {3, 3, 2}});
    check_split(t, in, n, "pinwheel");
    EXPECT_EQ(t.stats().cut, 1u);
    EXPECT_EQ(t.stats().leaves, 6u);
    Rng rng{9};
    check_orders(t, n, rng, "pinwheel");
}

TEST(BspTree, TheOrderOracleCatchesAReversedOrder) {
    // The pairwise oracle is not vacuous: back to front fails it, front to back passes.
    Rng rng{3};
    const int n[3] = {8, 7, 6};
    const std::vector<CellBox> in = random_tiling(n, rng, 3);
    BspTree t;
    t.build(in, CellBox{{0, 0, 0}, {8, 7, 6}});
    const double eye[3] = {-5.5, 3.25, 2.75};
    std::vector<int32_t> ids;
    t.order(Vec3f{-5.5f, 3.25f, 2.75f}, ids);
    std::vector<CellBox> order;
    for (int32_t id : ids) order.push_back(t.boxes()[size_t(id)].box);
    expect_visibility_order(order, eye, false, "front to back");
    bool caught = false;
    for (size_t i = 0; i < order.size() && !caught; ++i)
        for (size_t j = i + 1; j < order.size() && !caught; ++j)
            caught = hides(order[i], order[j], eye, false);
    EXPECT_TRUE(caught) << "reversing the order must break it";
}

TEST(BspTree, ChoosesThePlaneThatCutsFewestBoxes) {
    // Two slabs in z over a split in x: the z plane cuts nothing, any x plane cuts the top slab.
    const std::vector<CellBox> in = {CellBox{{0, 0, 0}, {3, 4, 2}}, CellBox{{3, 0, 0}, {8, 4, 2}},
                                     CellBox{{0, 0, 2}, {8, 4, 5}}};
    BspTree t;
    t.build(in, CellBox{{0, 0, 0}, {8, 4, 5}});
    EXPECT_EQ(t.stats().cut, 0u);
    EXPECT_EQ(t.nodes()[0].axis, 2);
    EXPECT_EQ(t.nodes()[0].plane, 2);
}

TEST(BspTree, MergingPreservesCoverageAndOrder) {
    Rng rng{17};
    for (int iter = 0; iter < 60; ++iter) {
        const int n[3] = {rng.range(1, 12), rng.range(1, 12), rng.range(1, 12)};
        const std::vector<CellBox> in = random_tiling(n, rng, rng.range(1, 6));
        BspTree t;
        t.build(in, CellBox{{0, 0, 0}, {n[0], n[1], n[2]}});
        const int one_in = rng.range(1, 4);
        size_t calls = 0;
        t.merge([&](int32_t a, int32_t b, const CellBox& m) {
            // The rule sees two leaves whose union is the merged box.
            EXPECT_EQ(box_volume(t.boxes()[size_t(a)].box) + box_volume(t.boxes()[size_t(b)].box),
                      box_volume(m));
            EXPECT_TRUE(inside(t.boxes()[size_t(a)].box, m));
            EXPECT_TRUE(inside(t.boxes()[size_t(b)].box, m));
            ++calls;
            return rng.coin(one_in);
        });
        const std::string what = "iter " + std::to_string(iter);
        check_tiling(n, leaf_boxes(t), what);
        EXPECT_EQ(t.stats().final_leaves, t.stats().leaves - t.stats().merged) << what;
        if (one_in == 1) {
            EXPECT_EQ(t.stats().final_leaves, 1u) << what;  // everything merges
        }
        // Parents: a live parent's pieces lie inside it.
        for (int32_t id : t.leaves()) {
            const int32_t p = t.parent_of(id);
            if (p >= 0) {
                ASSERT_TRUE(inside(t.boxes()[size_t(id)].box, in[size_t(p)])) << what;
            }
        }
        EXPECT_LE(t.sub_volumes(), t.leaves().size()) << what;
        check_orders(t, n, rng, what);
    }
}

TEST(BspTree, MergingTwoPiecesOfDifferentParentsDeletesBothParents) {
    // The pinwheel's one cut makes two pieces of one box; merging everything with one rule call
    // that joins boxes of different parents leaves every leaf parentless.
    const std::vector<CellBox> in = pinwheel(1);
    BspTree t;
    t.build(in, CellBox{{0, 0, 0}, {3, 3, 1}});
    ASSERT_EQ(t.sub_volumes(), 5u);  // five originals (one of them as two pieces)
    t.merge([&](int32_t a, int32_t b, const CellBox&) {
        const int32_t pa = t.parent_of(a), pb = t.parent_of(b);
        return pa != pb && (pa >= 0 || pb >= 0);
    });
    for (int32_t id : t.leaves()) EXPECT_EQ(t.parent_of(id), -1);
    EXPECT_GE(t.stats().merged, 1u);
}

TEST(BspTree, OverlapsAndHolesAreErrors) {
    BspTree t;
    EXPECT_THROW(t.build({CellBox{{0, 0, 0}, {2, 2, 2}}, CellBox{{1, 0, 0}, {3, 2, 2}}},
                         CellBox{{0, 0, 0}, {3, 2, 2}}),
                 Error);
    EXPECT_THROW(t.build({CellBox{{0, 0, 0}, {1, 2, 2}}}, CellBox{{0, 0, 0}, {3, 2, 2}}), Error);
}

}  // namespace
}  // namespace lacuna
