// The compositing cost model (src/dist/composite_model.h): its counts against the closed forms
// of the algorithms, and the fit against data made from known constants. (Its counts against
// what composite.cpp counts under MPI are checked by `lacuna bench mpi`, tests/dist/mpi/.)
#include "dist/composite_model.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lacuna::dist {
namespace {

constexpr double kPx = 16, kHdr = 16;  // bytes of a float RGBA pixel, of a rectangle header

TEST(CompositeModel, DirectSendsEveryPartialToRankZero) {
    for (int n : {1, 2, 3, 7, 64}) {
        const CompositeCounts c = composite_counts(Composite::Direct, n, 40, 30);
        EXPECT_EQ(c.messages, 2.0 * (n - 1));
        EXPECT_EQ(c.bytes, (n - 1) * (kHdr + kPx * 1200));
        EXPECT_EQ(c.pixels, 1200.0 * n);
    }
}

// Powers of two with rows that halve evenly: log2 N rounds receiving A/2, A/4, ... and a gather
// of N - 1 strips of A/N.
TEST(CompositeModel, BinarySwapHalvesThenGathers) {
    const int w = 16, h = 1024, a = w * h;
    for (int n : {2, 4, 8, 64, 1024}) {
        const int rounds = int(std::log2(n));
        const CompositeCounts c = composite_counts(Composite::BinarySwap, n, w, h);
        EXPECT_EQ(c.messages, 2.0 * rounds + 2.0 * (n - 1)) << n;
        EXPECT_EQ(c.bytes, kHdr * (rounds + n - 1) + kPx * a * (1 - 1.0 / n) * 2) << n;
        EXPECT_EQ(c.pixels, a * (1 - 1.0 / n) + a) << n;
    }
}

// Radix-k with k = 4 on 16 ranks: two rounds of 4 (3 exchanges each, A/4 then A/16 received per
// exchange, all 4 pieces composited: A, then A/4), the gather of 15 strips of A/16.
TEST(CompositeModel, RadixKRoundsOfK) {
    const int w = 16, h = 1024, a = w * h;
    const CompositeCounts c = composite_counts(Composite::RadixK, 16, w, h, 4);
    EXPECT_EQ(c.messages, 2.0 * 3 * 2 + 2.0 * 15);
    EXPECT_EQ(c.bytes, kHdr * (6 + 15) + kPx * (3.0 * a / 4 + 3.0 * a / 16 + 15.0 * a / 16));
    EXPECT_EQ(c.pixels, a + a / 4.0 + a);  // two rounds, then the gather of the whole image
    // k = 2 moves binary swap's bytes.
    EXPECT_EQ(composite_counts(Composite::RadixK, 16, w, h, 2).bytes,
              composite_counts(Composite::BinarySwap, 16, w, h).bytes);
}

// Three ranks: rank 2 folds into rank 0 first (one full image), then one swap round of two.
TEST(CompositeModel, ExtraRanksFoldFirst) {
    const CompositeCounts c = composite_counts(Composite::BinarySwap, 3, 10, 8);
    EXPECT_EQ(c.messages, 2.0 + 2.0 + 2.0);
    EXPECT_EQ(c.bytes, 3 * kHdr + kPx * (80 + 40 + 40));
}

TEST(CompositeModel, FitRecoversKnownConstants) {
    const CompositeModel truth{20e-6, 3e9, 4e-9};
    std::vector<CompositeSample> s;
    for (Composite alg : {Composite::Direct, Composite::BinarySwap, Composite::RadixK})
        for (int n : {2, 3, 4, 8})
            for (int e : {64, 256, 1024}) {
                const CompositeCounts c = composite_counts(alg, n, e, e);
                s.push_back({c, truth.seconds(c)});
            }
    const CompositeModel m = fit_composite_model(s);
    EXPECT_NEAR(m.latency, truth.latency, 1e-3 * truth.latency) << to_string(m);
    EXPECT_NEAR(m.bandwidth, truth.bandwidth, 1e-3 * truth.bandwidth) << to_string(m);
    EXPECT_NEAR(m.pixel_cost, truth.pixel_cost, 1e-3 * truth.pixel_cost) << to_string(m);
}

TEST(CompositeModel, LinkAndPixelCostFromTheirOwnMeasurements) {
    const CompositeModel truth{5e-6, 8e9, 2e-9};
    std::vector<std::pair<double, double>> pp;
    for (double b : {16.0, 65536.0, 1048576.0, 16777216.0})
        pp.push_back({b, truth.latency + b / truth.bandwidth});
    CompositeModel link;
    fit_link(pp, link.latency, link.bandwidth);
    EXPECT_NEAR(link.latency, truth.latency, 1e-6 * truth.latency);
    EXPECT_NEAR(link.bandwidth, truth.bandwidth, 1e-6 * truth.bandwidth);
    std::vector<CompositeSample> s;
    for (int n : {2, 4})
        for (int e : {64, 512}) {
            const CompositeCounts c = composite_counts(Composite::BinarySwap, n, e, e);
            s.push_back({c, truth.seconds(c)});
        }
    EXPECT_NEAR(fit_pixel_cost(s, link), truth.pixel_cost, 1e-6 * truth.pixel_cost);
}

}  // namespace
}  // namespace lacuna::dist
