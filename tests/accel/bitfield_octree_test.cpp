// What is specific to the bitfield octree (src/accel/bitfield_octree.h): bins between a cell's
// extreme corners, the TF bitfield, the 128-bit layout, and TF changes that must not touch the
// TF-independent tree unless the value mapping changes.
#include "accel/bitfield_octree.h"

#include <gtest/gtest.h>

#include "accel/minmax_octree.h"
#include "accel_test_util.h"

namespace lacuna {
namespace {

using namespace accel_test;

bool tf_bit(const BitfieldOctree& t, int b) {
    return (t.tf_bits()[b >> 6] >> (b & 63)) & 1;
}

// One cell whose 8 corners are `lo_value` (x = 0) and `hi_value` (x = 1), over a uint16 volume
// whose visualization range is [0, size-1]: voxel value v reads LUT entry v exactly.
Volume one_cell(float lo_value, float hi_value, int size = kDefaultLutSize) {
    Volume v({2, 2, 2}, VoxelType::UInt16, "one cell");
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j) {
            v.set_value(0, j, k, lo_value);
            v.set_value(1, j, k, hi_value);
        }
    v.set_vis_range({0.f, float(size - 1)});
    v.compute_range("one cell");
    return v;
}

TransferLut spike(ValueRange vis, int size, int entry) {
    TransferLut lut = empty_lut(vis, size);
    lut.entries[size_t(entry)] = {1, 1, 1, 0.5f};
    return lut;
}

// A cell with corners in bins 2 and 9 can produce every value in between, so bits 2..9 are set:
// a TF visible only in bin 5 (which no corner reads) must not skip it.
TEST(BitfieldOctree, SkipsNothingVisibleBetweenBins) {
    const Volume v = one_cell(40, 150);  // entries 40 and 150: bins 2 and 9 of 64 (16 entries each)
    AccelOptions o;
    o.leaf_cells = 2;
    o.bitfield_bits = 64;
    BitfieldOctree tree(v, o);
    const int cell[3] = {0, 0, 0};
    for (int b = 0; b < 64; ++b) {
        for (int e : {16 * b, 16 * b + 8, 16 * b + 15}) {
            tree.set_transfer_function(spike(v.vis_range(), kDefaultLutSize, e));
            ASSERT_TRUE(tf_bit(tree, b)) << "entry " << e;
            int hint = -1;
            const Region r = tree.region(cell, hint);
            EXPECT_EQ(r.empty, b < 2 || b > 9) << "spike at entry " << e << " (bin " << b << ")";
        }
    }
}

// The same for every width: bits bin(40)..bin(150) are set, bin(e) = e * bits / 1024.
TEST(BitfieldOctree, CellSetsEveryBinFromItsLowestToItsHighestCorner) {
    Rng rng{41};
    for (int bits : {8, 16, 32, 64, 128}) {
        for (int trial = 0; trial < 20; ++trial) {
            int a = rng.range(0, 1023), b = rng.range(0, 1023);
            if (a > b) std::swap(a, b);
            const Volume v = one_cell(float(a), float(b));
            AccelOptions o;
            o.bitfield_bits = bits;
            BitfieldOctree tree(v, o);
            const int cell[3] = {0, 0, 0};
            for (int s = 0; s < 40; ++s) {
                const int e = rng.range(0, 1023);
                tree.set_transfer_function(spike(v.vis_range(), kDefaultLutSize, e));
                int hint = -1;
                const int bin_e = e * bits / 1024;
                const bool expect_empty = bin_e < a * bits / 1024 || bin_e > b * bits / 1024;
                ASSERT_EQ(tree.region(cell, hint).empty, expect_empty)
                    << bits << " bits, corners at entries " << a << " and " << b << ", spike at "
                    << e;
            }
        }
    }
}

TEST(BitfieldOctree, TfBitSetExactlyWhenAnEntryOfThatBinIsVisible) {
    Rng rng{42};
    const int sizes[] = {kDefaultLutSize, kDefaultLutSize, 1000, 256, 4096, 100, 7, 65536};
    for (int trial = 0; trial < 200; ++trial) {
        const int bits = 8 << rng.range(0, 4), size = sizes[rng.range(0, 7)];
        Volume v = one_cell(0, 1);
        AccelOptions o;
        o.bitfield_bits = bits;
        BitfieldOctree tree(v, o);
        ASSERT_EQ(tree.bits(), bits);
        const TransferLut lut = random_lut(v.vis_range(), size, rng);
        tree.set_transfer_function(lut);
        std::vector<uint8_t> expect(size_t(bits), 0);
        for (int e = 0; e < size; ++e)
            if (lut.entries[size_t(e)].a > 0.f) expect[size_t(int64_t(e) * bits / size)] = 1;
        for (int b = 0; b < bits; ++b)
            ASSERT_EQ(tf_bit(tree, b), bool(expect[size_t(b)]))
                << bits << " bits, LUT size " << size << ", bin " << b;
        if (bits <= 64)
            ASSERT_EQ(tree.tf_bits()[1], 0u) << bits << " bits: the second word must stay clear";
        if (bits < 64)
            ASSERT_EQ(tree.tf_bits()[0] >> bits, 0u)
                << bits << " bits: bits past the width are set";
    }
}

// 128 bits: bins 64..127 live in the second word, for the TF and for the tree.
TEST(BitfieldOctree, WideBitfieldUsesBothWords) {
    // Corners at entries 1000 and 1010: bins 125 and 126 of 128 (8 entries each).
    const Volume v = one_cell(1000, 1010);
    AccelOptions o;
    o.bitfield_bits = 128;
    BitfieldOctree tree(v, o);
    const int cell[3] = {0, 0, 0};
    int hint = -1;
    tree.set_transfer_function(spike(v.vis_range(), kDefaultLutSize, 1005));  // bin 125
    EXPECT_EQ(tree.tf_bits()[0], 0u);
    EXPECT_EQ(tree.tf_bits()[1], uint64_t(1) << (125 - 64));
    EXPECT_FALSE(tree.region(cell, hint).empty);
    tree.set_transfer_function(spike(v.vis_range(), kDefaultLutSize, 1015));  // bin 126
    EXPECT_FALSE(tree.region(cell, hint).empty);
    tree.set_transfer_function(spike(v.vis_range(), kDefaultLutSize, 1020));  // bin 127
    EXPECT_TRUE(tree.region(cell, hint).empty);
    tree.set_transfer_function(spike(v.vis_range(), kDefaultLutSize, 125 - 64));  // bin 7 of word 0
    EXPECT_EQ(tree.tf_bits()[0], uint64_t(1) << 7);
    EXPECT_EQ(tree.tf_bits()[1], 0u);
    EXPECT_TRUE(tree.region(cell, hint).empty) << "a word-0 bit must not match a word-1 bit";

    // And the other way round: a low cell, bins 0..1, against high TF bins.
    const Volume low = one_cell(0, 15);
    BitfieldOctree t2(low, o);
    t2.set_transfer_function(spike(low.vis_range(), kDefaultLutSize, 64 * 8 + 8));  // bin 65
    EXPECT_TRUE(t2.region(cell, hint).empty);
    t2.set_transfer_function(spike(low.vis_range(), kDefaultLutSize, 12));  // bin 1
    EXPECT_FALSE(t2.region(cell, hint).empty);
}

// Every answer for every cell, with a fresh hint each time.
std::vector<Region> all_regions(const BitfieldOctree& t) {
    std::vector<Region> out;
    const int* n = t.cells();
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i) {
                const int c[3] = {i, j, k};
                int hint = -1;
                out.push_back(t.region(c, hint));
            }
    return out;
}

bool same_regions(const std::vector<Region>& a, const std::vector<Region>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (!same_region(a[i], b[i])) return false;
    return true;
}

// A TF change with the same value mapping only recomputes the TF bitfield: the tree is not
// rebuilt (its build time is untouched) and going back to the first TF gives the first answers.
TEST(BitfieldOctree, TransferFunctionChangeLeavesTheTreeAlone) {
    Rng rng{43};
    for (int trial = 0; trial < 16; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 3, 18), rng);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 2);
        o.bitfield_bits = 8 << rng.range(0, 4);
        BitfieldOctree tree(v, o);
        const double build = tree.stats().build_seconds;
        const size_t nodes = tree.stats().nodes, bytes = tree.stats().bytes;
        const ValueToLut map(v.vis_range(), kDefaultLutSize);
        const TransferLut a =
            random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, map, rng));
        const TransferLut b =
            random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, map, rng));
        tree.set_transfer_function(a);
        const std::vector<Region> first = all_regions(tree);
        tree.set_transfer_function(b);
        // Under b, every empty answer is brute-force empty.
        const BruteRanges brute = brute_ranges(v, map);
        const BoxCount visible_b(brute.g, visible_cells(b, brute.lo, brute.hi));
        for (const Region& r : all_regions(tree))
            if (r.empty)
                ASSERT_EQ(visible_b.count(r.box), 0) << describe(v, b) << " " << region_string(r);
        tree.set_transfer_function(a);
        EXPECT_TRUE(same_regions(first, all_regions(tree)))
            << describe(v, a) << ": answers changed after a -> b -> a";
        EXPECT_EQ(tree.stats().build_seconds, build)
            << "a TF change with the same mapping rebuilt the tree";
        EXPECT_EQ(tree.stats().nodes, nodes);
        EXPECT_EQ(tree.stats().bytes, bytes);
    }
}

// A LUT over another visualization range or with another size maps values to other entries and
// bins: the tree must be rebuilt for it, and stays exact.
TEST(BitfieldOctree, VisRangeOrLutSizeChangeRebuildsTheTreeExactly) {
    // uint8 ramp along x: values 0, 20, 40, ..., 240. Built for vis [0, 240]; then a LUT over
    // [0, 100] puts every value >= 100 on the last entry. A spike there must make the cells with
    // values >= 100 occupied (the old tree has them in bins 26..63, not 63).
    Volume v({13, 3, 3}, VoxelType::UInt8, "ramp");
    for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 13; ++i) v.set_value(i, j, k, float(20 * i));
    v.compute_range("ramp");
    AccelOptions o;
    o.leaf_cells = 2;
    BitfieldOctree tree(v, o);
    const double build = tree.stats().build_seconds;
    tree.set_transfer_function(spike(v.vis_range(), kDefaultLutSize, 1023));
    const TransferLut narrow = spike({0.f, 100.f}, kDefaultLutSize, 1023);
    tree.set_transfer_function(narrow);
    EXPECT_NE(tree.stats().build_seconds, build)
        << "a new visualization range must rebuild the tree";
    const BruteRanges brute = brute_ranges(v, narrow.map());
    const std::vector<uint8_t> vis = visible_cells(narrow, brute.lo, brute.hi);
    const BoxCount visible(brute.g, vis);
    const int* n = tree.cells();
    int visible_cells_seen = 0;
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i) {
                const int c[3] = {i, j, k};
                int hint = -1;
                const Region r = tree.region(c, hint);
                visible_cells_seen += vis[brute.g.index(i, j, k)];
                if (vis[brute.g.index(i, j, k)]) EXPECT_FALSE(r.empty) << cell_string(c);
                if (r.empty)
                    EXPECT_EQ(visible.count(r.box), 0) << cell_string(c) << " " << region_string(r);
            }
    EXPECT_GT(visible_cells_seen, 0);

    // Random: other ranges and LUT sizes, compared with brute force.
    Rng rng{44};
    for (int trial = 0; trial < 30; ++trial) {
        const Volume w = random_volume(kAllTypes[trial % 4], random_dims(rng, 3, 14), rng);
        AccelOptions ow;
        ow.leaf_cells = 2;
        ow.bitfield_bits = 8 << rng.range(0, 4);
        BitfieldOctree t(w, ow);
        for (int tf = 0; tf < 3; ++tf) {
            const ValueRange r = random_vis(w, rng);
            const int size = rng.coin() ? kDefaultLutSize : (rng.coin() ? 300 : 4096);
            const ValueToLut map(r, size);
            const TransferLut lut = random_lut(r, size, rng, voxel_entries(w, map, rng));
            t.set_transfer_function(lut);
            const BruteRanges br = brute_ranges(w, map);
            const BoxCount vb(br.g, visible_cells(lut, br.lo, br.hi));
            const int* m = t.cells();
            for (int k = 0; k < m[2]; ++k)
                for (int j = 0; j < m[1]; ++j)
                    for (int i = 0; i < m[0]; ++i) {
                        const int c[3] = {i, j, k};
                        int hint = -1;
                        const Region reg = t.region(c, hint);
                        if (reg.empty)
                            ASSERT_EQ(vb.count(reg.box), 0)
                                << describe(w, lut) << " " << cell_string(c) << " "
                                << region_string(reg);
                    }
        }
    }
}

// Why bitfield cannot skip more than the prefix-count min-max octree (docs/benchmarks.md,
// "Bitfield vs minmax on gaps"): a node is a box of cells, neighbouring cells share corner
// voxels, so their ranges overlap and the union over any box is one interval [lo, hi]. The
// node's bitfield is therefore exactly the run of bins bin(lo)..bin(hi) of the min-max node's
// range, and whenever bitfield finds a node empty the prefix count does too. Checked for every
// node of trees over random volumes of every type, leaf sizes and widths.
TEST(BitfieldOctree, NodeBitsAreTheBinRunOfTheMinMaxRangeSoMinMaxSkipsAtLeastAsMuch) {
    Rng rng{83};
    int nodes = 0, bitfield_empty = 0;
    for (int trial = 0; trial < 24; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 30), rng);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 3);
        o.bitfield_bits = 8 << rng.range(0, 4);
        o.threads = rng.range(0, 2);
        BitfieldOctree bf(v, o);
        MinMaxOctree mm(AccelKind::MinMax, v, o);
        const std::string what = to_string(v) + " leaf " + std::to_string(o.leaf_cells) + " bits " +
                                 std::to_string(o.bitfield_bits);
        for (size_t i = 0; i < mm.pyramid().node_count(); ++i, ++nodes) {
            const MinMaxOctree::Node nd = mm.node(i);
            uint64_t want[2] = {0, 0};
            if (nd.lo <= nd.hi)
                for (int b = bf.bin_of(nd.lo); b <= bf.bin_of(nd.hi); ++b)
                    want[b >> 6] |= uint64_t(1) << (b & 63);
            for (int w = 0; w < bf.words(); ++w)
                ASSERT_EQ(bf.node_bits(i)[w], want[w]) << what << " node " << i << " word " << w;
        }
        for (int tf = 0; tf < 6; ++tf) {
            const TransferLut lut = random_lut(v.vis_range(), kDefaultLutSize, rng);
            bf.set_transfer_function(lut);
            mm.set_transfer_function(lut);
            for (size_t i = 0; i < mm.pyramid().node_count(); ++i) {
                if (!bf.empty_node(i)) continue;
                ++bitfield_empty;
                const MinMaxOctree::Node nd = mm.node(i);
                for (int e = nd.lo; e <= nd.hi; ++e)
                    ASSERT_EQ(lut.entries[size_t(e)].a, 0.f)
                        << what << " node " << i << ": bitfield empty, entry " << e << " visible";
            }
        }
    }
    EXPECT_GT(nodes, 1000);
    EXPECT_GT(bitfield_empty, 100);
}

}  // namespace
}  // namespace lacuna
