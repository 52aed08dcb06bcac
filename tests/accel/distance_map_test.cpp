// The distance maps (src/accel/distance_map.h) against brute force: block occupancy from the
// cells each block covers, distances to the nearest occupied block by a scan over all blocks,
// and the documented empty cube (Chebyshev r = D - 1; Euclidean the largest r with
// r * sqrt(3) < D).
#include "accel/distance_map.h"

#include <gtest/gtest.h>

#include "accel_test_util.h"

namespace lacuna {
namespace {

using namespace accel_test;

// Expected answers per block, from an all-pairs scan.
struct DistanceOracle {
    int cells[3], nb[3], block;
    std::vector<uint8_t> occupied;
    std::vector<int> radius;  // -1 occupied; else the empty cube's radius in blocks
    bool any_occupied = false;

    DistanceOracle(AccelKind kind, const BuiltRanges& br, const TransferLut& lut, int b)
        : block(b) {
        for (int a = 0; a < 3; ++a) cells[a] = br.g.n[a], nb[a] = (cells[a] + b - 1) / b;
        const size_t n = size_t(nb[0]) * nb[1] * nb[2];
        occupied.assign(n, 0);
        for (int k = 0; k < cells[2]; ++k)
            for (int j = 0; j < cells[1]; ++j)
                for (int i = 0; i < cells[0]; ++i) {
                    const size_t c = br.g.index(i, j, k);
                    if (scan_visible(lut, br.lo[c], br.hi[c]))
                        occupied[index(i / b, j / b, k / b)] = 1;
                }
        std::vector<int> occ_list;
        for (size_t q = 0; q < n; ++q)
            if (occupied[q]) occ_list.push_back(int(q));
        any_occupied = !occ_list.empty();
        radius.assign(n, -1);
        for (int z = 0; z < nb[2]; ++z)
            for (int y = 0; y < nb[1]; ++y)
                for (int x = 0; x < nb[0]; ++x) {
                    const size_t id = index(x, y, z);
                    if (occupied[id] || !any_occupied) continue;
                    int64_t d2 = INT64_MAX, dc = INT64_MAX;
                    for (int q : occ_list) {
                        const int qx = q % nb[0], qy = (q / nb[0]) % nb[1],
                                  qz = q / (nb[0] * nb[1]);
                        const int64_t dx = std::abs(qx - x), dy = std::abs(qy - y),
                                      dz = std::abs(qz - z);
                        d2 = std::min(d2, dx * dx + dy * dy + dz * dz);
                        dc = std::min(dc, std::max({dx, dy, dz}));
                    }
                    if (kind == AccelKind::Chebyshev) {
                        radius[id] = int(dc - 1);
                    } else {
                        int r = 0;  // largest r with r * sqrt(3) < D, i.e. 3 r^2 < D^2
                        while (3 * int64_t(r + 1) * (r + 1) < d2) ++r;
                        radius[id] = r;
                    }
                }
    }
    size_t index(int x, int y, int z) const { return (size_t(z) * nb[1] + y) * nb[0] + x; }
    Region expected(const int cell[3]) const {
        const int b[3] = {cell[0] / block, cell[1] / block, cell[2] / block};
        Region r;
        const size_t id = index(b[0], b[1], b[2]);
        r.empty = !occupied[id];
        if (r.empty && !any_occupied) {  // nothing visible anywhere: the whole grid
            for (int a = 0; a < 3; ++a) r.box.lo[a] = 0, r.box.hi[a] = cells[a];
            return r;
        }
        const int rad = r.empty ? radius[id] : 0;
        for (int a = 0; a < 3; ++a) {
            r.box.lo[a] = std::max(0, b[a] - rad) * block;
            r.box.hi[a] = std::min(cells[a], (std::min(nb[a] - 1, b[a] + rad) + 1) * block);
        }
        return r;
    }
};

// Queries one random cell of every block and compares with the oracle; empty answers must also
// hold no cell whose 8-corner brute range is visible.
void expect_map_matches(AccelKind kind, const Volume& v, const TransferLut& lut, int block,
                        Rng& rng, int* empty_answers = nullptr) {
    AccelOptions o;
    o.distance_block = block;
    o.threads = rng.range(0, 2);
    DistanceMap map(kind, v, o);
    map.set_transfer_function(lut);
    const BuiltRanges built = built_ranges(v, lut.map(), rng.range(1, 5));
    const DistanceOracle oracle(kind, built, lut, block);
    const BruteRanges brute = brute_ranges(v, lut.map());
    const BoxCount visible(brute.g, visible_cells(lut, brute.lo, brute.hi));
    const std::string what =
        to_string(kind) + " " + describe(v, lut) + " block " + std::to_string(block);
    ASSERT_EQ(map.cells()[0], oracle.cells[0]);
    for (int z = 0; z < oracle.nb[2]; ++z)
        for (int y = 0; y < oracle.nb[1]; ++y)
            for (int x = 0; x < oracle.nb[0]; ++x) {
                const int bxyz[3] = {x, y, z};
                int cell[3];
                for (int a = 0; a < 3; ++a)
                    cell[a] =
                        std::min(oracle.cells[a] - 1, bxyz[a] * block + rng.range(0, block - 1));
                int hint = -1;
                const Region got = map.region(cell, hint);
                const Region want = oracle.expected(cell);
                ASSERT_TRUE(box_contains_cell(got, cell, oracle.cells)) << what;
                ASSERT_TRUE(same_region(got, want))
                    << what << " " << cell_string(cell) << ": got " << region_string(got)
                    << ", brute force " << region_string(want) << " (radius "
                    << oracle.radius[oracle.index(x, y, z)] << ")";
                if (got.empty) {
                    ASSERT_EQ(visible.count(got.box), 0)
                        << what << " " << cell_string(cell) << ": empty " << region_string(got)
                        << " holds a cell whose corner range is visible";
                    if (empty_answers) ++*empty_answers;
                }
            }
}

void expect_random_maps_match(AccelKind kind, uint64_t seed) {
    Rng rng{seed};
    int empty_answers = 0;
    for (int block : {1, 2, 3, 4, 5}) {
        for (int trial = 0; trial < 12; ++trial) {
            const int hi = block == 1 ? 12 : 20;
            const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, hi), rng);
            const ValueRange vis = rng.coin(3) ? random_vis(v, rng) : v.vis_range();
            const int size = rng.coin(4) ? 512 : kDefaultLutSize;
            const TransferLut lut =
                random_lut(vis, size, rng, voxel_entries(v, ValueToLut(vis, size), rng));
            expect_map_matches(kind, v, lut, block, rng, &empty_answers);
            if (::testing::Test::HasFatalFailure()) return;
        }
    }
    EXPECT_GT(empty_answers, 500);
}

TEST(DistanceMap, EmptyCubeIsInscribedInTheEuclideanEmptyBall) {
    expect_random_maps_match(AccelKind::Distance, 51);
}

TEST(ChebyshevDistanceMap, EmptyCubeRadiusIsTheChebyshevDistanceMinusOne) {
    expect_random_maps_match(AccelKind::Chebyshev, 52);
}

// One visible voxel: distances along an axis and a diagonal, where the two metrics differ.
TEST(DistanceMap, SingleOccupiedBlockGivesTheDocumentedRadii) {
    Volume v({13, 13, 13}, VoxelType::UInt8, "one voxel");
    v.set_value(0, 0, 0, 255);
    v.compute_range("one voxel");
    TransferLut lut = empty_lut(v.vis_range());
    lut.entries[1023].a = 1;  // only value 255 (cells touching voxel (0,0,0)) is visible
    AccelOptions o;
    o.distance_block = 1;
    DistanceMap euclid(AccelKind::Distance, v, o), cheb(AccelKind::Chebyshev, v, o);
    euclid.set_transfer_function(lut);
    cheb.set_transfer_function(lut);
    struct Probe {
        int cell[3];
        int cheb_r, euclid_r;
    };
    // Cell (0,0,0) is the only occupied one. Cell (7,0,0): D = 7 for both; Chebyshev r = 6,
    // Euclidean 3 r^2 < 49 -> r = 4. Cell (5,5,5): Chebyshev D = 5 -> r = 4; Euclidean
    // D^2 = 75 -> r = 4 (48 < 75, 75 !< 75). Cell (1,1,0): D = 1 / D^2 = 2 -> r = 0 both.
    const Probe probes[] = {
        {{7, 0, 0}, 6, 4}, {{5, 5, 5}, 4, 4}, {{1, 1, 0}, 0, 0}, {{11, 11, 11}, 10, 10}};
    for (const Probe& p : probes) {
        int hint = -1;
        const Region c = cheb.region(p.cell, hint), e = euclid.region(p.cell, hint);
        EXPECT_TRUE(c.empty && e.empty) << cell_string(p.cell);
        for (int a = 0; a < 3; ++a) {
            EXPECT_EQ(c.box.lo[a], std::max(0, p.cell[a] - p.cheb_r))
                << cell_string(p.cell) << " chebyshev";
            EXPECT_EQ(c.box.hi[a], std::min(12, p.cell[a] + p.cheb_r + 1))
                << cell_string(p.cell) << " chebyshev";
            EXPECT_EQ(e.box.lo[a], std::max(0, p.cell[a] - p.euclid_r))
                << cell_string(p.cell) << " euclidean";
            EXPECT_EQ(e.box.hi[a], std::min(12, p.cell[a] + p.euclid_r + 1))
                << cell_string(p.cell) << " euclidean";
        }
    }
    const int origin[3] = {0, 0, 0};
    int hint = -1;
    EXPECT_FALSE(cheb.region(origin, hint).empty);
    EXPECT_FALSE(euclid.region(origin, hint).empty);
}

// Nothing visible anywhere: one empty region, the whole grid, from every cell.
void expect_all_transparent_is_one_region(AccelKind kind) {
    Rng rng{53};
    for (int trial = 0; trial < 12; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 20), rng);
        AccelOptions o;
        o.distance_block = rng.range(1, 6);
        DistanceMap map(kind, v, o);
        map.set_transfer_function(empty_lut(v.vis_range()));
        const int* n = map.cells();
        for (int q = 0; q < 200; ++q) {
            const int cell[3] = {rng.range(0, n[0] - 1), rng.range(0, n[1] - 1),
                                 rng.range(0, n[2] - 1)};
            int hint = -1;
            const Region r = map.region(cell, hint);
            ASSERT_TRUE(r.empty) << to_string(v) << " " << cell_string(cell);
            for (int a = 0; a < 3; ++a) {
                ASSERT_EQ(r.box.lo[a], 0)
                    << to_string(v) << " " << cell_string(cell) << " " << region_string(r);
                ASSERT_EQ(r.box.hi[a], n[a])
                    << to_string(v) << " " << cell_string(cell) << " " << region_string(r);
            }
        }
    }
}

// Everything visible: every block is occupied and answers its own box.
void expect_all_occupied_answers_each_block(AccelKind kind) {
    Rng rng{54};
    for (int trial = 0; trial < 12; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 20), rng);
        AccelOptions o;
        o.distance_block = rng.range(1, 6);
        const int b = o.distance_block;
        DistanceMap map(kind, v, o);
        TransferLut lut = empty_lut(v.vis_range());
        for (auto& e : lut.entries) e.a = 0.25f;
        map.set_transfer_function(lut);
        const int* n = map.cells();
        for (int q = 0; q < 200; ++q) {
            const int cell[3] = {rng.range(0, n[0] - 1), rng.range(0, n[1] - 1),
                                 rng.range(0, n[2] - 1)};
            int hint = -1;
            const Region r = map.region(cell, hint);
            ASSERT_FALSE(r.empty) << to_string(v) << " " << cell_string(cell);
            for (int a = 0; a < 3; ++a) {
                ASSERT_EQ(r.box.lo[a], cell[a] / b * b)
                    << cell_string(cell) << " " << region_string(r);
                ASSERT_EQ(r.box.hi[a], std::min(n[a], (cell[a] / b + 1) * b))
                    << cell_string(cell) << " " << region_string(r);
            }
        }
    }
}

TEST(DistanceMap, AllTransparentVolumeIsOneEmptyRegion) {
    expect_all_transparent_is_one_region(AccelKind::Distance);
}
TEST(ChebyshevDistanceMap, AllTransparentVolumeIsOneEmptyRegion) {
    expect_all_transparent_is_one_region(AccelKind::Chebyshev);
}
TEST(DistanceMap, AllOccupiedVolumeAnswersEachBlockOccupied) {
    expect_all_occupied_answers_each_block(AccelKind::Distance);
}
TEST(ChebyshevDistanceMap, AllOccupiedVolumeAnswersEachBlockOccupied) {
    expect_all_occupied_answers_each_block(AccelKind::Chebyshev);
}

// The map follows the TF: a second TF replaces the first one's answers completely.
TEST(DistanceMap, TransferFunctionChangeRebuildsBothMetricsExactly) {
    Rng rng{55};
    for (AccelKind kind : {AccelKind::Distance, AccelKind::Chebyshev})
        for (int trial = 0; trial < 8; ++trial) {
            const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 4, 16), rng);
            const int block = rng.range(1, 4);
            AccelOptions o;
            o.distance_block = block;
            DistanceMap map(kind, v, o);
            const ValueToLut m(v.vis_range(), kDefaultLutSize);
            for (int tf = 0; tf < 3; ++tf) {
                const TransferLut lut =
                    random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, m, rng));
                map.set_transfer_function(lut);
                const DistanceOracle oracle(kind, built_ranges(v, m), lut, block);
                const int* n = map.cells();
                for (int q = 0; q < 300; ++q) {
                    const int cell[3] = {rng.range(0, n[0] - 1), rng.range(0, n[1] - 1),
                                         rng.range(0, n[2] - 1)};
                    int hint = -1;
                    ASSERT_TRUE(same_region(map.region(cell, hint), oracle.expected(cell)))
                        << to_string(kind) << " " << describe(v, lut) << " TF " << tf << " "
                        << cell_string(cell);
                }
            }
        }
}

}  // namespace
}  // namespace lacuna
