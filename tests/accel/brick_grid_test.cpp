// The brick grid (src/accel/brick_grid.h) against brute force: its apron ranges are the union of
// the built cell ranges over each brick and its one-cell apron; its per-TF bits are the prefix
// count of those ranges; and its DDA never skips a lattice sample the sampler computes in a
// visible cell or with a visible value. The skip check uses the marcher's own position
// expression for every skipped sample, on rays aimed at brick corners and edges, where a float
// walk and the exact ray order crossings differently.
#include "accel/brick_grid.h"

#include <gtest/gtest.h>

#include <cstring>

#include "accel/accel_impl.h"
#include "accel_test_util.h"
#include "lacuna/renderer.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"

namespace lacuna {
namespace {

using namespace accel_test;

TEST(BrickGrid, ApronRangesAreTheUnionOfTheBrickAndItsApronCells) {
    Rng rng{9101};
    for (int trial = 0; trial < 24; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 30), rng);
        const ValueToLut map(v.vis_range(), kDefaultLutSize);
        const BuiltRanges cells = built_ranges(v, map, -4);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 2);
        BrickGrid g(v, o);
        const int B = 1 << g.brick_log2();
        const int* nb = g.bricks();
        for (int a = 0; a < 3; ++a) ASSERT_EQ(nb[a], (cells.g.n[a] + B - 1) / B);
        for (int z = 0; z < nb[2]; ++z)
            for (int y = 0; y < nb[1]; ++y)
                for (int x = 0; x < nb[0]; ++x) {
                    int lo = 1 << 30, hi = -1;
                    const int b[3] = {x, y, z};
                    int c0[3], c1[3];
                    for (int a = 0; a < 3; ++a) {
                        c0[a] = std::max(0, b[a] * B - 1);
                        c1[a] = std::min(cells.g.n[a] - 1, b[a] * B + B);
                    }
                    for (int k = c0[2]; k <= c1[2]; ++k)
                        for (int j = c0[1]; j <= c1[1]; ++j)
                            for (int i = c0[0]; i <= c1[0]; ++i) {
                                lo = std::min(lo, cells.lo[cells.g.index(i, j, k)]);
                                hi = std::max(hi, cells.hi[cells.g.index(i, j, k)]);
                            }
                    int glo, ghi;
                    g.brick_range(x, y, z, glo, ghi);
                    ASSERT_EQ(glo, lo) << describe(v, empty_lut(v.vis_range())) << " brick " << x
                                       << "," << y << "," << z << " leaf " << B;
                    ASSERT_EQ(ghi, hi) << "brick " << x << "," << y << "," << z;
                }
    }
}

TEST(BrickGrid, BitsAreThePrefixCountOfTheRangesAndBricksPastTheGridAreEmpty) {
    Rng rng{9102};
    for (int trial = 0; trial < 16; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 40), rng);
        BrickGrid g(v, AccelOptions{});
        const ValueToLut m(v.vis_range(), kDefaultLutSize);
        const TransferLut lut =
            random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, m, rng));
        g.set_transfer_function(lut);
        const int* nb = g.bricks();
        int occupied = 0;
        for (int z = 0; z < ((nb[2] + 3) & ~3); ++z)
            for (int y = 0; y < ((nb[1] + 3) & ~3); ++y)
                for (int x = 0; x < ((nb[0] + 3) & ~3); ++x) {
                    const bool inside = x < nb[0] && y < nb[1] && z < nb[2];
                    bool expect = false;
                    if (inside) {
                        int lo, hi;
                        g.brick_range(x, y, z, lo, hi);
                        expect = scan_visible(lut, lo, hi);
                    }
                    ASSERT_EQ(g.occupied(x, y, z), expect) << x << "," << y << "," << z;
                    occupied += expect;
                }
        // An empty TF empties every word.
        g.set_transfer_function(empty_lut(v.vis_range()));
        for (int z = 0; z < nb[2]; ++z)
            for (int y = 0; y < nb[1]; ++y)
                for (int x = 0; x < nb[0]; ++x) ASSERT_EQ(g.word(x, y, z), 0u);
        (void)occupied;
    }
}

// refine(): the visible-cell mask holds, for every cell, whether its built (widened) range
// holds a visible entry (brute-force scan of the LUT), at the offset of its first corner voxel;
// every other offset is clear; a TF change drops the mask until the next refine().
TEST(BrickGrid, RefinedCellMaskIsTheVisibilityOfEveryCellsRange) {
    Rng rng{9107};
    int visible = 0, invisible = 0;
    for (int trial = 0; trial < 32; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 36), rng);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 3);
        o.threads = rng.range(1, 3);
        BrickGrid g(v, o);
        const ValueToLut m(v.vis_range(), kDefaultLutSize);
        TransferLut lut = random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, m, rng));
        if (trial % 8 == 7)  // everything visible but one entry band: fully visible bricks
            for (size_t e = 0; e < lut.entries.size(); ++e)
                lut.entries[e].a = e % 97 < 90 ? 0.5f : 0.f;
        g.set_transfer_function(lut);
        ASSERT_EQ(g.cell_mask(), nullptr) << "no mask before refine()";
        g.refine();
        const uint32_t* mask = g.cell_mask();
        ASSERT_NE(mask, nullptr);
        const BuiltRanges cells = built_ranges(v, m, -4);
        const Vec3i d = v.dims();
        std::vector<uint8_t> is_cell(v.voxel_count(), 0);
        for (int k = 0; k < cells.g.n[2]; ++k)
            for (int j = 0; j < cells.g.n[1]; ++j)
                for (int i = 0; i < cells.g.n[0]; ++i) {
                    const size_t off = (size_t(k) * d.y + j) * d.x + i;
                    is_cell[off] = 1;
                    const size_t id = cells.g.index(i, j, k);
                    const bool expect = scan_visible(lut, cells.lo[id], cells.hi[id]);
                    const bool got = (mask[off >> 5] >> (off & 31)) & 1u;
                    ASSERT_EQ(got, expect) << describe(v, lut) << " cell " << i << "," << j << ","
                                           << k << " leaf " << o.leaf_cells;
                    (expect ? visible : invisible)++;
                }
        for (size_t off = 0; off < v.voxel_count(); ++off)
            if (!is_cell[off])
                ASSERT_FALSE((mask[off >> 5] >> (off & 31)) & 1u) << "offset " << off;
        g.set_transfer_function(empty_lut(v.vis_range()));
        ASSERT_EQ(g.cell_mask(), nullptr) << "a TF change drops the mask";
    }
    EXPECT_GT(visible, 1000);
    EXPECT_GT(invisible, 1000);
}

// The leap map against brute force from the built cell ranges: a fine brick (4^3 cells) is at
// distance 0 iff some cell of it or of its one-cell apron has a visible range, else, in the map
// of each octant, the side of the largest box of bricks from it toward the octant holding no
// such brick (capped at 255; the least over the octants is the Chebyshev distance to the
// nearest one); a brick at distance 0 sets bit
// sx + 2 sy + 4 sz iff some cell of sub-brick (sx, sy, sz) (2^3 cells) or of its apron does
// (sub-bricks past the grid are free).
TEST(BrickGrid, LeapMapIsTheDistanceToVisibleBricksAndTheVisibleSubBricks) {
    Rng rng{9109};
    int near = 0, far = 0, sub_set = 0, sub_clear = 0, longer = 0, full = 0, longer_inside = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 40), rng);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 3);
        o.threads = rng.range(1, 3);
        BrickGrid g(v, o);
        const ValueToLut m(v.vis_range(), kDefaultLutSize);
        TransferLut lut = random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, m, rng));
        if (trial % 4 == 3)  // few visible entries: far bricks and clear sub-bricks
            for (size_t e = 0; e < lut.entries.size(); ++e)
                if (e % 37 != 5) lut.entries[e].a = 0.f;
        if (trial % 8 == 6)  // all but one band visible: fully visible bricks
            for (size_t e = 0; e < lut.entries.size(); ++e)
                lut.entries[e].a = e % 97 < 90 ? 0.5f : 0.f;
        g.set_transfer_function(lut);
        ASSERT_EQ(g.leap_map(), nullptr) << "no leap map before refine()";
        g.refine();
        const uint16_t* leap = g.leap_map();
        ASSERT_NE(leap, nullptr);
        const BuiltRanges cells = built_ranges(v, m, -4);
        const int* n = cells.g.n;
        // Is any cell of [lo, hi] (per axis, clipped) visible?
        auto any_visible = [&](const int lo[3], const int hi[3]) {
            for (int k = std::max(lo[2], 0); k <= std::min(hi[2], n[2] - 1); ++k)
                for (int j = std::max(lo[1], 0); j <= std::min(hi[1], n[1] - 1); ++j)
                    for (int i = std::max(lo[0], 0); i <= std::min(hi[0], n[0] - 1); ++i) {
                        const size_t id = cells.g.index(i, j, k);
                        if (scan_visible(lut, cells.lo[id], cells.hi[id])) return true;
                    }
            return false;
        };
        const int* nf = g.leap_dims();
        for (int a = 0; a < 3; ++a) ASSERT_EQ(nf[a], (n[a] + 3) / 4);
        std::vector<uint8_t> occ(size_t(nf[0]) * nf[1] * nf[2]);
        for (int z = 0; z < nf[2]; ++z)
            for (int y = 0; y < nf[1]; ++y)
                for (int x = 0; x < nf[0]; ++x) {
                    const int lo[3] = {4 * x - 1, 4 * y - 1, 4 * z - 1},
                              hi[3] = {4 * x + 4, 4 * y + 4, 4 * z + 4};
                    occ[(size_t(z) * nf[1] + y) * nf[0] + x] = any_visible(lo, hi);
                }
        const size_t stride = g.leap_octant_stride();
        ASSERT_EQ(stride, occ.size());
        for (int z = 0; z < nf[2]; ++z)
            for (int y = 0; y < nf[1]; ++y)
                for (int x = 0; x < nf[0]; ++x) {
                    const size_t id = (size_t(z) * nf[1] + y) * nf[0] + x;
                    // Per octant: the side of the largest box from (x, y, z) toward it with no
                    // occupied brick, i.e. the least max_a s_a (p_a - b_a) over the occupied p
                    // ahead (s_a (p_a - b_a) >= 0 on every axis), capped at 255.
                    int dist = 255, wants[8];
                    for (int o = 0; o < 8; ++o) {
                        const int sx = o & 1 ? -1 : 1, sy = o & 2 ? -1 : 1, sz = o & 4 ? -1 : 1;
                        int want = 255;
                        for (int c = 0; c < nf[2]; ++c)
                            for (int b = 0; b < nf[1]; ++b)
                                for (int a = 0; a < nf[0]; ++a) {
                                    const int u = sx * (a - x), w = sy * (b - y), t = sz * (c - z);
                                    if (u < 0 || w < 0 || t < 0 ||
                                        !occ[(size_t(c) * nf[1] + b) * nf[0] + a])
                                        continue;
                                    want = std::min(want, std::max({u, w, t}));
                                }
                        const uint16_t eo = leap[o * stride + id];
                        if (want == 0 && (eo >> 8) == 0xff) {
                            // A fully visible brick: the inside distance, the side of the
                            // largest box toward the octant of fully visible bricks (past the
                            // grid counts as not fully visible).
                            int inside =
                                std::min({sx > 0 ? nf[0] - x : x + 1, sy > 0 ? nf[1] - y : y + 1,
                                          sz > 0 ? nf[2] - z : z + 1, 255});
                            for (int c = 0; c < nf[2]; ++c)
                                for (int b = 0; b < nf[1]; ++b)
                                    for (int a = 0; a < nf[0]; ++a) {
                                        const int u = sx * (a - x), w = sy * (b - y),
                                                  t = sz * (c - z);
                                        if (u < 0 || w < 0 || t < 0 ||
                                            leap[(size_t(c) * nf[1] + b) * nf[0] + a] >> 8 == 0xff)
                                            continue;
                                        inside = std::min(inside, std::max({u, w, t}));
                                    }
                            ASSERT_EQ(eo & 0xff, inside)
                                << describe(v, lut) << " fine brick " << x << "," << y << "," << z
                                << " octant " << o << ": inside distance";
                            ++full;
                            longer_inside += inside > 1;
                        } else {
                            ASSERT_EQ(eo & 0xff, want) << describe(v, lut) << " fine brick " << x
                                                       << "," << y << "," << z << " octant " << o;
                        }
                        ASSERT_EQ(eo >> 8, leap[id] >> 8)
                            << "the sub-bricks are the same in every octant";
                        wants[o] = want;
                        dist = std::min(dist, want);  // (the symmetric Chebyshev distance)
                    }
                    for (int o = 0; o < 8; ++o) longer += wants[o] > dist;
                    const uint16_t e = leap[id];
                    if (dist > 0) {
                        ASSERT_EQ(e >> 8, 0) << "sub-bricks of a far brick";
                        ++far;
                        continue;
                    }
                    ++near;
                    for (int s = 0; s < 8; ++s) {
                        const int o3[3] = {4 * x + 2 * (s & 1), 4 * y + 2 * (s >> 1 & 1),
                                           4 * z + 2 * (s >> 2)};
                        // (a sub-brick past the grid holds no sample's cell: its bit is free)
                        if (o3[0] >= n[0] || o3[1] >= n[1] || o3[2] >= n[2]) continue;
                        const int lo[3] = {o3[0] - 1, o3[1] - 1, o3[2] - 1},
                                  hi[3] = {o3[0] + 2, o3[1] + 2, o3[2] + 2};
                        const bool expect = any_visible(lo, hi);
                        ASSERT_EQ(bool(e >> (8 + s) & 1), expect)
                            << describe(v, lut) << " fine brick " << x << "," << y << "," << z
                            << " sub-brick " << s;
                        (expect ? sub_set : sub_clear)++;
                    }
                }
    }
    EXPECT_GT(near, 200);
    EXPECT_GT(far, 200);
    EXPECT_GT(sub_set, 500);
    EXPECT_GT(sub_clear, 200);
    EXPECT_GT(longer, 200) << "octant maps that see farther than the symmetric distance";
    EXPECT_GT(full, 5000) << "fully visible bricks";
    EXPECT_GT(longer_inside, 2000) << "boxes of fully visible bricks";
}

// Zero everywhere but a few random voxels: empty blocks to leap over.
Volume sparse_volume(VoxelType t, Vec3i dims, Rng& rng) {
    Volume v(dims, t);
    float lo, hi;
    type_limits(t, lo, hi);
    const int points = rng.range(1, 6);
    for (int p = 0; p < points; ++p)
        v.set_value(rng.range(0, dims.x - 1), rng.range(0, dims.y - 1), rng.range(0, dims.z - 1),
                    random_value(t, lo, hi, rng));
    v.set_value(0, 0, 0, random_value(t, lo, hi, rng));
    v.compute_range();
    return v;
}

TEST(BrickGrid, BlockDistancesAreTheChebyshevDistanceToTheNearestOccupiedBlock) {
    Rng rng{9105};
    for (int trial = 0; trial < 20; ++trial) {
        const Volume v = sparse_volume(kAllTypes[trial % 4], random_dims(rng, 2, 120), rng);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 2);
        BrickGrid g(v, o);
        const ValueToLut m(v.vis_range(), kDefaultLutSize);
        g.set_transfer_function(trial % 5 == 4 ? empty_lut(v.vis_range())
                                               : random_lut(v.vis_range(), kDefaultLutSize, rng,
                                                            voxel_entries(v, m, rng, 2)));
        const int* nb = g.bricks();
        const int nw[3] = {(nb[0] + 3) / 4, (nb[1] + 3) / 4, (nb[2] + 3) / 4};
        for (int z = 0; z < nw[2]; ++z)
            for (int y = 0; y < nw[1]; ++y)
                for (int x = 0; x < nw[0]; ++x) {
                    int want = 255;
                    for (int c = 0; c < nw[2]; ++c)
                        for (int b = 0; b < nw[1]; ++b)
                            for (int a = 0; a < nw[0]; ++a)
                                if (g.word(4 * a, 4 * b, 4 * c))
                                    want =
                                        std::min(want, std::max({std::abs(a - x), std::abs(b - y),
                                                                 std::abs(c - z)}));
                    ASSERT_EQ(g.block_distance(4 * x, 4 * y, 4 * z), std::max(want, 1))
                        << "block " << x << "," << y << "," << z;
                }
    }
}

// A ray through two points of the box that lie on brick corners, edges or faces (or anywhere),
// starting outside it; t scaled anisotropically. False if it misses the box.
bool corner_ray(const float hi[3], int B, Rng& rng, kernel::IndexRay& r, float& t_near,
                float& t_far) {
    auto point = [&](int a) {
        const int n = int(hi[a]);
        if (rng.coin(4)) return hi[a] * rng.uniform();
        return float(std::min(n, B * rng.range(0, n / B + 1)));
    };
    float p0[3], p1[3], d[3], len = 0;
    for (int a = 0; a < 3; ++a) {
        p0[a] = point(a);
        p1[a] = rng.coin(5) ? p0[a] : point(a);  // sometimes in a plane
        d[a] = p1[a] - p0[a];
        len += d[a] * d[a];
    }
    if (len == 0.f) return false;
    len = std::sqrt(len) * (0.3f + rng.uniform());
    const float back = 0.5f + 8.f * rng.uniform();
    r.dx = d[0] / len, r.dy = d[1] / len, r.dz = d[2] / len;
    r.ox = p0[0] - back * r.dx, r.oy = p0[1] - back * r.dy, r.oz = p0[2] - back * r.dz;
    return kernel::intersect_box(r, hi, t_near, t_far);
}

// Trial `trial` of a walk test: a sparse or a random volume, a grid with a random brick edge and
// a TF visible at `spikes` of the volume's voxel values; calls fn(volume, grid, hi).
template <class Fn>
void with_random_grid(int trial, int spikes, Rng& rng, Fn&& fn) {
    const Volume v = trial % 2 ? sparse_volume(kAllTypes[trial % 4], random_dims(rng, 6, 90), rng)
                               : random_volume(kAllTypes[trial % 4], random_dims(rng, 6, 70), rng);
    AccelOptions o;
    o.leaf_cells = 2 << rng.range(0, 2);
    BrickGrid g(v, o);
    const ValueToLut m(v.vis_range(), kDefaultLutSize);
    g.set_transfer_function(
        random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, m, rng, spikes)));
    const Vec3i d = v.dims();
    const float hi[3] = {float(d.x - 1), float(d.y - 1), float(d.z - 1)};
    fn(v, g, hi);
}

// The lemma the exactness argument rests on: the walk's steps tile [t_near, t_far], and every
// lattice sample in a step's stretch, placed by the marcher's arithmetic, lies within far less
// than one voxel of that step's brick (or block), so its cell is in the brick's apron.
TEST(BrickGrid, WalkStepsTileTheRayAndHoldTheMarchersSamplePositions) {
    Rng rng{9104};
    int samples = 0, coarse = 0, leaps = 0;
    float worst = 0.f;
    for (int trial = 0; trial < 30; ++trial) {
        with_random_grid(trial, 2, rng, [&](const Volume&, const BrickGrid& g, const float* hi) {
            const int B = 1 << g.brick_log2();
            for (int ray = 0; ray < 80; ++ray) {
                kernel::IndexRay r;
                float t_near, t_far;
                if (!corner_ray(hi, B, rng, r, t_near, t_far)) continue;
                const float dt = 0.02f + 0.5f * rng.uniform();
                const int k_end = lattice_end(t_near, t_far, dt);
                BrickGrid::Cursor cursor(g, r, t_near, t_far);
                BrickGrid::Cursor::Step st;
                float t_prev = t_near;
                int k = 0, steps = 0;
                while (cursor.step(st)) {
                    ASSERT_LT(++steps, 100000) << "the walk does not terminate";
                    ASSERT_EQ(st.t0, t_prev) << "steps must tile the ray";
                    ASSERT_LE(st.t0, st.t1);
                    t_prev = st.t1;
                    coarse += st.coarse;
                    for (int a = 0; a < 3; ++a) {
                        ASSERT_LE(0, st.lo[a]);
                        ASSERT_LE(st.lo[a], st.hi[a]);
                        ASSERT_LT(st.hi[a], g.bricks()[a]);
                    }
                    if (st.coarse)  // a leap crosses only empty bricks
                        for (int z = st.lo[2]; z <= st.hi[2]; ++z)
                            for (int y = st.lo[1]; y <= st.hi[1]; ++y)
                                for (int x = st.lo[0]; x <= st.hi[0]; ++x)
                                    ASSERT_FALSE(g.occupied(x, y, z))
                                        << "leap over a visible brick";
                    leaps += st.coarse && (st.hi[0] - st.lo[0] > 3 || st.hi[1] - st.lo[1] > 3 ||
                                           st.hi[2] - st.lo[2] > 3);
                    for (; k < k_end; ++k) {
                        const float t = t_near + (float(k) + 0.5f) * dt;
                        if (t > st.t1) break;
                        float p[3] = {r.ox + t * r.dx, r.oy + t * r.dy, r.oz + t * r.dz};
                        for (int a = 0; a < 3; ++a) {
                            p[a] = p[a] < 0.f ? 0.f : (p[a] > hi[a] ? hi[a] : p[a]);
                            const float lo = float(st.lo[a] * B);
                            const float up = std::min(hi[a], float((st.hi[a] + 1) * B));
                            const float out = std::max(lo - p[a], p[a] - up);
                            worst = std::max(worst, out);
                            ASSERT_LT(out, 1e-3f)
                                << "sample " << k << " at t " << t << " is " << out
                                << " voxels outside its step's box on axis " << a
                                << (st.coarse ? " (block)" : " (brick)");
                        }
                        ++samples;
                    }
                }
                ASSERT_EQ(t_prev, t_far) << "the walk must end at t_far";
                ASSERT_EQ(k, k_end) << "every lattice sample lies in a step";
            }
        });
        if (HasFatalFailure()) return;
    }
    EXPECT_GT(samples, 50000);
    EXPECT_GT(coarse, 100) << "the cases must take coarse steps";
    EXPECT_GT(leaps, 20) << "the cases must leap over more than one block";
    std::printf("worst excursion of a sample outside its step's box: %.3g voxels\n", worst);
}

// Every lattice sample the marcher would take but the grid's cursor skips, located with the
// marcher's own arithmetic: it must be invisible (its cell's brute range and its trilinear
// value). Rays start and end on brick corners, edges and faces.
template <class T>
void check_skipped_samples(const BrickGrid& g, const Volume& v, const T* data,
                           const TransferLut& lut, const std::vector<uint8_t>& cell_visible,
                           const CellGrid& cg, Rng& rng, int& skipped, int& kept) {
    const auto grid = kernel::make_grid<int32_t>(data, v.dims());
    const float hi[3] = {grid.hi_x, grid.hi_y, grid.hi_z};
    const ValueToLut map = lut.map();
    const int B = 1 << g.brick_log2();
    for (int ray = 0; ray < 60; ++ray) {
        kernel::IndexRay r;
        float t_near, t_far;
        if (!corner_ray(hi, B, rng, r, t_near, t_far)) continue;
        const float dt = 0.05f + 0.6f * rng.uniform();
        const int k_end = lattice_end(t_near, t_far, dt);
        std::vector<uint8_t> taken(size_t(std::max(k_end, 0)), 0);
        BrickGrid::Cursor cursor(g, r, t_near, t_far, rng.coin() ? 0.f : dt,
                                 rng.coin() ? 0.f : 16.f * dt);
        for_each_lattice_run(cursor, t_near, dt, k_end, [&](int kb, int ke) {
            for (int k = kb; k < ke; ++k) taken[size_t(k)] = 1;
            return true;
        });
        for (int k = 0; k < k_end; ++k) {
            if (taken[size_t(k)]) {
                ++kept;
                continue;
            }
            ++skipped;
            const float t = t_near + (float(k) + 0.5f) * dt;
            float p[3] = {r.ox + t * r.dx, r.oy + t * r.dy, r.oz + t * r.dz};
            int cell[3];
            for (int a = 0; a < 3; ++a) {
                p[a] = p[a] < 0.f ? 0.f : (p[a] > hi[a] ? hi[a] : p[a]);
                cell[a] = std::min(int(p[a]), cg.n[a] - 1);
            }
            const float value = kernel::trilinear(grid, p[0], p[1], p[2]);
            ASSERT_FALSE(cell_visible[cg.index(cell[0], cell[1], cell[2])])
                << "skipped sample " << k << " at t " << t << " lies in visible cell "
                << cell_string(cell) << " (brick edge " << B << ")";
            ASSERT_EQ(lut.entries[size_t(map(value))].a, 0.f)
                << "skipped sample " << k << " is visible";
        }
    }
}

// The renderer's walk (brick_run: registers, branch-free axis choice) hands out exactly the
// stretches of the reference walk through step(), on every kind of ray and every setting of the
// stretch bookkeeping (minimum skip, chunks).
TEST(BrickGrid, FastWalkGivesTheStepWalksStretchesToTheBit) {
    Rng rng{9106};
    int segments = 0;
    for (int trial = 0; trial < 30; ++trial) {
        with_random_grid(trial, 3, rng, [&](const Volume&, const BrickGrid& g, const float* hi) {
            for (int ray = 0; ray < 60; ++ray) {
                kernel::IndexRay r;
                float t_near, t_far;
                if (!corner_ray(hi, 1 << g.brick_log2(), rng, r, t_near, t_far)) continue;
                const float dt = 0.05f + 0.5f * rng.uniform();
                const float min_skip = rng.coin() ? 0.f : dt, chunk = rng.coin() ? 0.f : 16.f * dt;
                BrickGrid::Cursor fast(g, r, t_near, t_far, min_skip, chunk);
                BrickGrid::Cursor slow(g, r, t_near, t_far, min_skip, chunk);
                Segment a, b;
                for (int n = 0;; ++n) {
                    ASSERT_LT(n, 100000);
                    const bool ga = fast.next<true>(a), gb = slow.next<false>(b);
                    ASSERT_EQ(ga, gb) << "ray " << ray << " segment " << n;
                    if (!ga) break;
                    ASSERT_EQ(a.t0, b.t0) << "ray " << ray << " segment " << n;
                    ASSERT_EQ(a.t1, b.t1) << "ray " << ray << " segment " << n;
                    ++segments;
                }
            }
        });
        if (HasFatalFailure()) return;
    }
    EXPECT_GT(segments, 500);
}

TEST(BrickGrid, CursorSkipsOnlyInvisibleSamplesOnRaysThroughBrickCornersAndEdges) {
    Rng rng{9103};
    int skipped = 0, kept = 0;
    for (int trial = 0; trial < 40; ++trial) {
        // Sparse volumes: a few visible voxels, often on brick corners.
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 6, 40), rng);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 2);
        BrickGrid g(v, o);
        const ValueToLut m(v.vis_range(), kDefaultLutSize);
        const TransferLut lut =
            random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, m, rng, 3));
        g.set_transfer_function(lut);
        const BruteRanges brute = brute_ranges(v, m);
        const std::vector<uint8_t> vis = visible_cells(lut, brute.lo, brute.hi);
        visit_voxels(v, [&](const auto* data) {
            check_skipped_samples(g, v, data, lut, vis, brute.g, rng, skipped, kept);
        });
        if (HasFatalFailure()) return;
    }
    EXPECT_GT(skipped, 10000) << "the cases must skip";
    EXPECT_GT(kept, 1000) << "the cases must keep samples";
}

}  // namespace
}  // namespace lacuna
