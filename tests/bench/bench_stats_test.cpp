// Statistics helpers of the benchmarks (src/bench/stats.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "bench/stats.h"

namespace lacuna::bench {
namespace {

TEST(BenchStats, MeanOfKnownValues) {
    EXPECT_DOUBLE_EQ(mean({1, 2, 3, 4}), 2.5);
    EXPECT_DOUBLE_EQ(mean({7}), 7);
    EXPECT_DOUBLE_EQ(mean({}), 0);
}

TEST(BenchStats, PercentileIsNearestRank) {
    std::vector<double> v(100);
    std::iota(v.begin(), v.end(), 1.0);  // 1..100
    std::reverse(v.begin(), v.end());    // order must not matter
    EXPECT_DOUBLE_EQ(percentile(v, 99), 99);
    EXPECT_DOUBLE_EQ(percentile(v, 50), 50);
    EXPECT_DOUBLE_EQ(percentile(v, 100), 100);
    EXPECT_DOUBLE_EQ(percentile(v, 1), 1);
    std::vector<double> w(200);
    std::iota(w.begin(), w.end(), 1.0);
    EXPECT_DOUBLE_EQ(percentile(w, 99), 198);
}

TEST(BenchStats, P99OfAShortOrbitIsTheSlowestFrame) {
    std::vector<double> frames(36, 10.0);
    frames[17] = 25.0;
    EXPECT_DOUBLE_EQ(percentile(frames, 99), 25.0);
    EXPECT_DOUBLE_EQ(percentile({3, 1, 2}, 50), 2);
    EXPECT_DOUBLE_EQ(percentile({4}, 99), 4);
    EXPECT_DOUBLE_EQ(percentile({}, 99), 0);
}

TEST(BenchStats, SummaryHoldsMeanP99MinMax) {
    const Summary s = summarize({4, 1, 3, 2});
    EXPECT_EQ(s.n, 4u);
    EXPECT_DOUBLE_EQ(s.mean, 2.5);
    EXPECT_DOUBLE_EQ(s.p99, 4);
    EXPECT_DOUBLE_EQ(s.min, 1);
    EXPECT_DOUBLE_EQ(s.max, 4);
    EXPECT_NE(to_string(s).find("mean 2.5"), std::string::npos) << to_string(s);
}

}  // namespace
}  // namespace lacuna::bench
