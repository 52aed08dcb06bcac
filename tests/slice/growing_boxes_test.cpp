// Growing boxes (growing-boxes paper, Section 3.1), their TF classification and the --accel
// boxes source, against brute force over cells.
#include "slice/growing_boxes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lacuna/error.h"
#include "lacuna/io.h"
#include "slice/boxes_test_util.h"
#include "slice/growing_boxes_source.h"

namespace lacuna {
namespace {

using accel_test::Rng;
using namespace boxes_test;

// Brute gradient cells: central differences (one-sided at the border) at the 8 corners, in the
// build's float arithmetic (same operations, same order; -ffp-contract=off).
std::vector<uint8_t> brute_gradient_cells(const Volume& v, float limit) {
    const Vec3i d = v.dims();
    const float lim2 = limit * limit;
    auto steep = [&](int i, int j, int k) {
        float g[3];
        for (int a = 0; a < 3; ++a) {
            int q0[3] = {i, j, k}, q1[3] = {i, j, k};
            if (q0[a] > 0) q0[a]--;
            if (q1[a] + 1 < d[a]) q1[a]++;
            const float span = float(q1[a] - q0[a]);
            g[a] = (v.value(q1[0], q1[1], q1[2]) - v.value(q0[0], q0[1], q0[2])) / span;
        }
        return g[0] * g[0] + g[1] * g[1] + g[2] * g[2] > lim2;
    };
    int c[3];
    cell_counts(v, c);
    std::vector<uint8_t> out(size_t(c[0]) * c[1] * c[2], 0);
    for (int k = 0; k < c[2]; ++k)
        for (int j = 0; j < c[1]; ++j)
            for (int i = 0; i < c[0]; ++i) {
                bool any = false;
                for (int m = 0; m < 8; ++m)
                    any |= steep(i + (m & 1), j + ((m >> 1) & 1), k + (m >> 2));
                out[(size_t(k) * c[1] + j) * c[0] + i] = any;
            }
    return out;
}

void voxel_range(const Volume& v, const CellBox& b, float& mn, float& mx) {
    mn = INFINITY, mx = -INFINITY;
    for (int k = b.lo[2]; k <= b.hi[2]; ++k)
        for (int j = b.lo[1]; j <= b.hi[1]; ++j)
            for (int i = b.lo[0]; i <= b.hi[0]; ++i) {
                mn = std::min(mn, v.value(i, j, k));
                mx = std::max(mx, v.value(i, j, k));
            }
}

TEST(GrowingBoxes, PartitionCoversEveryCellExactlyOnceAndKeepsItsRules) {
    Rng rng{11};
    for (int iter = 0; iter < 120; ++iter) {
        const VoxelType t = accel_test::kAllTypes[iter % 4];
        const Volume v = adversarial_volume(iter % 6, t, rng);
        const BoxesOptions o = random_options(rng);
        const BoxMeasure m(v, o);
        const std::vector<BoxInfo> grown = grow_boxes(m);
        const std::string what =
            "iter " + std::to_string(iter) + " " + to_string(v) + " " + to_string(o);
        int c[3];
        cell_counts(v, c);
        std::vector<CellBox> boxes;
        for (const BoxInfo& b : grown) boxes.push_back(b.box);
        for (int n : coverage(c, boxes)) ASSERT_EQ(n, 1) << what;
        // Gradient cells as brute force says.
        const std::vector<uint8_t> grad = brute_gradient_cells(v, o.gradient * m.full_scale());
        for (int k = 0; k < c[2]; ++k)
            for (int j = 0; j < c[1]; ++j)
                for (int i = 0; i < c[0]; ++i)
                    ASSERT_EQ(m.gradient_cell(i, j, k),
                              grad[(size_t(k) * c[1] + j) * c[0] + i] != 0)
                        << what << " cell " << i << "," << j << "," << k;
        for (const BoxInfo& b : grown) {
            ASSERT_TRUE(inside(b.box, CellBox{{0, 0, 0}, {c[0], c[1], c[2]}})) << what;
            float mn, mx;
            voxel_range(v, b.box, mn, mx);
            ASSERT_EQ(b.vmin, mn) << what;
            ASSERT_EQ(b.vmax, mx) << what;
            int64_t g = 0;
            for (int k = b.box.lo[2]; k < b.box.hi[2]; ++k)
                for (int j = b.box.lo[1]; j < b.box.hi[1]; ++j)
                    for (int i = b.box.lo[0]; i < b.box.hi[0]; ++i)
                        g += grad[(size_t(k) * c[1] + j) * c[0] + i];
            ASSERT_EQ(int64_t(b.gradient_cells), g) << what;
            // The minimum box size holds for every box (growth runs on blocks of that size).
            bool one_block = true;
            for (int a = 0; a < 3; ++a) {
                const int e = b.box.hi[a] - b.box.lo[a];
                ASSERT_GE(e, std::min(o.min_uniform, c[a])) << what << " " << to_string(b.box);
                one_block &= e < 2 * o.min_uniform || c[a] < 2 * o.min_uniform;
            }
            // The growth type is what the facts say (type_of), and its rule holds.
            ASSERT_EQ(m.type_of(b), b.type) << what << " " << to_string(b.box);
            const double vol = double(box_volume(b.box));
            switch (b.type) {
                case BoxType::Uniform:
                    // The spread bound over every voxel the box's samples read.
                    ASSERT_LE(mx - mn, m.spread_limit()) << what << " " << to_string(b.box);
                    break;
                case BoxType::Gradient:
                    ASSERT_GT(g, 0) << what;
                    ASSERT_LE(vol - double(g), double(o.gradient_waste) * vol) << what;
                    break;
                case BoxType::Other:
                    ASSERT_GT(mx - mn, m.spread_limit()) << what;
                    if (!one_block) {
                        ASSERT_LE(vol * (double(mx) - double(mn)) / double(m.full_scale()),
                                  double(o.other_cost) + 1e-6)
                            << what;
                    }
                    break;
            }
        }
    }
}

TEST(GrowingBoxes, ConstantVolumeIsOneUniformBox) {
    Volume v(Vec3i{20, 13, 9}, VoxelType::UInt8);
    for (int k = 0; k < 9; ++k)
        for (int j = 0; j < 13; ++j)
            for (int i = 0; i < 20; ++i) v.set_value(i, j, k, 7);
    v.compute_range();
    const BoxMeasure m(v, BoxesOptions{});
    const std::vector<BoxInfo> g = grow_boxes(m);
    ASSERT_EQ(g.size(), 1u);
    EXPECT_EQ(g[0].type, BoxType::Uniform);
    EXPECT_EQ(box_volume(g[0].box), 19 * 12 * 8);
}

TEST(GrowingBoxes, SpreadScalesWithTheVisualizationRange) {
    Volume v(Vec3i{4, 4, 4}, VoxelType::Int16);
    v.compute_range();
    v.set_vis_range(ValueRange{-1000, 3000});
    BoxesOptions o;
    o.spread = 32;
    EXPECT_FLOAT_EQ(BoxMeasure(v, o).spread_limit(), 500.f);
    Volume u(Vec3i{4, 4, 4}, VoxelType::UInt8);
    u.compute_range();
    u.set_vis_range(ValueRange{10, 20});
    EXPECT_FLOAT_EQ(BoxMeasure(u, o).spread_limit(), 32.f);  // 32 of 256 for 8-bit data
}

TEST(GrowingBoxes, BadOptionsNameTheirField) {
    auto msg = [](BoxesOptions o) {
        try {
            validate(o);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    BoxesOptions o;
    o.spread = -1;
    EXPECT_NE(msg(o).find("structure.spread"), std::string::npos);
    o = {};
    o.min_uniform = 0;
    EXPECT_NE(msg(o).find("structure.min_uniform"), std::string::npos);
    o = {};
    o.gradient = NAN;
    EXPECT_NE(msg(o).find("structure.gradient:"), std::string::npos);
    o = {};
    o.gradient_waste = 2;
    EXPECT_NE(msg(o).find("structure.gradient_waste"), std::string::npos);
    o = {};
    o.other_cost = INFINITY;
    EXPECT_NE(msg(o).find("structure.other_cost"), std::string::npos);
    o = {};
    o.thin = -1;
    EXPECT_NE(msg(o).find("structure.thin"), std::string::npos);
}

// Brute answer for one box: some cell of the box has a built range with a visible entry.
bool brute_box_visible(const accel_test::BuiltRanges& r, const CellBox& b, const TransferLut& lut) {
    for (int k = b.lo[2]; k < b.hi[2]; ++k)
        for (int j = b.lo[1]; j < b.hi[1]; ++j)
            for (int i = b.lo[0]; i < b.hi[0]; ++i) {
                const size_t id = r.g.index(i, j, k);
                if (accel_test::scan_visible(lut, r.lo[id], r.hi[id])) return true;
            }
    return false;
}

TEST(BoxClassifier, EmptyEqualsBruteForceOverCellsUnderRandomTfs) {
    Rng rng{23};
    for (int iter = 0; iter < 60; ++iter) {
        const VoxelType t = accel_test::kAllTypes[iter % 4];
        const Volume v = adversarial_volume(iter % 6, t, rng);
        BoxesOptions o = random_options(rng);
        GrowingBoxesSource src(v, o);
        const int size = rng.coin() ? kDefaultLutSize : rng.range(2, 300);
        ValueRange vis = v.vis_range();
        if (size != kDefaultLutSize && rng.coin()) {  // a TF file with its own range
            const float w = std::max(vis.width(), 1.f);
            vis =
                ValueRange{vis.min - 0.3f * w * rng.uniform(), vis.max - 0.5f * w * rng.uniform()};
            if (!(vis.max > vis.min)) vis.max = vis.min + 1;
        }
        const ValueToLut map(vis, size);
        const accel_test::BuiltRanges built = accel_test::built_ranges(v, map, -8);
        const accel_test::BruteRanges brute = accel_test::brute_ranges(v, map);
        std::vector<int> hits;
        for (size_t c = 0; c < built.lo.size(); ++c)
            hits.push_back(built.lo[c]), hits.push_back(built.hi[c]);
        const std::string what = "iter " + std::to_string(iter) + " " + to_string(v);
        for (int tf = 0; tf < 12; ++tf) {
            TransferLut lut = accel_test::random_lut(vis, size, rng, hits);
            if (tf < 4) {  // a single-entry spike at an entry a cell range ends on
                lut = accel_test::empty_lut(vis, size);
                lut.entries[size_t(hits[size_t(rng.range(0, int(hits.size()) - 1))])].a = 1e-30f;
            }
            src.set_transfer_function(lut);
            for (int32_t id : src.leaves()) {
                const CellBox& b = src.tree().boxes()[size_t(id)].box;
                const bool visible = brute_box_visible(built, b, lut);
                ASSERT_EQ(src.empty(id), !visible) << what << " tf " << tf << " " << to_string(b);
                // Conservative against unwidened brute ranges of the box's own cells.
                if (src.empty(id))
                    for (int k = b.lo[2]; k < b.hi[2]; ++k)
                        for (int j = b.lo[1]; j < b.hi[1]; ++j)
                            for (int i = b.lo[0]; i < b.hi[0]; ++i) {
                                const size_t c = brute.g.index(i, j, k);
                                ASSERT_FALSE(
                                    accel_test::scan_visible(lut, brute.lo[c], brute.hi[c]))
                                    << what;
                            }
            }
        }
    }
}

TEST(BoxClassifier, EverySingleEntrySpikeOnAThinSheet) {
    // A one-voxel sheet of value 200 in uint8 zeros: the boxes next to it see it, the others
    // see only zeros; exhaustively, every entry of a 64-entry LUT.
    Volume v(Vec3i{16, 11, 13}, VoxelType::UInt8);
    for (int k = 0; k < 13; ++k)
        for (int j = 0; j < 11; ++j) v.set_value(7, j, k, 200);
    v.compute_range();
    v.set_vis_range(ValueRange{0, 255});
    BoxesOptions o;
    o.coalesce = -1.f;  // every non-empty leaf on its own
    GrowingBoxesSource src(v, o);
    const ValueToLut map(v.vis_range(), 64);
    const accel_test::BuiltRanges built = accel_test::built_ranges(v, map, -8);
    for (int e = 0; e < 64; ++e) {
        TransferLut lut = accel_test::empty_lut(v.vis_range(), 64);
        lut.entries[size_t(e)].a = 1e-45f;
        src.set_transfer_function(lut);
        size_t visible = 0;
        for (int32_t id : src.leaves()) {
            const CellBox& b = src.tree().boxes()[size_t(id)].box;
            ASSERT_EQ(src.empty(id), !brute_box_visible(built, b, lut)) << "entry " << e;
            visible += !src.empty(id);
        }
        EXPECT_EQ(src.boxes_front_to_back(Vec3f{-5, 3, 4}).size(), visible);
    }
}

TEST(GrowingBoxesSource, ReturnsDisjointNonEmptyBoxesInVisibilityOrderCoveringVisibleCells) {
    Rng rng{37};
    for (int iter = 0; iter < 40; ++iter) {
        const VoxelType t = accel_test::kAllTypes[iter % 4];
        const Volume v = adversarial_volume(iter % 6, t, rng);
        GrowingBoxesSource src(v, random_options(rng));
        EXPECT_STREQ(src.name(), "boxes");
        const accel_test::BruteRanges brute =
            accel_test::brute_ranges(v, ValueToLut(v.vis_range(), kDefaultLutSize));
        std::vector<int> hits(brute.lo.begin(), brute.lo.end());
        const TransferLut lut = accel_test::random_lut(v.vis_range(), kDefaultLutSize, rng, hits);
        src.set_transfer_function(lut);
        int c[3];
        cell_counts(v, c);
        const std::string what = "iter " + std::to_string(iter) + " " + to_string(v);
        for (int view = 0; view < 6; ++view) {
            double key[3];
            const bool is_dir = view % 2 == 1;
            for (int a = 0; a < 3; ++a)
                key[a] = is_dir     ? double(rng.uniform() * 2 - 1)
                         : view < 3 ? double(c[a]) * (rng.uniform() * 1.4 - 0.2)  // inside or near
                                    : double(c[a]) * (rng.uniform() * 8 - 4);
            const Vec3f k{float(key[0]), float(key[1]), float(key[2])};
            for (int a = 0; a < 3; ++a) key[a] = double(k[a]);
            const std::vector<CellBox> boxes =
                is_dir ? src.boxes_front_to_back_along(k) : src.boxes_front_to_back(k);
            std::vector<int> n = coverage(c, boxes);
            for (int kk = 0; kk < c[2]; ++kk)
                for (int j = 0; j < c[1]; ++j)
                    for (int i = 0; i < c[0]; ++i) {
                        const size_t id = brute.g.index(i, j, kk);
                        ASSERT_LE(n[id], 1) << what << ": boxes overlap";
                        if (accel_test::scan_visible(lut, brute.lo[id], brute.hi[id])) {
                            ASSERT_EQ(n[id], 1) << what << ": visible cell left out";
                        }
                    }
            expect_visibility_order(boxes, key, is_dir, what);
        }
    }
}

// Coalescing (BoxesOptions::coalesce): every emitted box is a BSP room that holds every visible
// leaf inside it (each in exactly one box), at most `coalesce` of its cells in empty leaves
// (0: none) and, when it joins leaves, at most coalesce_edge long per axis (cells x spacing);
// off (< 0) emits
// exactly the non-empty leaves; 1 without an edge limit emits one box.
TEST(GrowingBoxesSource, CoalescedBoxesAreRoomsWithinTheEmptyShare) {
    Rng rng{43};
    for (int iter = 0; iter < 30; ++iter) {
        Volume v = adversarial_volume(iter % 6, accel_test::kAllTypes[iter % 4], rng);
        if (iter % 2 == 1)  // anisotropic voxels: the edge limit is in world units
            v.spacing = Vec3d{0.5 + rng.uniform(), 0.5 + rng.uniform(), 0.3 + 2 * rng.uniform()};
        BoxesOptions o = random_options(rng);
        const float shares[] = {-1.f, 0.f, 0.2f, 0.6f, 1.f};
        o.coalesce = shares[iter % 5];
        o.coalesce_edge = iter % 3 == 0 ? 1e9f : float(rng.range(1, 12)) * 0.7f;
        GrowingBoxesSource src(v, o);
        src.set_transfer_function(accel_test::random_lut(v.vis_range(), kDefaultLutSize, rng));
        const std::string what = "iter " + std::to_string(iter) + " coalesce " +
                                 std::to_string(o.coalesce) + " " + to_string(v);
        // Non-empty leaf cells per emitted box, by brute force over the leaves.
        size_t nonempty_leaves = 0;
        const std::vector<CellBox> boxes = src.boxes_front_to_back_along(Vec3f{1, -1, 1});
        std::vector<double> full(boxes.size(), 0.0);
        std::vector<int> leaves_in(boxes.size(), 0);
        for (int32_t id : src.leaves()) {
            if (src.empty(id)) continue;
            ++nonempty_leaves;
            const CellBox& lb = src.tree().boxes()[size_t(id)].box;
            size_t owners = 0;
            for (size_t b = 0; b < boxes.size(); ++b)
                if (inside(lb, boxes[b]))
                    ++owners, ++leaves_in[b], full[b] += double(box_volume(lb));
            ASSERT_EQ(owners, 1u) << what << ": a visible leaf in " << owners << " boxes";
        }
        ASSERT_EQ(src.emitted(), boxes.size()) << what;
        for (size_t b = 0; b < boxes.size(); ++b) {
            const double vol = double(box_volume(boxes[b]));
            ASSERT_GT(full[b], 0.0) << what << ": an emitted box without a visible leaf";
            if (leaves_in[b] > 1 || full[b] < vol)  // joined: within the edge limit
                for (int a = 0; a < 3; ++a)
                    ASSERT_LE(double(boxes[b].hi[a] - boxes[b].lo[a]) * v.spacing[a],
                              double(o.coalesce_edge))
                        << what << ": box " << to_string(boxes[b]);
            if (o.coalesce >= 0.f)
                ASSERT_GE(full[b], (1.0 - double(o.coalesce)) * vol - 1e-9)
                    << what << ": box " << to_string(boxes[b]) << " too empty";
            else
                ASSERT_EQ(full[b], vol) << what;
        }
        if (o.coalesce < 0.f) ASSERT_EQ(boxes.size(), nonempty_leaves) << what;
        if (o.coalesce >= 1.f && o.coalesce_edge >= 1e9f && nonempty_leaves > 0)
            ASSERT_EQ(boxes.size(), 1u) << what;
    }
}

TEST(GrowingBoxesSource, SameBoxesForAnyThreadCount) {
    Rng rng{41};
    for (int iter = 0; iter < 8; ++iter) {
        const Volume v = adversarial_volume(4 + iter % 2, accel_test::kAllTypes[iter % 4], rng);
        BoxesOptions o = random_options(rng);
        o.threads = 1;
        GrowingBoxesSource one(v, o);
        o.threads = 2;
        GrowingBoxesSource two(v, o);
        const TransferLut lut = accel_test::random_lut(v.vis_range(), kDefaultLutSize, rng);
        one.set_transfer_function(lut);
        two.set_transfer_function(lut);
        const std::vector<CellBox> a = one.boxes_front_to_back(Vec3f{-3, 40, 7}),
                                   b = two.boxes_front_to_back(Vec3f{-3, 40, 7});
        ASSERT_EQ(a.size(), b.size());
        for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(to_string(a[i]), to_string(b[i]));
    }
}

TEST(GrowingBoxesSource, RealHeadBuildsAndClassifies) {
    // A real scan: the partition tiles the grid, the classification is non-trivial.
    const std::string path = "/usr/share/mricron/templates/ch2.nii.gz";
    const Volume v = read_volume(path);
    GrowingBoxesSource src(v, BoxesOptions{});
    int c[3];
    cell_counts(v, c);
    std::vector<CellBox> leaves;
    for (int32_t id : src.leaves()) leaves.push_back(src.tree().boxes()[size_t(id)].box);
    for (int n : coverage(c, leaves)) ASSERT_EQ(n, 1);
    src.set_transfer_function(discretise(preset("mr-brain"), v.vis_range()));
    EXPECT_GT(src.stats().empty, 0u);
    EXPECT_LT(src.stats().empty, leaves.size());
}

}  // namespace
}  // namespace lacuna
