// `lacuna bench li` in-process on a tiny synthetic dataset: every column is there, ESS and
// ESS+M give the Basic bytes, ESS+CC stays within its threshold's bound, and Figure 6 has one
// entry per frame of its orbit. No timing assertions (timings never gate tests).
#include <gtest/gtest.h>

#include <algorithm>

#include "bench/datasets.h"
#include "bench/li.h"
#include "lacuna/synthetic.h"

namespace lacuna::bench {
namespace {

TEST(BenchLi, TinyRunHasEveryColumnIsExactAndRecordsFigure6) {
    SyntheticOptions so;
    so.dims = {40, 36, 32};
    auto vol = std::make_shared<const Volume>(generate(SyntheticKind::SphereShells, so));
    const std::vector<BenchDataset> ds = {
        make_dataset("shells", "generate(sphere-shells, 40x36x32)", vol, preset("mr-default"))};
    LiOptions o;
    o.orbit.views = 3;
    o.orbit.size = 48;
    o.threads = 2;
    o.updates_views = 7;
    const LiReport rep = run_li(ds, o);
    ASSERT_EQ(rep.datasets.size(), 1u);
    const LiDataset& d = rep.datasets[0];
    for (const char* c : {"Basic", "ESS", "ESS+CC", "ESS+M", "ESS+C", "march none"}) {
        const LiColumn* col = d.find(c);
        ASSERT_NE(col, nullptr) << c;
        EXPECT_EQ(col->frame_ms.size(), 3u) << c;
        EXPECT_GT(col->samples, 0.0) << c;
    }
    EXPECT_TRUE(d.ess_exact);
    EXPECT_TRUE(d.map_only_exact);
    // Threshold 0.95: no channel may differ by more than 5% of full scale (plus rounding).
    EXPECT_LE(d.max_cc_diff, int(0.05 * 255) + 2);
    // Skipping never adds samples: ESS takes at most Basic's, ESS+CC at most ESS's.
    EXPECT_LE(d.find("ESS")->samples, d.find("Basic")->samples);
    EXPECT_LE(d.find("ESS+CC")->samples, d.find("ESS")->samples);
    EXPECT_GT(d.boxes, 0u);
    // Growing boxes: partition and BSP build times are reported and within the source's build.
    EXPECT_GE(d.partition_ms, 0.0);
    EXPECT_GE(d.bsp_ms, 0.0);
    EXPECT_LE(d.partition_ms + d.bsp_ms, d.source_ms + 1e-6);
    // Polygon set-up is measured (CPU and wall shares of the frame).
    for (const char* c : {"ESS", "Basic"}) {
        EXPECT_GT(d.find(c)->setup_fraction, 0.0) << c;
        EXPECT_LT(d.find(c)->setup_fraction, 1.0) << c;
        EXPECT_GT(d.find(c)->setup_wall, 0.0) << c;
    }
    // Figure 6: one entry per frame; the actual updates never exceed the desired ones.
    const LiUpdates& u = rep.figure6;
    EXPECT_EQ(u.dataset, "shells");
    ASSERT_EQ(u.desired.size(), 7u);
    ASSERT_EQ(u.actual.size(), 7u);
    for (size_t i = 0; i < u.desired.size(); ++i) {
        EXPECT_GE(u.actual[i], 0);
        EXPECT_LE(u.actual[i], u.desired[i]) << "frame " << i;
        EXPECT_GE(u.skipped[i], 0.0);
        EXPECT_LE(u.skipped[i], 1.0);
    }
    const std::string csv = li_updates_csv(rep);
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 8);
    EXPECT_NE(li_updates_gnuplot(rep, "/tmp/x.png").find("$d << EOD"), std::string::npos);
}

}  // namespace
}  // namespace lacuna::bench
