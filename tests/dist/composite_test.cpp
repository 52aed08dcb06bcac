// src/dist/composite.h without messages: rectangles, over, and radix-k's block order.
#include "dist/composite.h"

#include <gtest/gtest.h>

#include "common/rng.h"

namespace lacuna::dist {
namespace {

TEST(Composite, NonEmptyRectIsTheBoundingBoxOfNonZeroPixels) {
    Partial p{10, 8, std::vector<float>(10 * 8 * 4, 0.f)};
    EXPECT_TRUE(nonempty_rect(p, {0, 0, 10, 8}).empty());
    p.at(3, 2)[1] = 0.5f;
    p.at(6, 5)[3] = 0.25f;
    const Rect r = nonempty_rect(p, {0, 0, 10, 8});
    EXPECT_EQ(r.x0, 3);
    EXPECT_EQ(r.y0, 2);
    EXPECT_EQ(r.x1, 7);
    EXPECT_EQ(r.y1, 6);
    const Rect part = nonempty_rect(p, {0, 4, 10, 8});  // only the second pixel's rows
    EXPECT_EQ(part.x0, 6);
    EXPECT_EQ(part.y0, 5);
    EXPECT_EQ(part.pixels(), 1);
}

// Over is the sequential front-to-back accumulation regrouped: equal to the chain within float
// rounding, and over zero (either side) is exact.
TEST(Composite, OverOfPartialChainsIsTheChain) {
    test::Rng rng{5};
    for (int it = 0; it < 1000; ++it) {
        const int n = rng.range(1, 30), m = rng.range(0, n);
        float chain[4] = {0, 0, 0, 0}, front[4] = {0, 0, 0, 0}, back[4] = {0, 0, 0, 0};
        for (int s = 0; s < n; ++s) {
            const float a = rng.uniform() * 0.3f,
                        c[3] = {rng.uniform() * a, rng.uniform() * a, rng.uniform() * a};
            for (float* acc : {chain, s < m ? front : back}) {
                const float w = 1.f - acc[3];
                for (int ch = 0; ch < 3; ++ch) acc[ch] += w * c[ch];
                acc[3] += w * a;
            }
        }
        Partial dst{1, 1, {back[0], back[1], back[2], back[3]}};
        composite_into(dst, {0, 0, 1, 1}, front, true);
        for (int ch = 0; ch < 4; ++ch) EXPECT_NEAR(dst.rgba[size_t(ch)], chain[ch], 1e-5f);
        Partial zero{1, 1, {0, 0, 0, 0}};
        composite_into(zero, {0, 0, 1, 1}, front, false);
        for (int ch = 0; ch < 4; ++ch) EXPECT_EQ(zero.rgba[size_t(ch)], front[ch]);
    }
}

// Radix-k's order of the blocks of a subtree is the visibility order of the ranks in them.
TEST(Composite, BlockOrderIsTheVisibilityOrderOfTheSubtree) {
    test::Rng rng{11};
    for (int n : {2, 4, 8, 16}) {
        const Decomposition d = decompose_voxels({40, 33, 29}, n);
        for (int it = 0; it < 20; ++it) {
            const Vec3f eye{-20.f + 80.f * rng.uniform(), -20.f + 70.f * rng.uniform(),
                            -20.f + 70.f * rng.uniform()};
            const Vec3f dir{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f};
            const bool ortho = it % 2 == 0;
            EXPECT_EQ(block_order(d, 0, n, 1, eye, dir, ortho),
                      visibility_order(d, eye, dir, ortho));
            if (n >= 4) {
                // Blocks of 2: the order of the pairs, each pair's ranks together.
                const std::vector<int> pairs = block_order(d, 0, n, 2, eye, dir, ortho);
                const std::vector<int> ranks = visibility_order(d, eye, dir, ortho);
                for (size_t i = 0; i < pairs.size(); ++i) {
                    EXPECT_EQ(ranks[2 * i] / 2, pairs[i]);
                    EXPECT_EQ(ranks[2 * i + 1] / 2, pairs[i]);
                }
            }
        }
    }
}

}  // namespace
}  // namespace lacuna::dist
