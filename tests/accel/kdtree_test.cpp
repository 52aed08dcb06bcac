// The kd-tree partition (src/accel/kdtree_partition.h, summed_volume_table.h) and --accel kdtree
// (src/accel/kdtree.h) against brute force: the summed-volume table's box counts (Eqs. 5, 6),
// the bounding-volume scan (Eq. 3), the split choice (Eq. 1), the halting criteria, the
// M-limited subvolume list (Section 2.2), the region answers, and the visibility order. Image
// exactness is the conformance suite's job (it runs every AccelKind).
#include "accel/kdtree.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <memory>
#include <set>

#include "accel/kdtree_partition.h"
#include "accel/summed_volume_table.h"
#include "accel_test_util.h"
#include "apps/cli_run.h"
#include "lacuna/error.h"
#include "lacuna/renderer.h"
#include "lacuna/synthetic.h"

namespace lacuna {
namespace {

using namespace accel_test;

// ---- helpers --------------------------------------------------------------------------------

// A random 0/1 cell grid: empty, full, sparse points, or random boxes.
std::vector<uint8_t> random_flags(const int n[3], Rng& rng) {
    const size_t count = size_t(n[0]) * n[1] * n[2];
    std::vector<uint8_t> f(count, 0);
    switch (rng.range(0, 5)) {
        case 0:
            break;  // all empty
        case 1:
            std::fill(f.begin(), f.end(), 1);
            break;
        case 2: {
            const int p = rng.range(1, 6);
            for (int s = 0; s < p; ++s) f[size_t(rng.range(0, int(count) - 1))] = 1;
            break;
        }
        case 3: {
            const float d = rng.uniform();
            for (auto& x : f) x = rng.uniform() < d;
            break;
        }
        default: {
            const int boxes = rng.range(1, 5);
            for (int b = 0; b < boxes; ++b) {
                int lo[3], hi[3];
                for (int a = 0; a < 3; ++a) {
                    lo[a] = rng.range(0, n[a] - 1);
                    hi[a] = std::min(n[a], lo[a] + rng.range(1, std::max(1, n[a] / 2)));
                }
                for (int k = lo[2]; k < hi[2]; ++k)
                    for (int j = lo[1]; j < hi[1]; ++j)
                        for (int i = lo[0]; i < hi[0]; ++i)
                            f[(size_t(k) * n[1] + j) * n[0] + i] = 1;
            }
        }
    }
    return f;
}

// Fills a table with `flags` as step 1 does (rows summed along x) and runs step 2.
template <class Count>
void fill_table(SummedVolumeTable<Count>& t, const int n[3], const std::vector<uint8_t>& flags,
                bool literal_eq5 = false) {
    t.resize(n);
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j) {
            Count* row = t.row(j, k);
            Count s = 0;
            for (int i = 0; i < n[0]; ++i) {
                const Count f = flags[(size_t(k) * n[1] + j) * n[0] + i];
                s += f;
                row[i] = literal_eq5 ? f : s;
            }
        }
    if (literal_eq5)
        t.build_eq5();
    else
        t.build_from_row_sums();
}

uint64_t brute_count(const int n[3], const std::vector<uint8_t>& f, const CellBox& b) {
    uint64_t c = 0;
    for (int k = b.lo[2]; k < b.hi[2]; ++k)
        for (int j = b.lo[1]; j < b.hi[1]; ++j)
            for (int i = b.lo[0]; i < b.hi[0]; ++i) c += f[(size_t(k) * n[1] + j) * n[0] + i];
    return c;
}

// Tight box of the flagged cells inside `b`; false if none.
bool brute_bv(const int n[3], const std::vector<uint8_t>& f, const CellBox& b, CellBox& out) {
    bool any = false;
    CellBox r{{INT32_MAX, INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN, INT32_MIN}};
    for (int k = b.lo[2]; k < b.hi[2]; ++k)
        for (int j = b.lo[1]; j < b.hi[1]; ++j)
            for (int i = b.lo[0]; i < b.hi[0]; ++i)
                if (f[(size_t(k) * n[1] + j) * n[0] + i]) {
                    any = true;
                    const int c[3] = {i, j, k};
                    for (int a = 0; a < 3; ++a) {
                        r.lo[a] = std::min(r.lo[a], c[a]);
                        r.hi[a] = std::max(r.hi[a], c[a] + 1);
                    }
                }
    if (any) out = r;
    return any;
}

CellBox random_box(const int n[3], Rng& rng) {
    CellBox b;
    for (int a = 0; a < 3; ++a) {
        int x = rng.range(0, n[a]), y = rng.range(0, n[a]);
        if (x > y) std::swap(x, y);
        b.lo[a] = x, b.hi[a] = y;
    }
    return b;
}

std::string dims_string(const int n[3]) {
    return std::to_string(n[0]) + "x" + std::to_string(n[1]) + "x" + std::to_string(n[2]);
}

bool contains(const CellBox& b, const int c[3]) {
    for (int a = 0; a < 3; ++a)
        if (c[a] < b.lo[a] || c[a] >= b.hi[a]) return false;
    return true;
}
bool inside(const CellBox& inner, const CellBox& outer) {
    for (int a = 0; a < 3; ++a)
        if (inner.lo[a] < outer.lo[a] || inner.hi[a] > outer.hi[a]) return false;
    return true;
}
bool overlap(const CellBox& x, const CellBox& y) {
    for (int a = 0; a < 3; ++a)
        if (x.hi[a] <= y.lo[a] || y.hi[a] <= x.lo[a]) return false;
    return true;
}

// Per-cell flag as the partition classified it (single-cell box count of its table).
bool classified(const KdPartition& p, int i, int j, int k) {
    const CellBox b{{i, j, k}, {i + 1, j + 1, k + 1}};
    return p.wide_counts() ? p.table64().count(b) != 0 : p.table32().count(b) != 0;
}

// Settings that split a lot on small grids (so trees are deep and lists long).
KdSettings fine_settings(Rng& rng) {
    KdSettings s;
    s.delta = rng.range(1, 3);
    s.min_volume = rng.coin() ? 0.f : 0.01f * float(rng.range(0, 10));
    s.min_gain = rng.coin() ? 0.f : 0.01f * float(rng.range(0, 10));
    s.max_depth = rng.range(0, 12);
    s.threads = rng.range(1, 2);
    return s;
}

// A random volume and a LUT that makes part of it visible.
struct VolumeCase {
    Volume v;
    TransferLut lut;
};
VolumeCase random_case(Rng& rng, int lo = 3, int hi = 22) {
    const VoxelType t = kAllTypes[rng.range(0, 3)];
    VolumeCase c{random_volume(t, random_dims(rng, lo, hi), rng), {}};
    const ValueRange vis = random_vis(c.v, rng);
    const int size = rng.coin(4) ? rng.range(2, 300) : kDefaultLutSize;
    const ValueToLut map(vis, size);
    c.lut = random_lut(vis, size, rng, voxel_entries(c.v, map, rng));
    return c;
}

// ---- step 2: summed-volume table ------------------------------------------------------------

template <class Count>
void check_table_counts(uint64_t seed) {
    Rng rng{seed};
    for (int trial = 0; trial < 60; ++trial) {
        const int n[3] = {rng.range(1, 19), rng.range(1, 19), rng.range(1, 19)};
        const std::vector<uint8_t> f = random_flags(n, rng);
        SummedVolumeTable<Count> fast, literal;
        fill_table(fast, n, f);
        fill_table(literal, n, f, true);
        const std::string what = dims_string(n) + " trial " + std::to_string(trial);
        // Eq. 5 literally and the row-sum pass give the same table, cell for cell.
        for (int k = 0; k < n[2]; ++k)
            for (int j = 0; j < n[1]; ++j)
                for (int i = 0; i < n[0]; ++i)
                    ASSERT_EQ(fast.at(i, j, k), literal.at(i, j, k))
                        << what << " at " << i << "," << j << "," << k;
        ASSERT_EQ(uint64_t(fast.total()), brute_count(n, f, CellBox{{0, 0, 0}, {n[0], n[1], n[2]}}))
            << what;
        for (int q = 0; q < 200; ++q) {
            const CellBox b = random_box(n, rng);
            ASSERT_EQ(uint64_t(fast.count(b)), brute_count(n, f, b))
                << what << " box " << box_string(b);
        }
    }
}

TEST(KdTreeSummedVolumeTable, BoxCountsMatchBruteForce32) {
    check_table_counts<uint32_t>(1);
}
TEST(KdTreeSummedVolumeTable, BoxCountsMatchBruteForce64) {
    check_table_counts<uint64_t>(2);
}

TEST(KdTreeSummedVolumeTable, SingleCellAndBorderBoxesUseZeroForMinusOne) {
    const int n[3] = {4, 3, 2};
    std::vector<uint8_t> f(24, 0);
    f[0] = 1;   // (0,0,0)
    f[23] = 1;  // (3,2,1)
    SummedVolumeTable<uint32_t> t;
    fill_table(t, n, f);
    EXPECT_EQ(t.at(-1, 0, 0), 0u);
    EXPECT_EQ(t.count(CellBox{{0, 0, 0}, {1, 1, 1}}), 1u);
    EXPECT_EQ(t.count(CellBox{{3, 2, 1}, {4, 3, 2}}), 1u);
    EXPECT_EQ(t.count(CellBox{{1, 0, 0}, {3, 3, 2}}), 0u);
    EXPECT_EQ(t.count(CellBox{{2, 2, 2}, {2, 2, 2}}), 0u);  // an empty box
    EXPECT_EQ(t.total(), 2u);
}

// ---- bounding volume (Eq. 3) ----------------------------------------------------------------

TEST(KdTreeBoundingVolume, ScanOnAllSixSidesMatchesBruteForce) {
    Rng rng{3};
    for (int trial = 0; trial < 80; ++trial) {
        const int n[3] = {rng.range(1, 24), rng.range(1, 24), rng.range(1, 24)};
        const std::vector<uint8_t> f = random_flags(n, rng);
        SummedVolumeTable<uint32_t> t;
        fill_table(t, n, f);
        for (int q = 0; q < 60; ++q) {
            const CellBox b = random_box(n, rng);
            CellBox got{}, want{};
            const bool has = bounding_volume(t, b, got);
            const std::string what = dims_string(n) + " box " + box_string(b);
            ASSERT_EQ(has, brute_bv(n, f, b, want)) << what;
            if (!has) continue;
            ASSERT_TRUE(same_box(got, want))
                << what << ": scan " << box_string(got) << ", brute " << box_string(want);
            // The galloping search finds the same boundary as the paper's slab-by-slab scan.
            for (int a = 0; a < 3; ++a)
                for (int side = 0; side < 2; ++side)
                    ASSERT_EQ(bv_scan(t, b, a, side), bv_scan_linear(t, b, a, side))
                        << what << " axis " << a << " side " << side;
        }
    }
}

// ---- step 3: cost function and halting ------------------------------------------------------

TEST(KdTreeSplit, CostFunctionChoosesTheBruteForceOptimalCandidatePlane) {
    Rng rng{4};
    for (int trial = 0; trial < 120; ++trial) {
        const int n[3] = {rng.range(2, 26), rng.range(2, 26), rng.range(2, 26)};
        std::vector<uint8_t> f = random_flags(n, rng);
        f[size_t(rng.range(0, int(f.size()) - 1))] = 1;
        SummedVolumeTable<uint32_t> t;
        fill_table(t, n, f);
        // The node: the BV of the grid or of a random box (nodes are always tight BVs).
        CellBox node;
        if (!rng.coin() || !bounding_volume(t, random_box(n, rng), node))
            ASSERT_TRUE(bounding_volume(t, CellBox{{0, 0, 0}, {n[0], n[1], n[2]}}, node));
        const int delta = rng.range(1, 5);
        const KdSplit sp = choose_split(t, node, delta, rng.range(1, 2));
        const std::string what =
            dims_string(n) + " node " + box_string(node) + " delta " + std::to_string(delta);
        // Brute force: the longest axis, every candidate plane, BVs by scanning the cells.
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (node.hi[a] - node.lo[a] > node.hi[axis] - node.lo[axis]) axis = a;
        int64_t best = std::numeric_limits<int64_t>::max();
        int best_plane = -1, candidates = 0;
        for (int p = node.lo[axis] + delta; p < node.hi[axis]; p += delta) {
            ++candidates;
            CellBox l = node, r = node, bv;
            l.hi[axis] = p;
            r.lo[axis] = p;
            int64_t cost = 0;
            if (brute_bv(n, f, l, bv)) cost += box_volume(bv);
            if (brute_bv(n, f, r, bv)) cost += box_volume(bv);
            if (cost < best) best = cost, best_plane = p;
        }
        ASSERT_EQ(sp.valid, candidates > 0) << what;
        if (!sp.valid) continue;
        EXPECT_EQ(sp.axis, axis) << what;
        EXPECT_EQ(sp.candidates, candidates) << what;
        EXPECT_EQ(sp.cost, best) << what;
        EXPECT_EQ(sp.plane, best_plane) << what;
    }
}

// Every interior node passed all three halting tests; every leaf failed one of them.
void check_halting(const KdPartition& p, const std::string& what) {
    const KdSettings& s = p.settings();
    const double total = double(p.total_cells());
    const double min_volume = std::ceil(double(s.min_volume) * total);
    for (size_t i = 0; i < p.nodes().size(); ++i) {
        const KdNode& n = p.nodes()[i];
        const double vol = double(box_volume(n.box));
        const std::string w = what + " node " + std::to_string(i) + " " + box_string(n.box) +
                              " depth " + std::to_string(n.depth);
        KdSplit sp;
        if (p.wide_counts())
            sp = choose_split(p.table64(), n.box, p.delta(), 1);
        else
            sp = choose_split(p.table32(), n.box, p.delta(), 1);
        const bool gain_ok = sp.valid && double(int64_t(vol) - sp.cost) >= double(s.min_gain) * vol;
        if (!n.is_leaf()) {
            ASSERT_LT(n.depth, s.max_depth) << w << ": split at the maximum depth";
            ASSERT_GE(vol, min_volume) << w << ": split below the minimum volume";
            ASSERT_TRUE(gain_ok) << w << ": split removing less than min_gain";
            ASSERT_EQ(n.axis, sp.axis) << w;
            ASSERT_EQ(n.plane, sp.plane) << w;
            const KdNode& l = p.nodes()[size_t(n.left)];
            const KdNode& r = p.nodes()[size_t(n.left + 1)];
            ASSERT_EQ(l.depth, n.depth + 1) << w;
            ASSERT_EQ(n.leaves, l.leaves + r.leaves) << w;
            ASSERT_LE(l.box.hi[n.axis], n.plane) << w;
            ASSERT_GE(r.box.lo[n.axis], n.plane) << w;
            ASSERT_TRUE(inside(l.box, n.box) && inside(r.box, n.box)) << w;
        } else {
            ASSERT_EQ(n.leaves, 1) << w;
            const bool halted = n.depth >= s.max_depth || vol < min_volume || !gain_ok;
            ASSERT_TRUE(halted) << w << ": a leaf that no halting criterion stopped";
        }
    }
}

TEST(KdTreeHalting, EveryCriterionIsRespected) {
    Rng rng{5};
    for (int trial = 0; trial < 150; ++trial) {
        const int n[3] = {rng.range(2, 30), rng.range(2, 30), rng.range(2, 30)};
        Volume v({n[0] + 1, n[1] + 1, n[2] + 1}, VoxelType::UInt8);
        const std::vector<uint8_t> f = random_flags(n, rng);
        // Voxel (i,j,k) = 255 where cell (i,j,k) is flagged: a threshold of 255 flags a superset.
        for (int k = 0; k < n[2]; ++k)
            for (int j = 0; j < n[1]; ++j)
                for (int i = 0; i < n[0]; ++i)
                    if (f[(size_t(k) * n[1] + j) * n[0] + i]) v.set_value(i, j, k, 255);
        v.compute_range();
        // Thresholds spread so that each criterion is the one that stops some nodes.
        KdSettings s = fine_settings(rng);
        const float gains[] = {0.f, 0.02f, 0.05f, 0.1f, 0.2f, 0.35f};
        const float volumes[] = {0.f, 0.005f, 0.02f, 0.1f, 0.3f};
        s.min_gain = gains[rng.range(0, 5)];
        s.min_volume = volumes[rng.range(0, 4)];
        s.delta = rng.coin() ? 0 : s.delta;
        KdPartition p;
        p.build_from_threshold(v, 255.f, s);
        check_halting(p, dims_string(n) + " " + to_string(s));
        for (const KdNode& node : p.nodes()) ASSERT_LE(node.depth, s.max_depth);
    }
}

TEST(KdTreeHalting, EachCriterionAloneStopsTheRoot) {
    SyntheticOptions so;
    so.dims = {40, 36, 44};
    const Volume v = generate(SyntheticKind::Tree, so);
    const TransferLut lut = discretise(preset("mr-default"), v.vis_range());
    KdSettings s;
    s.min_volume = 0, s.min_gain = 0;
    KdPartition p;
    p.build_from_tf(v, lut, s);
    ASSERT_GT(p.nodes().size(), 1u) << "the tree must split at all for this test to mean anything";
    KdSettings depth0 = s;
    depth0.max_depth = 0;
    p.build_from_tf(v, lut, depth0);
    EXPECT_EQ(p.nodes().size(), 1u) << "max_depth 0";
    KdSettings vol1 = s;
    vol1.min_volume = 1.f;  // the root BV is smaller than the grid
    p.build_from_tf(v, lut, vol1);
    EXPECT_EQ(p.nodes().size(), 1u) << "min_volume 1";
    KdSettings gain1 = s;
    gain1.min_gain = 1.f;  // no split removes everything
    p.build_from_tf(v, lut, gain1);
    EXPECT_EQ(p.nodes().size(), 1u) << "min_gain 1";
    KdSettings big_delta = s;
    big_delta.delta = 1000;  // no candidate plane fits
    p.build_from_tf(v, lut, big_delta);
    EXPECT_EQ(p.nodes().size(), 1u) << "delta 1000";
}

TEST(KdTreeHalting, DefaultsFollowThePaper) {
    const int c256[3] = {255, 255, 255}, c512[3] = {511, 400, 300}, small[3] = {20, 30, 10};
    EXPECT_EQ(default_kd_delta(c256), 4);
    EXPECT_EQ(default_kd_delta(c512), 8);
    EXPECT_EQ(default_kd_delta(small), 1);
    const KdSettings s = kd_settings(AccelOptions{});
    EXPECT_EQ(s.max_boxes, 0);
    EXPECT_FLOAT_EQ(s.min_volume, 0.1f);
    EXPECT_FLOAT_EQ(s.min_gain, 0.05f);
    EXPECT_EQ(s.max_depth, 10);
}

TEST(KdTreePartition, WideAndNarrowTablesBuildTheSameTree) {
    Rng rng{6};
    for (int trial = 0; trial < 20; ++trial) {
        const VolumeCase c = random_case(rng);
        KdSettings s = fine_settings(rng);
        KdPartition narrow, wide;
        narrow.build_from_tf(c.v, c.lut, s);
        s.wide_counts = true;
        wide.build_from_tf(c.v, c.lut, s);
        ASSERT_FALSE(narrow.wide_counts());
        ASSERT_TRUE(wide.wide_counts());
        ASSERT_EQ(narrow.nodes().size(), wide.nodes().size()) << describe(c.v, c.lut);
        for (size_t i = 0; i < narrow.nodes().size(); ++i)
            ASSERT_EQ(0, std::memcmp(&narrow.nodes()[i], &wide.nodes()[i], sizeof(KdNode)))
                << describe(c.v, c.lut) << " node " << i;
        ASSERT_EQ(narrow.list(), wide.list());
    }
}

// ---- step 1: classification -----------------------------------------------------------------

TEST(KdTreeClassification, TfCellsAreTheBuiltRangesVisibleCellsAndCoverTheBruteOnes) {
    Rng rng{7};
    for (int trial = 0; trial < 40; ++trial) {
        const VolumeCase c = random_case(rng);
        KdPartition p;
        p.build_from_tf(c.v, c.lut, fine_settings(rng));
        const BuiltRanges built = built_ranges(c.v, c.lut.map());
        const BruteRanges brute = brute_ranges(c.v, c.lut.map());
        const CellGrid& g = built.g;
        for (int k = 0; k < g.n[2]; ++k)
            for (int j = 0; j < g.n[1]; ++j)
                for (int i = 0; i < g.n[0]; ++i) {
                    const size_t id = g.index(i, j, k);
                    const bool want = scan_visible(c.lut, built.lo[id], built.hi[id]);
                    ASSERT_EQ(classified(p, i, j, k), want)
                        << describe(c.v, c.lut) << " cell " << i << "," << j << "," << k;
                    if (scan_visible(c.lut, brute.lo[id], brute.hi[id]))
                        ASSERT_TRUE(want)
                            << describe(c.v, c.lut) << ": a visible cell classified empty";
                }
    }
}

TEST(KdTreeClassification, ThresholdFlagsCellsWhoseLargestCornerReachesIt) {
    Rng rng{8};
    for (int trial = 0; trial < 40; ++trial) {
        const VoxelType t = kAllTypes[rng.range(0, 3)];
        const Volume v = random_volume(t, random_dims(rng, 2, 20), rng);
        const float threshold =
            v.value(rng.range(0, v.dims().x - 1), 0, 0) + (rng.coin() ? 0.f : 0.5f);
        KdPartition p;
        p.build_from_threshold(v, threshold, KdSettings{});
        const BruteRanges brute = brute_ranges(v, ValueToLut(v.vis_range(), kDefaultLutSize));
        const CellGrid& g = brute.g;
        for (int k = 0; k < g.n[2]; ++k)
            for (int j = 0; j < g.n[1]; ++j)
                for (int i = 0; i < g.n[0]; ++i)
                    ASSERT_EQ(classified(p, i, j, k), brute.vmax[g.index(i, j, k)] >= threshold)
                        << to_string(v) << " threshold " << threshold << " cell " << i << "," << j
                        << "," << k;
    }
}

// ---- step 4: the subvolume list -------------------------------------------------------------

void check_list(const KdPartition& p, int m, const std::string& what) {
    const std::vector<CellBox> boxes = p.boxes();
    const int leaves = p.nodes().empty() ? 0 : p.nodes()[0].leaves;
    if (m > 0) ASSERT_LE(int(boxes.size()), m) << what;
    if (m == 0 || m >= leaves) ASSERT_EQ(int(boxes.size()), leaves) << what << ": every leaf";
    if (m == 1 && !p.nodes().empty()) ASSERT_TRUE(same_box(boxes[0], p.nodes()[0].box)) << what;
    const int* n = p.cells();
    const CellBox grid{{0, 0, 0}, {n[0], n[1], n[2]}};
    // Inside the grid, pairwise disjoint; every leaf in exactly one list box.
    for (size_t a = 0; a < boxes.size(); ++a) {
        ASSERT_TRUE(inside(boxes[a], grid)) << what << " " << box_string(boxes[a]);
        for (size_t b = a + 1; b < boxes.size(); ++b)
            ASSERT_FALSE(overlap(boxes[a], boxes[b]))
                << what << ": " << box_string(boxes[a]) << " overlaps " << box_string(boxes[b]);
    }
    for (const KdNode& node : p.nodes()) {
        if (!node.is_leaf()) continue;
        int holders = 0;
        for (const CellBox& b : boxes) holders += inside(node.box, b);
        ASSERT_EQ(holders, 1) << what << " leaf " << box_string(node.box);
    }
    // Every non-empty cell is in a box (the table counts the cells inside the boxes).
    uint64_t covered = 0;
    for (const CellBox& b : boxes)
        covered += p.wide_counts() ? p.table64().count(b) : p.table32().count(b);
    ASSERT_EQ(covered, p.non_empty_cells()) << what << ": non-empty cells outside every box";
    // Consistent common faces: where two boxes touch, the face of one is the face of the
    // other (same plane, index coordinates), so the slicer sees no gap and no overlap.
    for (size_t a = 0; a < boxes.size(); ++a)
        for (size_t b = 0; b < boxes.size(); ++b) {
            if (a == b) continue;
            for (int ax = 0; ax < 3; ++ax) {
                CellBox x = boxes[a], y = boxes[b];
                if (x.hi[ax] != y.lo[ax]) continue;
                // Touching across axis ax: the index-space closures share a face at x.hi[ax].
                x.lo[ax] = y.lo[ax] - 1, x.hi[ax] = y.lo[ax];
                y.hi[ax] = y.lo[ax] + 1;
                if (!overlap(x, y)) continue;
                ASSERT_EQ(boxes[a].hi[ax], boxes[b].lo[ax]) << what;
            }
        }
}

TEST(KdTreeList, MLimitedListsHaveAtMostMDisjointBoxesCoveringEveryNonEmptyCell) {
    Rng rng{9};
    for (int trial = 0; trial < 25; ++trial) {
        const VolumeCase c = random_case(rng, 6, 26);
        KdPartition p;
        KdSettings s = fine_settings(rng);
        s.max_depth = std::max(s.max_depth, 4);
        p.build_from_tf(c.v, c.lut, s);
        for (int m = 0; m <= 24; ++m) {
            p.make_list(m);
            check_list(p, m, describe(c.v, c.lut) + " M " + std::to_string(m));
        }
    }
}

TEST(KdTreeList, ShareOfMNeverExceedsMWhereThePaperCeilingsWould) {
    // A tree whose root has 2 + 2 leaves below it: the paper's ceilings give M = 3 four boxes.
    SyntheticOptions so;
    so.dims = {48, 48, 48};
    const Volume v = generate(SyntheticKind::Tree, so);
    const TransferLut lut = discretise(preset("mr-default"), v.vis_range());
    KdSettings s;
    s.min_volume = 0, s.min_gain = 0, s.delta = 1;
    for (int depth = 1; depth <= 6; ++depth) {
        s.max_depth = depth;
        KdPartition p;
        p.build_from_tf(v, lut, s);
        for (int m = 1; m <= 40; ++m) {
            p.make_list(m);
            ASSERT_LE(int(p.list().size()), m) << "depth " << depth;
            ASSERT_EQ(int(p.list().size()), std::min(m, p.nodes()[0].leaves)) << "depth " << depth;
        }
    }
}

// ---- rendering face: region answers ---------------------------------------------------------

TEST(KdTreeRegion, EmptyBoxesHoldNoVisibleCellAndOccupiedBoxesAreListBoxes) {
    Rng rng{10};
    for (int trial = 0; trial < 60; ++trial) {
        const VolumeCase c = random_case(rng);
        AccelOptions o;
        const KdSettings fine = fine_settings(rng);
        o.kd_delta = fine.delta;
        o.kd_min_volume = fine.min_volume;
        o.kd_min_gain = fine.min_gain;
        o.kd_max_depth = fine.max_depth;
        o.kd_max_boxes = rng.coin() ? 0 : rng.range(1, 6);
        o.threads = fine.threads;
        KdTree tree(c.v, o);
        tree.set_transfer_function(c.lut);
        const BruteRanges brute = brute_ranges(c.v, c.lut.map());
        const BoxCount visible(brute.g, visible_cells(c.lut, brute.lo, brute.hi));
        const std::vector<CellBox> boxes = tree.partition().boxes();
        const int* n = tree.cells();
        int hint = -1;
        for (int k = 0; k < n[2]; ++k)
            for (int j = 0; j < n[1]; ++j)
                for (int i = 0; i < n[0]; ++i) {
                    const int cell[3] = {i, j, k};
                    const Region r = tree.region(cell, hint);
                    const std::string what =
                        describe(c.v, c.lut) + " " + cell_string(cell) + " " + region_string(r);
                    ASSERT_TRUE(box_contains_cell(r, cell, n)) << what;
                    if (r.empty) {
                        ASSERT_EQ(visible.count(r.box), 0)
                            << what << ": a visible cell in an empty box";
                        for (const CellBox& b : boxes) ASSERT_FALSE(overlap(b, r.box)) << what;
                    } else {
                        bool listed = false;
                        for (const CellBox& b : boxes) listed |= same_box(b, r.box);
                        ASSERT_TRUE(listed) << what << ": occupied box is not a list box";
                    }
                }
    }
}

TEST(KdTreeRegion, TransparentTfEmptiesTheGridAndOpaqueTfFillsIt) {
    SyntheticOptions so;
    so.dims = {20, 17, 23};
    const Volume v = generate(SyntheticKind::SphereShells, so);
    KdTree tree(v, AccelOptions{});
    const int cell[3] = {3, 4, 5};
    int hint = -1;
    EXPECT_FALSE(tree.region(cell, hint).empty) << "before any TF every cell may be visible";
    TransferLut lut = empty_lut(v.vis_range());
    tree.set_transfer_function(lut);
    Region r = tree.region(cell, hint);
    EXPECT_TRUE(r.empty);
    EXPECT_TRUE(same_box(r.box, CellBox{{0, 0, 0}, {19, 16, 22}})) << region_string(r);
    EXPECT_TRUE(tree.partition().boxes().empty());
    for (auto& e : lut.entries) e.a = 0.5f;
    tree.set_transfer_function(lut);
    r = tree.region(cell, hint);
    EXPECT_FALSE(r.empty);
    EXPECT_TRUE(same_box(r.box, CellBox{{0, 0, 0}, {19, 16, 22}})) << region_string(r);
    EXPECT_EQ(tree.partition().boxes().size(), 1u);
    EXPECT_GT(tree.stats().tf_update_seconds, 0.0);
    EXPECT_GT(tree.stats().bytes, 0u);
}

TEST(KdTreeRegion, DeepTreesAndMLimitedListsRenderExactly) {
    // The conformance suite renders the default (shallow) trees; here deep trees, short and
    // long lists, against --accel none byte for byte.
    Rng rng{12};
    int long_lists = 0;
    for (int trial = 0; trial < 24; ++trial) {
        const VolumeCase c = random_case(rng, 6, 30);
        AccelOptions o;
        o.kd_delta = rng.range(1, 3);
        o.kd_min_volume = 0.f;
        o.kd_min_gain = rng.coin() ? 0.f : 0.05f;
        o.kd_max_depth = rng.range(3, 12);
        o.kd_max_boxes = rng.coin() ? 0 : rng.range(1, 9);
        auto tree = make_accel(AccelKind::KdTree, c.v, o);
        tree->set_transfer_function(c.lut);
        long_lists += static_cast<const KdTree&>(*tree).partition().list().size() >= 4;
        RayMarcher m(c.v);
        m.set_transfer_function(c.lut);
        OrbitParams op;
        op.azimuth_deg = 360.f * rng.uniform();
        op.elevation_deg = -70.f + 140.f * rng.uniform();
        op.projection = rng.coin(3) ? Projection::Orthographic : Projection::Perspective;
        const Camera cam = Camera::orbit(m.bounds(), op, 40, 40);
        RenderOptions ro;
        ro.keep_float = true;
        ro.step = 0.3f + rng.uniform();
        ro.ert = rng.coin() ? 0.99f : kNoEarlyTermination;
        const RenderResult ref = m.render(cam, ro);
        m.set_accel(tree.get());
        const RenderResult got = m.render(cam, ro);
        ASSERT_EQ(got.image.rgba, ref.image.rgba) << describe(c.v, c.lut) << " trial " << trial;
        ASSERT_EQ(0, std::memcmp(got.rgba_float.data(), ref.rgba_float.data(),
                                 ref.rgba_float.size() * sizeof(float)))
            << describe(c.v, c.lut) << " trial " << trial;
        ASSERT_LE(got.stats.samples, ref.stats.samples);
    }
    EXPECT_GE(long_lists, 8) << "too few deep trees for this test to mean anything";
}

// ---- object-order face: visibility order ----------------------------------------------------

// Entry parameter of the ray o + t d (t >= t_min) into the closed index box of `b`; false on a
// miss.
bool ray_entry(const float o[3], const float d[3], const CellBox& b, float t_min, float& t_in) {
    float t0 = t_min, t1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.f) {
            if (o[a] < float(b.lo[a]) || o[a] > float(b.hi[a])) return false;
            continue;
        }
        float ta = (float(b.lo[a]) - o[a]) / d[a], tb = (float(b.hi[a]) - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (t1 - t0 < 1e-3f) return false;  // grazing an edge or a face: no sample inside
    t_in = t0;
    return true;
}

TEST(KdTreeVisibilityOrder, BoxesHitByAnyRayFromTheEyeComeInIncreasingEntryOrder) {
    Rng rng{11};
    int multi_box_views = 0, multi_hit_rays = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const VolumeCase c = random_case(rng, 8, 30);
        KdPartition p;
        KdSettings s = fine_settings(rng);
        s.max_depth = std::max(4, s.max_depth);
        p.build_from_tf(c.v, c.lut, s);
        p.make_list(rng.coin() ? 0 : rng.range(1, 12));
        const int* n = p.cells();
        for (int view = 0; view < 6; ++view) {
            // Eyes outside and inside the grid.
            const float eye[3] = {-float(n[0]) + 3.f * float(n[0]) * rng.uniform(),
                                  -float(n[1]) + 3.f * float(n[1]) * rng.uniform(),
                                  -float(n[2]) + 3.f * float(n[2]) * rng.uniform()};
            const std::vector<CellBox> order =
                p.boxes_in_visibility_order({eye[0], eye[1], eye[2]});
            if (order.size() >= 3) ++multi_box_views;
            ASSERT_EQ(order.size(), p.list().size());
            for (int ray = 0; ray < 200; ++ray) {
                // Toward a random point of the grid.
                const float target[3] = {float(n[0]) * rng.uniform(), float(n[1]) * rng.uniform(),
                                         float(n[2]) * rng.uniform()};
                const float d[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
                float last = -INFINITY;
                int hit = 0;
                for (size_t b = 0; b < order.size(); ++b) {
                    float t;
                    if (!ray_entry(eye, d, order[b], 0.f, t)) continue;
                    ASSERT_GE(t, last - 1e-4f) << "box " << b << " " << box_string(order[b])
                                               << " is entered before an earlier box";
                    last = t;
                    ++hit;
                }
                multi_hit_rays += hit >= 2;
            }
            // Parallel rays (orthographic): the same along a direction.
            const float dir[3] = {rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f};
            const std::vector<CellBox> along =
                p.boxes_in_visibility_order_along({dir[0], dir[1], dir[2]});
            for (int ray = 0; ray < 200; ++ray) {
                const float through[3] = {float(n[0]) * rng.uniform(), float(n[1]) * rng.uniform(),
                                          float(n[2]) * rng.uniform()};
                float last = -INFINITY;
                for (size_t b = 0; b < along.size(); ++b) {
                    float t;
                    if (!ray_entry(through, dir, along[b], -INFINITY, t)) continue;
                    ASSERT_GE(t, last - 1e-4f) << "box " << b << " " << box_string(along[b]);
                    last = t;
                }
            }
        }
    }
    // The test means something only if lists are long and rays cross several boxes.
    EXPECT_GT(multi_box_views, 60);
    EXPECT_GT(multi_hit_rays, 5000);
}

// ---- options --------------------------------------------------------------------------------

TEST(KdTreeOptions, InvalidOptionsAreOneLineErrorsNamingTheOption) {
    SyntheticOptions so;
    so.dims = {8, 8, 8};
    const Volume v = generate(SyntheticKind::Sphere, so);
    auto expect_error = [&](AccelOptions o, const std::string& needle) {
        try {
            make_accel(AccelKind::KdTree, v, o);
            ADD_FAILURE() << "no error for " << needle;
        } catch (const Error& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(needle), std::string::npos) << msg;
            EXPECT_EQ(msg.find("--"), std::string::npos) << msg;  // a field, not a flag
            EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        }
    };
    AccelOptions o;
    o.kd_max_boxes = -1;
    expect_error(o, "structure.max_boxes");
    o = {};
    o.kd_delta = -2;
    expect_error(o, "structure.delta");
    o = {};
    o.kd_min_volume = 1.5f;
    expect_error(o, "structure.min_volume");
    o = {};
    o.kd_min_gain = -0.1f;
    expect_error(o, "structure.min_gain");
    o = {};
    o.kd_max_depth = 65;
    expect_error(o, "structure.max_depth");
    o = {};
    o.kd_threshold = 10.f;
    expect_error(o, "structure.threshold");
    EXPECT_EQ(parse_accel("kdtree"), AccelKind::KdTree);
    EXPECT_EQ(to_string(AccelKind::KdTree), "kdtree");
}

// ---- the paper's claim on a sparse volume ---------------------------------------------------

TEST(KdTreePartition, FewBoxesRemoveMostOfTheEmptySpaceOfASparseTree) {
    SyntheticOptions so;
    so.dims = {96, 96, 96};
    const Volume v = generate(SyntheticKind::Tree, so);
    const TransferLut lut = discretise(preset("mr-default"), v.vis_range());
    KdPartition p;
    p.build_from_tf(v, lut, KdSettings{});
    double last = 0;
    for (int m : {1, 2, 4, 8, 16}) {
        p.make_list(m);
        // More boxes never remove less (each box of the M list is split or kept for larger M).
        EXPECT_GE(p.removed_fraction(), last - 1e-12) << "M " << m;
        last = p.removed_fraction();
    }
    p.make_list(16);
    EXPECT_GE(p.removed_empty_fraction(), 0.6) << "M 16";
}

// ---- `lacuna partition` ---------------------------------------------------------------------

namespace fs = std::filesystem;

using CliRun = lacuna::test::CliResult;
std::string slurp(const fs::path& p) {
    return lacuna::test::slurp_file(p);
}

fs::path temp_dir() {
    static const fs::path dir = lacuna::test::cli_temp_dir("kdtree");
    return dir;
}

CliRun run_cli(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
}

TEST(KdTreePartitionCli, WritesBoxesJsonAndOverlayPng) {
    const fs::path vol = temp_dir() / "tree.nrrd", json = temp_dir() / "boxes.json",
                   png = temp_dir() / "overlay.png";
    ASSERT_EQ(run_cli("generate tree --dims 40x36x44 --out " + vol.string()).code, 0);
    const CliRun r = run_cli("partition " + vol.string() +
                             " --tf mr-default --method kdtree "
                             "--max-boxes 4 --size 96 --json " +
                             json.string() + " --out " + png.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string j = slurp(json);
    for (const char* key :
         {"\"dims\"", "\"method\"", "\"settings\"", "\"timings_ms\"", "\"volume_removed_percent\"",
          "\"empty_space_removed_percent\"", "\"boxes\"", "\"classify\""})
        EXPECT_NE(j.find(key), std::string::npos) << key << " missing from " << j;
    EXPECT_EQ(slurp(png).substr(1, 3), "PNG");
    // Threshold classification works for partition, and an unknown method is an error (boxes:
    // tests/slice/partition_boxes_cli_test.cpp).
    const CliRun t = run_cli("partition " + vol.string() +
                             " --tf mr-default --threshold 100 --json " + json.string());
    EXPECT_EQ(t.code, 0) << t.err;
    const CliRun b = run_cli("partition " + vol.string() +
                             " --tf mr-default --method octree --json " + json.string());
    EXPECT_EQ(b.code, 2);
    EXPECT_NE(b.err.find("unknown 'octree'; expected one of: kdtree, boxes"), std::string::npos)
        << b.err;
    EXPECT_EQ(b.err.find('\n'), b.err.size() - 1) << b.err;
    const CliRun m = run_cli("partition " + vol.string() +
                             " --tf mr-default --max-boxes -1 --json " + json.string());
    EXPECT_EQ(m.code, 2);
    EXPECT_NE(m.err.find("--max-boxes"), std::string::npos) << m.err;
}

}  // namespace
}  // namespace lacuna
