// `lacuna bench faludi` in-process on tiny synthetic datasets: the table is complete, exact,
// and its speedups agree with its sample counts. No timing assertions (timings never gate tests).
#include "bench/faludi.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include "bench/datasets.h"
#include "bench/plot.h"
#include "bench/report.h"
#include "bench/sweep.h"
#include "lacuna/error.h"
#include "lacuna/synthetic.h"

namespace lacuna::bench {
namespace {

std::shared_ptr<const Volume> synthetic(SyntheticKind k, int n) {
    SyntheticOptions so;
    so.dims = {n, n, n};
    return std::make_shared<const Volume>(generate(k, so));
}

std::vector<BenchDataset> tiny_datasets() {
    return {make_dataset("tree", "generate(tree, 32^3)", synthetic(SyntheticKind::Tree, 32),
                         preset("mr-default")),
            make_dataset("blobs-gap", "generate(noise-blobs, 24^3)",
                         synthetic(SyntheticKind::NoiseBlobs, 24), preset("mr-gap"))};
}

FaludiOptions tiny_options() {
    FaludiOptions o;
    o.orbit.views = 2;
    o.orbit.size = 32;
    o.threads = 2;
    o.tf_repeats = 2;
    return o;
}

size_t count_lines(const std::string& s) {
    return size_t(std::count(s.begin(), s.end(), '\n'));
}

TEST(BenchFaludi, TinyRunIsExactAndSpeedupsMatchSampleCounts) {
    const FaludiReport rep = run_faludi(tiny_datasets(), tiny_options());
    const std::vector<AccelKind> kinds = all_accel_kinds();
    ASSERT_EQ(rep.datasets.size(), 2u);
    EXPECT_TRUE(rep.exactness_failures().empty());
    for (const DatasetResult& d : rep.datasets) {
        ASSERT_EQ(d.rows.size(), 2u) << d.name;
        EXPECT_EQ(d.structures.size(), kinds.size());
        EXPECT_GT(d.visible_cell_fraction, 0.0);
        EXPECT_LT(d.visible_cell_fraction, 1.0);
        for (const RowResult& r : d.rows) {
            ASSERT_EQ(r.cells.size(), kinds.size());
            const CellResult& none = r.cells[0];
            EXPECT_EQ(none.kind, AccelKind::None);
            EXPECT_DOUBLE_EQ(none.speedup, 1.0);
            ASSERT_GT(r.ideal_samples, 0u);
            EXPECT_LE(r.ideal_samples, none.samples);
            EXPECT_DOUBLE_EQ(r.ideal_speedup(), double(none.samples) / double(r.ideal_samples));
            for (const CellResult& c : r.cells) {
                EXPECT_TRUE(c.exact) << d.name << " " << to_string(c.kind);
                EXPECT_EQ(c.frame_ms.n, 2u);
                EXPECT_EQ(c.rays, none.rays) << "every structure sees the same rays";
                EXPECT_LE(c.samples, none.samples) << to_string(c.kind);
                EXPECT_GE(c.samples, r.ideal_samples) << to_string(c.kind);
                EXPECT_DOUBLE_EQ(c.sample_reduction, double(none.samples) / double(c.samples));
                EXPECT_LE(c.sample_reduction, r.ideal_speedup() * (1 + 1e-12));
                EXPECT_DOUBLE_EQ(c.speedup, none.frame_ms.mean / c.frame_ms.mean);
            }
        }
        // The early-exit row never takes more samples than marching only.
        EXPECT_LE(d.rows[1].cells[0].samples, d.rows[0].cells[0].samples);
        EXPECT_LE(d.rows[1].ideal_samples, d.rows[0].ideal_samples);
        for (const StructureResult& s : d.structures)
            if (s.kind != AccelKind::None) EXPECT_GT(s.bytes, 0u) << to_string(s.kind);
        // The grid was refined (its finer per-TF level is what the frames used).
        EXPECT_GT(d.find(AccelKind::Grid)->refine_ms, 0.0) << d.name;
    }
}

// Without refine() the structures are timed as right after an edit: the same exact images,
// no refine time, and the grid takes at least the samples of its refined self.
TEST(BenchFaludi, NoRefineIsExactAndRefiningNeverAddsSamples) {
    FaludiOptions o = tiny_options();
    o.accels = {AccelKind::Grid};
    const FaludiReport refined = run_faludi(tiny_datasets(), o);
    o.refine = false;
    const FaludiReport plain = run_faludi(tiny_datasets(), o);
    EXPECT_TRUE(plain.exactness_failures().empty());
    for (size_t i = 0; i < plain.datasets.size(); ++i) {
        EXPECT_EQ(plain.datasets[i].find(AccelKind::Grid)->refine_ms, 0.0);
        for (size_t r = 0; r < plain.datasets[i].rows.size(); ++r)
            EXPECT_GE(plain.datasets[i].rows[r].find(AccelKind::Grid)->samples,
                      refined.datasets[i].rows[r].find(AccelKind::Grid)->samples);
    }
}

TEST(BenchFaludi, ReportsHoldTheTableAndEveryNumber) {
    const FaludiReport rep = run_faludi(tiny_datasets(), tiny_options());
    RunInfo info = collect_run_info("lacuna bench faludi --size 32 --views 2");
    const std::string md = faludi_markdown(rep, info);
    EXPECT_NE(md.find("`lacuna bench faludi --size 32 --views 2`"), std::string::npos);
    EXPECT_NE(md.find("32×32 pixels, 2 views"), std::string::npos)
        << "the table states its settings";
    EXPECT_NE(md.find("| Dataset |  | none | distance | chebyshev | boolean | minmax | bitfield |"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| **tree** | Marching only [ms] |"), std::string::npos);
    EXPECT_NE(md.find("+ Early exit [ms]"), std::string::npos);
    EXPECT_NE(md.find("Generation [ms]"), std::string::npos);
    EXPECT_NE(md.find("Every structure's view 0 equals none's"), std::string::npos);
    EXPECT_EQ(md.find("**NO**"), std::string::npos);
    const std::string csv = faludi_csv(rep);
    EXPECT_EQ(count_lines(csv), 1 + 2 * 2 * all_accel_kinds().size());
    std::istringstream lines(csv);
    std::string header, line;
    std::getline(lines, header);
    EXPECT_NE(header.find(",exact,"), std::string::npos);
    while (std::getline(lines, line)) EXPECT_NE(line.find(",yes,"), std::string::npos) << line;
}

TEST(BenchFaludi, TargetsNeedTheirRows) {
    FaludiOptions o = tiny_options();
    o.orbit.views = 1;
    o.modes = {RowMode::MarchingOnly};
    const FaludiReport rep = run_faludi(tiny_datasets(), o);
    const auto targets = check_targets(rep);
    ASSERT_EQ(targets.size(), 9u);
    EXPECT_NE(targets[0].target.find("default structure (" + to_string(default_accel()) + ")"),
              std::string::npos)
        << targets[0].target;
    // No >= 512^3 volume in the tiny run: those targets are not measured, never "met".
    EXPECT_EQ(targets[2].status, TargetStatus::NotMeasured);
    EXPECT_EQ(targets[5].status, TargetStatus::NotMeasured);
    // The default structure's share, bitfield's share of ideal and TF change are measured on
    // any run.
    EXPECT_NE(targets[0].status, TargetStatus::NotMeasured);
    EXPECT_NE(targets[1].status, TargetStatus::NotMeasured);
    EXPECT_NE(targets[6].status, TargetStatus::NotMeasured);
}

TEST(BenchFaludi, ColumnsAlwaysStartWithNone) {
    EXPECT_EQ(bench_columns({AccelKind::Bitfield, AccelKind::MinMax, AccelKind::Bitfield}),
              (std::vector<AccelKind>{AccelKind::None, AccelKind::Bitfield, AccelKind::MinMax}));
    EXPECT_EQ(bench_columns(all_accel_kinds()), all_accel_kinds());
}

TEST(BenchDatasets, NamesRoundTripAndUnknownNamesListTheValidOnes) {
    for (DatasetId id : all_datasets()) EXPECT_EQ(parse_dataset(to_string(id)), id);
    EXPECT_EQ(dataset_names().size(), all_datasets().size());
    try {
        parse_dataset("ch3");
        FAIL() << "expected lacuna::Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("ch2better-gap"), std::string::npos) << e.what();
    }
}

TEST(BenchDatasets, GeneratedTreeIsLabelledWithHowItWasMade) {
    DatasetSource src;
    src.tree_size = 24;
    const auto ds = load_datasets({DatasetId::Tree512}, src);
    ASSERT_EQ(ds.size(), 1u);
    EXPECT_EQ(ds[0].name, "tree24");
    EXPECT_NE(ds[0].description.find("generate(tree, 24^3 uint8"), std::string::npos)
        << ds[0].description;
    EXPECT_EQ(ds[0].volume->dims().x, 24);
    EXPECT_EQ(ds[0].lut.size(), kDefaultLutSize);
}

TEST(BenchSweep, TinySweepCoversTheGridAndPicksAMeasuredSetting) {
    SweepOptions o;
    o.orbit = {1, 24, 20.f};
    o.leaves = {2, 4};
    o.bits = {8, 64};
    o.threads = 2;
    const SweepResult r = run_sweep(tiny_datasets(), o);
    EXPECT_EQ(r.leaf_bits.size(), 2u * 2u * 2u);
    EXPECT_TRUE(r.exactness_failures().empty());
    EXPECT_TRUE(r.best_leaf == 2 || r.best_leaf == 4);
    EXPECT_TRUE(r.best_bits == 8 || r.best_bits == 64);
    // Every level of both trees, both traversals.
    size_t expected = 0;
    for (const SweepPoint& p : r.levels)
        if (p.bidirectional) ++expected;
    EXPECT_EQ(r.levels.size(), 2 * expected);
    for (const SweepPoint& p : r.levels) {
        EXPECT_EQ(p.leaf, r.best_leaf);
        EXPECT_GE(p.skipped_levels(), 0);
        EXPECT_LT(p.skipped_levels(), p.levels);
    }
    EXPECT_GE(r.best_skipped_levels, 0);
    EXPECT_EQ(count_lines(sweep_leaf_bits_csv(r)), 1 + r.leaf_bits.size());
    EXPECT_EQ(count_lines(sweep_levels_csv(r)), 1 + r.levels.size());
    const std::string md = sweep_markdown(r, collect_run_info("sweep"), {});
    EXPECT_NE(md.find("Recommended defaults"), std::string::npos);
    const std::string script = leaf_bits_gnuplot(r, "/tmp/x.png");
    EXPECT_NE(script.find("$d0_0 << EOD"), std::string::npos);
    EXPECT_NE(levels_gnuplot(r, "/tmp/y.png").find("top-down"), std::string::npos);
}

}  // namespace
}  // namespace lacuna::bench
