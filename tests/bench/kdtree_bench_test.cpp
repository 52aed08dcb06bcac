#include "bench/kdtree_bench.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "common/rng.h"
#include "lacuna/error.h"
#include "lacuna/synthetic.h"

namespace lacuna::bench {
namespace {

// Opaque above 0.5 of the range, transparent below.
TransferFunction step_tf() {
    TransferFunction tf;
    tf.name = "step";
    tf.color = {{0, 1, 1, 1}};
    tf.opacity = {{0, 0.f}, {0.5, 0.f}, {0.5, 0.5f}, {1, 0.5f}};
    return tf;
}

TransferLut lut_for(const Volume& v) {
    return discretise(step_tf(), v.vis_range());
}

// Independent brute force: relax "reachable from the faces" until nothing changes.
std::vector<uint8_t> holes_by_relaxation(const HoleMap& h) {
    const int nx = h.cells[0], ny = h.cells[1], nz = h.cells[2];
    auto at = [&](int i, int j, int k) { return (size_t(k) * ny + size_t(j)) * nx + size_t(i); };
    std::vector<uint8_t> out(h.cls.size(), 0);  // 1 = outside-reachable empty
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                if (h.cls[at(i, j, k)] != 1 &&
                    (i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1))
                    out[at(i, j, k)] = 1;
    for (bool changed = true; changed;) {
        changed = false;
        for (int k = 0; k < nz; ++k)
            for (int j = 0; j < ny; ++j)
                for (int i = 0; i < nx; ++i) {
                    const size_t c = at(i, j, k);
                    if (out[c] || h.cls[c] == 1) continue;
                    const bool reach =
                        (i > 0 && out[at(i - 1, j, k)]) || (i + 1 < nx && out[at(i + 1, j, k)]) ||
                        (j > 0 && out[at(i, j - 1, k)]) || (j + 1 < ny && out[at(i, j + 1, k)]) ||
                        (k > 0 && out[at(i, j, k - 1)]) || (k + 1 < nz && out[at(i, j, k + 1)]);
                    if (reach) out[c] = 1, changed = true;
                }
    }
    return out;
}

TEST(KdBenchHoles, ClosedBoxShellHasItsInteriorAsHoles) {
    // Voxels on the faces of [2, 9]^3 are 255: cells touching them are non-empty; cells with
    // all corners in 3..8 (cells 3..7 on each axis) are enclosed: 5^3 holes.
    Volume v({12, 12, 12}, VoxelType::UInt8);
    for (int k = 2; k <= 9; ++k)
        for (int j = 2; j <= 9; ++j)
            for (int i = 2; i <= 9; ++i)
                if (i == 2 || i == 9 || j == 2 || j == 9 || k == 2 || k == 9)
                    v.set_value(i, j, k, 255);
    v.compute_range();
    const HoleMap h = find_holes(v, lut_for(v), 2);
    EXPECT_EQ(h.holes, 125u);
    EXPECT_EQ(h.holes_in(CellBox{{0, 0, 0}, {11, 11, 11}}), 125u);
    EXPECT_EQ(h.holes_in(CellBox{{3, 3, 3}, {5, 8, 8}}), 2u * 25u);
    // Opening one face lets the interior out.
    for (int i = 4; i <= 7; ++i)
        for (int j = 4; j <= 7; ++j) v.set_value(i, j, 2, 0);
    EXPECT_EQ(find_holes(v, lut_for(v), 1).holes, 0u);
}

TEST(KdBenchHoles, MatchesRelaxationOnRandomVolumes) {
    test::Rng rng{7};
    for (int t = 0; t < 6; ++t) {
        Volume v({int(6 + rng.next() % 10), int(6 + rng.next() % 10), int(6 + rng.next() % 10)},
                 VoxelType::UInt8);
        const int density = int(rng.next() % 30);  // % of bright voxels
        for (int k = 0; k < v.dims().z; ++k)
            for (int j = 0; j < v.dims().y; ++j)
                for (int i = 0; i < v.dims().x; ++i)
                    v.set_value(i, j, k, int(rng.next() % 100) < density ? 255.f : 0.f);
        v.set_value(0, 0, 0, 255);
        v.set_value(1, 0, 0, 0);
        v.compute_range();
        const HoleMap h = find_holes(v, lut_for(v), 2);
        const std::vector<uint8_t> outside = holes_by_relaxation(h);
        uint64_t holes = 0;
        for (size_t c = 0; c < h.cls.size(); ++c) {
            const bool hole = h.cls[c] != 1 && !outside[c];
            EXPECT_EQ(h.cls[c] == 2, hole) << "cell " << c << " volume " << t;
            holes += hole;
        }
        EXPECT_EQ(h.holes, holes);
    }
}

TEST(KdBench, ListsMatchTheirBoxesAndRenderExactly) {
    SyntheticOptions so;
    so.dims = {40, 40, 40};
    so.seed = 3;
    auto vol = std::make_shared<const Volume>(generate(SyntheticKind::Tree, so));
    const BenchDataset d = make_dataset("tree 40³", "test", vol, preset("mr-default"));
    KdBenchOptions o;
    o.orbit.size = 24;
    o.orbit.views = 2;
    o.repeats = 2;
    o.threads = 2;
    o.accel.kd_min_volume = 0.01f;
    o.max_boxes = {1, 2, 4, 0};
    const KdDatasetResult r = run_kd_dataset(d, 40, o, {});
    ASSERT_EQ(r.lists.size(), 4u);
    EXPECT_EQ(r.cells, 39u * 39u * 39u);
    EXPECT_EQ(r.preprocess_ms.size(), 2u);
    EXPECT_GT(r.non_empty, 0u);
    EXPECT_GT(r.table_bytes, 0u);
    // Brute force: the same partition's lists, box by box.
    AccelOptions ao = o.accel;
    ao.kd_max_boxes = 0;
    KdPartition part;
    part.build_from_tf(*vol, d.lut, kd_settings(ao));
    const HoleMap h = find_holes(*vol, d.lut, 1);
    EXPECT_EQ(r.holes, h.holes);
    EXPECT_EQ(r.leaves, int(part.list().size()));
    for (const KdListResult& l : r.lists) {
        part.make_list(l.max_boxes);
        uint64_t listed = 0, kept = 0, non_empty_inside = 0;
        for (const CellBox& b : part.boxes()) {
            listed += uint64_t(box_volume(b));
            kept += h.holes_in(b);
            for (int k = b.lo[2]; k < b.hi[2]; ++k)
                for (int j = b.lo[1]; j < b.hi[1]; ++j)
                    for (int i = b.lo[0]; i < b.hi[0]; ++i)
                        non_empty_inside +=
                            h.cls[(size_t(k) * h.cells[1] + size_t(j)) * h.cells[0] + size_t(i)] ==
                            1;
        }
        EXPECT_EQ(non_empty_inside, r.non_empty) << "every non-empty cell is in a box";
        EXPECT_EQ(l.boxes, int(part.boxes().size()));
        if (l.max_boxes > 0) {
            EXPECT_LE(l.boxes, l.max_boxes);
        }
        EXPECT_EQ(l.listed_cells, listed);
        EXPECT_DOUBLE_EQ(l.removed_percent, 100.0 * double(r.cells - listed) / double(r.cells));
        EXPECT_DOUBLE_EQ(l.removed_empty_percent,
                         100.0 * double(r.cells - listed) / double(r.cells - r.non_empty));
        EXPECT_DOUBLE_EQ(l.empty_in_boxes_percent,
                         100.0 * double(listed - r.non_empty) / double(listed));
        if (r.holes) {
            EXPECT_DOUBLE_EQ(l.holes_kept_percent, 100.0 * double(kept) / double(r.holes));
        }
        EXPECT_TRUE(l.exact) << l.max_boxes;
        EXPECT_EQ(l.frame_ms.n, 2u);
        EXPECT_GT(l.rays, 0u);
        EXPECT_LE(l.samples, r.none_samples);
    }
    KdBenchReport rep;
    rep.options = o;
    rep.datasets.push_back(r);
    EXPECT_TRUE(rep.exactness_failures().empty());
    const std::string md = kd_bench_markdown(rep, RunInfo{});
    EXPECT_NE(md.find("| all leaves |"), std::string::npos) << md;
    EXPECT_NE(md.find("| M=4 |"), std::string::npos) << md;
    const std::string csv = kd_bench_csv(rep);
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);  // header + 4 lists
}

TEST(KdBench, DatasetNames) {
    EXPECT_EQ(parse_kd_dataset("ch2bet"), DatasetId::Ch2betBrain);
    EXPECT_EQ(parse_kd_dataset("tree"), DatasetId::Tree512);
    EXPECT_EQ(parse_kd_dataset("ch2-skin"), DatasetId::Ch2Skin);
    EXPECT_THROW(parse_kd_dataset("brain"), Error);
    for (DatasetId id : default_kd_datasets()) EXPECT_EQ(parse_kd_dataset(kd_dataset_name(id)), id);
}

}  // namespace
}  // namespace lacuna::bench
