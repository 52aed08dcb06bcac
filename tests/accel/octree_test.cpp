// The octree pyramid (src/accel/octree.h) and the region answers of the three octrees
// (minmax, bitfield, boolean) against brute force: an independent pyramid, per-node emptiness
// computed straight from the cells each node covers, and the 8-corner visibility of every cell.
#include "accel/octree.h"

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <set>

#include "accel/bitfield_octree.h"
#include "accel/boolean_octree.h"
#include "accel/minmax_octree.h"
#include "accel_test_util.h"
#include "lacuna/error.h"

namespace lacuna {
namespace {

using namespace accel_test;

// ---- Pyramid --------------------------------------------------------------------------------

int ceil_div(int64_t a, int64_t b) {
    return int((a + b - 1) / b);
}

TEST(Pyramid, NodeCountsPerLevelAreCeilDivisionsForOddCellCounts) {
    const int counts[] = {1, 2, 3, 5, 7, 9, 15, 17, 31, 33, 63, 65, 100, 127, 129, 1000, 32767};
    Rng rng{21};
    for (int trial = 0; trial < 300; ++trial) {
        const int c[3] = {counts[rng.range(0, 16)], counts[rng.range(0, 16)],
                          counts[rng.range(0, 16)]};
        const int leaf = 2 << rng.range(0, 5);
        Pyramid p;
        p.init(c, leaf);
        const std::string what = std::to_string(c[0]) + "x" + std::to_string(c[1]) + "x" +
                                 std::to_string(c[2]) + " leaf " + std::to_string(leaf);
        ASSERT_EQ(1 << p.leaf_log2, leaf) << what;
        size_t total = 0;
        int levels = 0;
        for (int l = 0;; ++l) {
            ASSERT_LT(l, p.levels) << what;
            int n[3];
            for (int a = 0; a < 3; ++a) {
                n[a] = ceil_div(c[a], int64_t(leaf) << l);
                ASSERT_EQ(p.n[l][a], n[a]) << what << " level " << l << " axis " << a;
            }
            ASSERT_EQ(p.offset[l], total) << what << " level " << l;
            total += size_t(n[0]) * n[1] * n[2];
            levels = l + 1;
            if (n[0] == 1 && n[1] == 1 && n[2] == 1) break;
        }
        ASSERT_EQ(p.levels, levels) << what << ": the root must be the first level with one node";
        ASSERT_EQ(p.node_count(), total) << what;
        ASSERT_EQ(p.index(p.levels - 1, 0, 0, 0), total - 1)
            << what << ": the root is the last node";
    }
}

TEST(Pyramid, BoxesOfEachLevelTileTheCellGridExactly) {
    Rng rng{22};
    for (int trial = 0; trial < 80; ++trial) {
        const int c[3] = {rng.range(1, 40), rng.range(1, 40), rng.range(1, 40)};
        const int leaf = 2 << rng.range(0, 5);
        Pyramid p;
        p.init(c, leaf);
        const std::string what = std::to_string(c[0]) + "x" + std::to_string(c[1]) + "x" +
                                 std::to_string(c[2]) + " leaf " + std::to_string(leaf);
        std::vector<uint8_t> index_seen(p.node_count(), 0);
        for (int l = 0; l < p.levels; ++l) {
            std::vector<int> hits(size_t(c[0]) * c[1] * c[2], 0);
            for (int z = 0; z < p.n[l][2]; ++z)
                for (int y = 0; y < p.n[l][1]; ++y)
                    for (int x = 0; x < p.n[l][0]; ++x) {
                        const size_t id = p.index(l, x, y, z);
                        ASSERT_LT(id, p.node_count()) << what;
                        ASSERT_EQ(index_seen[id]++, 0) << what << ": node index used twice";
                        const CellBox b = p.box(l, x, y, z);
                        const int xyz[3] = {x, y, z};
                        for (int a = 0; a < 3; ++a) {
                            ASSERT_EQ(b.lo[a], xyz[a] * (leaf << l)) << what;
                            ASSERT_LT(b.lo[a], b.hi[a]) << what << " level " << l << ": empty box";
                            ASSERT_LE(b.hi[a], c[a])
                                << what << " level " << l << ": box leaves the grid";
                        }
                        for (int k = b.lo[2]; k < b.hi[2]; ++k)
                            for (int j = b.lo[1]; j < b.hi[1]; ++j)
                                for (int i = b.lo[0]; i < b.hi[0]; ++i)
                                    ++hits[(size_t(k) * c[1] + j) * c[0] + i];
                    }
            for (size_t h = 0; h < hits.size(); ++h)
                ASSERT_EQ(hits[h], 1) << what << " level " << l << " cell " << h;
        }
    }
}

bool box_inside(const CellBox& in, const CellBox& out) {
    for (int a = 0; a < 3; ++a)
        if (in.lo[a] < out.lo[a] || in.hi[a] > out.hi[a]) return false;
    return true;
}

TEST(Pyramid, ForChildrenVisitsExactlyTheNodesInsideTheParent) {
    Rng rng{23};
    for (int trial = 0; trial < 60; ++trial) {
        const int c[3] = {rng.range(1, 45), rng.range(1, 45), rng.range(1, 45)};
        Pyramid p;
        p.init(c, 2 << rng.range(0, 3));
        for (int l = 1; l < p.levels; ++l) {
            std::vector<int> parents(p.offset[l] - p.offset[l - 1], 0);
            for (int z = 0; z < p.n[l][2]; ++z)
                for (int y = 0; y < p.n[l][1]; ++y)
                    for (int x = 0; x < p.n[l][0]; ++x) {
                        const CellBox parent = p.box(l, x, y, z);
                        std::set<size_t> visited, expected;
                        p.for_children(l, x, y, z,
                                       [&](size_t i) { ASSERT_TRUE(visited.insert(i).second); });
                        for (int cz = 0; cz < p.n[l - 1][2]; ++cz)
                            for (int cy = 0; cy < p.n[l - 1][1]; ++cy)
                                for (int cx = 0; cx < p.n[l - 1][0]; ++cx)
                                    if (box_inside(p.box(l - 1, cx, cy, cz), parent))
                                        expected.insert(p.index(l - 1, cx, cy, cz));
                        ASSERT_EQ(visited, expected)
                            << "level " << l << " node " << x << "," << y << "," << z;
                        ASSERT_FALSE(visited.empty());
                        for (size_t i : visited) ++parents[i - p.offset[l - 1]];
                    }
            for (int n : parents)
                ASSERT_EQ(n, 1) << "level " << l - 1 << ": a node without exactly one parent";
        }
    }
}

TEST(Pyramid, RejectsLeafSizesThatAreNotPowersOfTwoIn2To64) {
    const int c[3] = {9, 9, 9};
    for (int leaf : {-2, 0, 1, 3, 6, 12, 65, 128, 1 << 20}) {
        Pyramid p;
        EXPECT_THROW(p.init(c, leaf), Error) << "leaf " << leaf;
    }
    for (int leaf : {2, 4, 8, 16, 32, 64}) {
        Pyramid p;
        EXPECT_NO_THROW(p.init(c, leaf)) << "leaf " << leaf;
    }
}

// ---- Octree regions against brute force -----------------------------------------------------

enum class Tree { MinMax, Bitfield, Boolean, MinMaxInterval };

std::string tree_name(Tree t) {
    return t == Tree::MinMax     ? "minmax"
           : t == Tree::Bitfield ? "bitfield"
           : t == Tree::Boolean  ? "boolean"
                                 : "minmax-interval";
}

// An independent pyramid with every node's emptiness computed straight from its cells' built
// ranges, the way the structure's header defines it.
struct OctreeOracle {
    int cells[3];
    int leaf, levels = 0, start;
    std::vector<std::array<int, 3>> n;        // nodes per axis per level
    std::vector<std::vector<uint8_t>> empty;  // per level, x fastest

    OctreeOracle(Tree t, const BuiltRanges& br, const TransferLut& lut, const AccelOptions& o) {
        for (int a = 0; a < 3; ++a) cells[a] = br.g.n[a];
        leaf = o.leaf_cells;
        // TF bins for the bitfield: bin b has a visible entry.
        const int bits = o.bitfield_bits, size = lut.size();
        auto bin = [&](int e) { return int(int64_t(e) * bits / size); };
        std::vector<uint8_t> tf_bin(size_t(bits), 0);
        for (int e = 0; e < size; ++e)
            if (lut.entries[size_t(e)].a > 0.f) tf_bin[size_t(bin(e))] = 1;
        for (int l = 0;; ++l) {
            const int64_t s = int64_t(leaf) << l;
            std::array<int, 3> nl;
            for (int a = 0; a < 3; ++a) nl[a] = ceil_div(cells[a], s);
            n.push_back(nl);
            std::vector<uint8_t> e(size_t(nl[0]) * nl[1] * nl[2]);
            for (int z = 0; z < nl[2]; ++z)
                for (int y = 0; y < nl[1]; ++y)
                    for (int x = 0; x < nl[0]; ++x) {
                        const CellBox b = box(l, x, y, z);
                        int lo = 1 << 30, hi = -1;
                        bool any_visible_cell = false;
                        std::vector<uint8_t> node_bin(size_t(bits), 0);
                        for (int k = b.lo[2]; k < b.hi[2]; ++k)
                            for (int j = b.lo[1]; j < b.hi[1]; ++j)
                                for (int i = b.lo[0]; i < b.hi[0]; ++i) {
                                    const size_t c = br.g.index(i, j, k);
                                    lo = std::min(lo, br.lo[c]);
                                    hi = std::max(hi, br.hi[c]);
                                    if (t == Tree::Boolean && !any_visible_cell)
                                        any_visible_cell = scan_visible(lut, br.lo[c], br.hi[c]);
                                    if (t == Tree::Bitfield)
                                        for (int q = bin(br.lo[c]); q <= bin(br.hi[c]); ++q)
                                            node_bin[size_t(q)] = 1;
                                }
                        bool is_empty = true;
                        if (t == Tree::MinMax) is_empty = !scan_visible(lut, lo, hi);
                        if (t == Tree::MinMaxInterval) {
                            // The paper's test: [lo, hi] misses [first, last visible entry].
                            int first = -1, last = -1;
                            for (int e2 = 0; e2 < size; ++e2)
                                if (lut.entries[size_t(e2)].a > 0.f) {
                                    if (first < 0) first = e2;
                                    last = e2;
                                }
                            is_empty = first < 0 || hi < first || lo > last;
                        }
                        if (t == Tree::Boolean) is_empty = !any_visible_cell;
                        if (t == Tree::Bitfield)
                            for (int q = 0; q < bits; ++q)
                                is_empty = is_empty && !(node_bin[size_t(q)] && tf_bin[size_t(q)]);
                        e[(size_t(z) * nl[1] + y) * nl[0] + x] = is_empty;
                    }
            empty.push_back(std::move(e));
            levels = l + 1;
            if (nl[0] == 1 && nl[1] == 1 && nl[2] == 1) break;
        }
        start = o.initial_level < 0 ? levels - 1 : std::min(o.initial_level, levels - 1);
    }
    CellBox box(int l, int x, int y, int z) const {
        const int64_t s = int64_t(leaf) << l;
        const int p[3] = {x, y, z};
        CellBox b;
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = int(p[a] * s);
            b.hi[a] = int(std::min<int64_t>((p[a] + 1) * s, cells[a]));
        }
        return b;
    }
    // The coarsest empty node at or below the start level containing `cell`, else its leaf.
    Region expected(const int cell[3]) const {
        for (int l = start; l >= 0; --l) {
            const int64_t s = int64_t(leaf) << l;
            const int x = int(cell[0] / s), y = int(cell[1] / s), z = int(cell[2] / s);
            if (empty[size_t(l)][(size_t(z) * n[size_t(l)][1] + y) * n[size_t(l)][0] + x])
                return Region{box(l, x, y, z), true};
        }
        return Region{box(0, cell[0] / leaf, cell[1] / leaf, cell[2] / leaf), false};
    }
};

std::unique_ptr<OctreeBase> make_tree(Tree t, const Volume& v, const AccelOptions& o) {
    switch (t) {
        case Tree::MinMax:
        case Tree::MinMaxInterval:
            return std::make_unique<MinMaxOctree>(
                t == Tree::MinMax ? AccelKind::MinMax : AccelKind::MinMaxInterval, v, o);
        case Tree::Bitfield:
            return std::make_unique<BitfieldOctree>(v, o);
        case Tree::Boolean:
            break;
    }
    return std::make_unique<BooleanOctree>(v, o);
}

Region tree_region(Tree t, const OctreeBase& tree, const int cell[3], int& hint) {
    switch (t) {
        case Tree::MinMax:
        case Tree::MinMaxInterval:
            return static_cast<const MinMaxOctree&>(tree).region(cell, hint);
        case Tree::Bitfield:
            return static_cast<const BitfieldOctree&>(tree).region(cell, hint);
        case Tree::Boolean:
            break;
    }
    return static_cast<const BooleanOctree&>(tree).region(cell, hint);
}

AccelOptions random_octree_options(Rng& rng) {
    AccelOptions o;
    o.leaf_cells = 2 << rng.range(0, 5);
    if (rng.coin()) o.leaf_cells = 2 << rng.range(0, 1);  // small leaves: deeper trees
    o.bitfield_bits = 8 << rng.range(0, 4);
    const int levels[] = {-1, -1, 0, 1, 2, 3, 20};
    o.initial_level = levels[rng.range(0, 6)];
    o.bidirectional = rng.coin();
    o.threads = rng.range(0, 2);
    return o;
}

std::string options_string(const AccelOptions& o) {
    return "leaf " + std::to_string(o.leaf_cells) + " bits " + std::to_string(o.bitfield_bits) +
           " initial level " + std::to_string(o.initial_level) +
           (o.bidirectional ? " bidirectional" : " top-down");
}

// A random walk over cells: mostly steps to a neighbour (as a cursor moves), sometimes a jump.
void next_cell(int cell[3], const int cells[3], Rng& rng) {
    if (rng.coin(8)) {
        for (int a = 0; a < 3; ++a) cell[a] = rng.range(0, cells[a] - 1);
        return;
    }
    const int a = rng.range(0, 2);
    cell[a] = std::clamp(cell[a] + rng.range(-3, 3), 0, cells[a] - 1);
}

// Builds tree t over random volumes, sets random TFs (spikes, bumps, other vis ranges and LUT
// sizes, which rebuild the TF-independent part) and compares every answer with the oracle; an
// empty answer must also hold no cell whose 8-corner brute range is visible.
void expect_regions_match_brute_force(Tree t, uint64_t seed, int volumes) {
    Rng rng{seed};
    int empty_answers = 0, occupied_answers = 0;
    for (int trial = 0; trial < volumes; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 20), rng);
        const AccelOptions o = random_octree_options(rng);
        const auto tree = make_tree(t, v, o);
        for (int tf = 0; tf < 4; ++tf) {
            const ValueRange vis = rng.coin(3) ? random_vis(v, rng) : v.vis_range();
            const int size = rng.coin(3) ? (rng.coin() ? 256 : 4096) : kDefaultLutSize;
            const ValueToLut map(vis, size);
            const TransferLut lut = random_lut(vis, size, rng, voxel_entries(v, map, rng));
            tree->set_transfer_function(lut);
            const BuiltRanges built = built_ranges(v, map, rng.range(1, 9));
            const OctreeOracle oracle(t, built, lut, o);
            const BruteRanges brute = brute_ranges(v, map);
            const BoxCount visible(brute.g, visible_cells(lut, brute.lo, brute.hi));
            const std::string what =
                tree_name(t) + " " + describe(v, lut) + " " + options_string(o);
            ASSERT_EQ(tree->pyramid().levels, oracle.levels) << what;
            int cell[3] = {0, 0, 0}, hint = -1;
            const int queries = std::min<int>(int(brute.g.count()) * 2, 1500);
            for (int q = 0; q < queries; ++q) {
                next_cell(cell, oracle.cells, rng);
                if (rng.coin(10)) hint = rng.range(-1, oracle.levels - 1);  // any starting level
                const Region got = tree_region(t, *tree, cell, hint);
                const Region want = oracle.expected(cell);
                ASSERT_TRUE(box_contains_cell(got, cell, oracle.cells)) << what;
                ASSERT_TRUE(same_region(got, want))
                    << what << " " << cell_string(cell) << ": got " << region_string(got)
                    << ", brute force " << region_string(want);
                if (got.empty)
                    ASSERT_EQ(visible.count(got.box), 0)
                        << what << " " << cell_string(cell) << ": empty region "
                        << region_string(got) << " holds a cell whose corner range is visible";
                (got.empty ? empty_answers : occupied_answers)++;
            }
        }
    }
    // The random cases exercised both answers.
    EXPECT_GT(empty_answers, 1000);
    EXPECT_GT(occupied_answers, 1000);
}

TEST(MinMaxOctree, RegionIsTheCoarsestEmptyNodeByBruteForce) {
    expect_regions_match_brute_force(Tree::MinMax, 31, 40);
}
TEST(BitfieldOctree, RegionIsTheCoarsestEmptyNodeByBruteForce) {
    expect_regions_match_brute_force(Tree::Bitfield, 32, 40);
}
TEST(BooleanOctree, RegionIsTheCoarsestEmptyNodeByBruteForce) {
    expect_regions_match_brute_force(Tree::Boolean, 33, 40);
}
TEST(MinMaxOctree, IntervalTestRegionIsTheCoarsestEmptyNodeByBruteForce) {
    expect_regions_match_brute_force(Tree::MinMaxInterval, 34, 40);
}

// The header's claim: emptiness is monotone, so bidirectional search (starting at the previous
// answer's level) and top-down search (from the initial level every time) give the same region.
TEST(Octree, BidirectionalAndTopDownTraversalGiveTheSameRegion) {
    Rng rng{34};
    for (int trial = 0; trial < 36; ++trial) {
        const Tree t = Tree(trial % 3);
        const Volume v = random_volume(kAllTypes[rng.range(0, 3)], random_dims(rng, 2, 24), rng);
        AccelOptions o = random_octree_options(rng);
        o.bidirectional = true;
        const auto bi = make_tree(t, v, o);
        o.bidirectional = false;
        const auto td = make_tree(t, v, o);
        for (int tf = 0; tf < 3; ++tf) {
            const TransferLut lut =
                random_lut(v.vis_range(), kDefaultLutSize, rng,
                           voxel_entries(v, ValueToLut(v.vis_range(), kDefaultLutSize), rng));
            bi->set_transfer_function(lut);
            td->set_transfer_function(lut);
            int cell[3] = {0, 0, 0}, hint_bi = -1, hint_td = -1;
            for (int q = 0; q < 2000; ++q) {
                next_cell(cell, bi->cells(), rng);
                const Region a = tree_region(t, *bi, cell, hint_bi);
                const Region b = tree_region(t, *td, cell, hint_td);
                ASSERT_TRUE(same_region(a, b))
                    << tree_name(t) << " " << describe(v, lut) << " " << options_string(o) << " "
                    << cell_string(cell) << ": bidirectional " << region_string(a) << ", top-down "
                    << region_string(b);
            }
        }
    }
}

// Leaf 2: whenever a leaf holds a cell whose 8-corner range is visible, every cell of that leaf
// gets the leaf back as occupied, whatever the traversal state.
TEST(MinMaxOctree, LeafWithAVisibleCellIsAlwaysOccupied) {
    Rng rng{35};
    int checked = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 18), rng);
        AccelOptions o = random_octree_options(rng);
        o.leaf_cells = 2;
        MinMaxOctree tree(AccelKind::MinMax, v, o);
        const ValueToLut map(v.vis_range(), kDefaultLutSize);
        const TransferLut lut =
            random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, map, rng));
        tree.set_transfer_function(lut);
        const BruteRanges brute = brute_ranges(v, map);
        const std::vector<uint8_t> vis = visible_cells(lut, brute.lo, brute.hi);
        const int* n = tree.cells();
        for (int k = 0; k < n[2]; ++k)
            for (int j = 0; j < n[1]; ++j)
                for (int i = 0; i < n[0]; ++i) {
                    if (!vis[brute.g.index(i, j, k)]) continue;
                    // Every cell of this cell's leaf.
                    for (int dz = 0; dz < 2; ++dz)
                        for (int dy = 0; dy < 2; ++dy)
                            for (int dx = 0; dx < 2; ++dx) {
                                const int c[3] = {(i & ~1) + dx, (j & ~1) + dy, (k & ~1) + dz};
                                if (c[0] >= n[0] || c[1] >= n[1] || c[2] >= n[2]) continue;
                                int hint = rng.range(-1, tree.pyramid().levels - 1);
                                const Region r = tree.region(c, hint);
                                const CellBox leaf =
                                    tree.pyramid().box(0, c[0] / 2, c[1] / 2, c[2] / 2);
                                ASSERT_TRUE(!r.empty && same_box(r.box, leaf))
                                    << describe(v, lut) << " " << options_string(o) << " "
                                    << cell_string(c) << " shares a leaf with visible cell (" << i
                                    << "," << j << "," << k << ") but got " << region_string(r);
                                ++checked;
                            }
                }
    }
    EXPECT_GT(checked, 1000);
}

// Boolean octree, leaf 2: a leaf is empty exactly when none of its cells' built ranges holds a
// visible entry (the tightest a per-cell test can be), and never when a brute range is visible.
TEST(BooleanOctree, LeafIsEmptyExactlyWhenNoCellOfItCanBeVisible) {
    Rng rng{36};
    for (int trial = 0; trial < 30; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 16), rng);
        AccelOptions o;
        o.leaf_cells = 2;
        o.initial_level = 0;
        BooleanOctree tree(v, o);
        const ValueToLut map(v.vis_range(), kDefaultLutSize);
        const TransferLut lut =
            random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, map, rng));
        tree.set_transfer_function(lut);
        const BuiltRanges built = built_ranges(v, map);
        const BruteRanges brute = brute_ranges(v, map);
        const int* n = tree.cells();
        for (int k = 0; k < n[2]; ++k)
            for (int j = 0; j < n[1]; ++j)
                for (int i = 0; i < n[0]; ++i) {
                    const int c[3] = {i, j, k};
                    int hint = -1;
                    const Region r = tree.region(c, hint);
                    bool built_visible = false, brute_visible = false;
                    for (int z = r.box.lo[2]; z < r.box.hi[2]; ++z)
                        for (int y = r.box.lo[1]; y < r.box.hi[1]; ++y)
                            for (int x = r.box.lo[0]; x < r.box.hi[0]; ++x) {
                                const size_t id = built.g.index(x, y, z);
                                built_visible |= scan_visible(lut, built.lo[id], built.hi[id]);
                                brute_visible |= scan_visible(lut, brute.lo[id], brute.hi[id]);
                            }
                    ASSERT_EQ(r.empty, !built_visible)
                        << describe(v, lut) << " " << cell_string(c) << " " << region_string(r);
                    if (r.empty)
                        ASSERT_FALSE(brute_visible) << describe(v, lut) << " " << cell_string(c);
                }
    }
}

// Before any TF is set the boolean octree has nothing to go on: everything is occupied.
TEST(BooleanOctree, EverythingIsOccupiedBeforeTheFirstTransferFunction) {
    Rng rng{37};
    const Volume v = random_volume(VoxelType::UInt8, {9, 7, 5}, rng);
    AccelOptions o;
    o.leaf_cells = 2;
    BooleanOctree tree(v, o);
    const int* n = tree.cells();
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i) {
                const int c[3] = {i, j, k};
                int hint = -1;
                EXPECT_FALSE(tree.region(c, hint).empty) << cell_string(c);
            }
}

}  // namespace
}  // namespace lacuna
