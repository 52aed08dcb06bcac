// The generic ray cursor (src/accel/cursor.h) over every structure, against brute force along
// the ray: segments are ordered, disjoint and inside [t_near, t_far], and every parameter whose
// position (computed in float like the marcher, clamped) lies in a visible cell or gives a
// visible trilinear sample is inside a segment.
#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <memory>

#include "accel/accel_impl.h"
#include "accel_test_util.h"
#include "render/ray_march_kernel.h"

namespace lacuna {
namespace {

using namespace accel_test;

// An IndexRay built component by component (the random rays below set o[a] and d[a]).
struct RayParts {
    float o[3], d[3];
    operator IndexRay() const { return IndexRay{o[0], o[1], o[2], d[0], d[1], d[2]}; }
};

// The marcher's slab test against the index-space box [0, hi] (src/render/ray_marcher.cpp).
bool intersect_box(const RayParts& r, const float hi[3], float& t0, float& t1) {
    t0 = 0.f;
    t1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0.f) {
            if (r.o[a] < 0.f || r.o[a] > hi[a]) return false;
            continue;
        }
        const float inv = 1.f / r.d[a];
        float ta = (0.f - r.o[a]) * inv, tb = (hi[a] - r.o[a]) * inv;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 < t1;
}

// A random ray that hits the box: origin outside or inside, direction with random anisotropic
// scale (world-to-index spacing) and sometimes zero components (axis-aligned rays, rays in a
// face plane).
bool random_ray(const float hi[3], Rng& rng, RayParts& r, float& t_near, float& t_far) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        const bool inside = rng.coin(3);
        for (int a = 0; a < 3; ++a) {
            r.o[a] = inside ? hi[a] * rng.uniform()
                            : -0.6f * hi[a] - 2.f + (2.2f * hi[a] + 4.f) * rng.uniform();
            if (rng.coin(12)) r.o[a] = rng.coin() ? 0.f : hi[a];  // on a face
            r.d[a] = (rng.uniform() * 2.f - 1.f) * (0.25f + 2.f * rng.uniform());
            if (rng.coin(6)) r.d[a] = 0.f;
        }
        if (r.d[0] == 0.f && r.d[1] == 0.f && r.d[2] == 0.f) r.d[rng.range(0, 2)] = 1.f;
        if (!inside) {  // aim at a random point of the box from outside
            float target[3];
            for (int a = 0; a < 3; ++a) target[a] = hi[a] * rng.uniform();
            if (rng.coin())
                for (int a = 0; a < 3; ++a) r.d[a] = (target[a] - r.o[a]) * (0.1f + rng.uniform());
        }
        if (intersect_box(r, hi, t_near, t_far)) return true;
    }
    return false;
}

struct RayCheck {
    int rays = 0, segments = 0, visible_points = 0;
};

// Runs the structure's cursor on `rays` random rays and checks the segments against brute
// force. `cell_visible` is per cell (8-corner brute range); the sample check uses the kernel.
template <class S, class T>
void check_rays(const S& s, const Volume& v, const T* data, const TransferLut& lut,
                const std::vector<uint8_t>& cell_visible, const CellGrid& g, int rays, Rng& rng,
                const std::string& what, RayCheck& stats) {
    const Vec3i d = v.dims();
    const float hi[3] = {float(d.x - 1), float(d.y - 1), float(d.z - 1)};
    const kernel::Grid<T> grid{
        data, ptrdiff_t(d.x), ptrdiff_t(d.x) * d.y, hi[0], hi[1], hi[2], d.x - 2, d.y - 2, d.z - 2};
    const ValueToLut map = lut.map();
    for (int ray = 0; ray < rays; ++ray) {
        RayParts r;
        float t_near, t_far;
        if (!random_ray(hi, rng, r, t_near, t_far)) continue;
        ++stats.rays;
        char rs[256];
        std::snprintf(rs, sizeof rs,
                      " ray o (%.9g, %.9g, %.9g) d (%.9g, %.9g, %.9g) t [%.9g, %.9g]", r.o[0],
                      r.o[1], r.o[2], r.d[0], r.d[1], r.d[2], t_near, t_far);
        // 1. Collect the segments: ordered, disjoint, non-empty, within [t_near, t_far]. A
        // minimum skip (the renderer passes about one sample spacing) only ever keeps more.
        const float min_skip = rng.coin() ? 0.f : 2.f * rng.uniform();
        typename S::Cursor cursor(s, r, t_near, t_far, min_skip);
        std::vector<Segment> segs;
        Segment seg;
        while (cursor.next(seg)) {
            ASSERT_LT(segs.size(), 100000u) << what << rs << ": the cursor does not terminate";
            ASSERT_LT(seg.t0, seg.t1) << what << rs << ": empty segment";
            ASSERT_GE(seg.t0, segs.empty() ? t_near : segs.back().t1)
                << what << rs << ": segments overlap or go back";
            ASSERT_LE(seg.t1, t_far) << what << rs;
            segs.push_back(seg);
        }
        ASSERT_FALSE(cursor.next(seg)) << what << rs << ": next() after the end";
        stats.segments += int(segs.size());
        // 2. Densely along the ray: a visible position must be covered.
        auto covered = [&](float t) {
            for (const Segment& sg : segs)
                if (sg.t0 <= t && t <= sg.t1) return true;
            return false;
        };
        for (int q = 0; q < 2500; ++q) {
            float t = q < 2000 ? t_near + (t_far - t_near) * (float(q) / 1999.f)
                               : t_near + (t_far - t_near) * rng.uniform();
            t = std::clamp(t, t_near, t_far);
            float p[3];
            int cell[3];
            for (int a = 0; a < 3; ++a) {
                p[a] = r.o[a] + t * r.d[a];  // as in kernel::march
                p[a] = p[a] < 0.f ? 0.f : (p[a] > hi[a] ? hi[a] : p[a]);
                cell[a] = std::min(int(p[a]), g.n[a] - 1);
            }
            const bool in_visible_cell = cell_visible[g.index(cell[0], cell[1], cell[2])];
            const bool visible_sample =
                lut.entries[size_t(map(kernel::trilinear(grid, p[0], p[1], p[2])))].a > 0.f;
            if (!in_visible_cell && !visible_sample) continue;
            ++stats.visible_points;
            if (!covered(t)) {
                std::string list;
                for (const Segment& sg : segs)
                    list += " [" + std::to_string(sg.t0) + ", " + std::to_string(sg.t1) + "]";
                char ps[160];
                std::snprintf(ps, sizeof ps, ": t = %.9g at (%.9g, %.9g, %.9g) ", t, p[0], p[1],
                              p[2]);
                FAIL() << what << rs << " min_skip " << min_skip << ps << cell_string(cell)
                       << (in_visible_cell ? " is a visible cell" : " gives a visible sample")
                       << " but no segment covers it; segments:" << list;
            }
        }
    }
}

void expect_cursor_covers_visible_cells(AccelKind kind, uint64_t seed) {
    Rng rng{seed};
    RayCheck stats;
    for (int trial = 0; trial < 24; ++trial) {
        const Volume v = random_volume(kAllTypes[trial % 4], random_dims(rng, 2, 16), rng);
        AccelOptions o;
        o.leaf_cells = 2 << rng.range(0, 3);
        o.bitfield_bits = 8 << rng.range(0, 4);
        o.initial_level = rng.range(-1, 2);
        o.bidirectional = rng.coin();
        o.distance_block = rng.range(1, 4);
        const auto accel = make_accel(kind, v, o);
        const ValueToLut m(v.vis_range(), kDefaultLutSize);
        for (int tf = 0; tf < 2; ++tf) {
            const TransferLut lut =
                random_lut(v.vis_range(), kDefaultLutSize, rng, voxel_entries(v, m, rng));
            accel->set_transfer_function(lut);
            const BruteRanges brute = brute_ranges(v, m);
            const std::vector<uint8_t> vis = visible_cells(lut, brute.lo, brute.hi);
            const std::string what = to_string(kind) + " " + describe(v, lut);
            visit_accel(*accel, [&](const auto& s) {
                visit_voxels(v, [&](const auto* data) {
                    check_rays(s, v, data, lut, vis, brute.g, 40, rng, what, stats);
                });
            });
            if (::testing::Test::HasFatalFailure()) return;
        }
    }
    EXPECT_GT(stats.rays, 1500);
    EXPECT_GT(stats.visible_points, 10000) << "the random cases must put visible cells on the rays";
}

TEST(Cursor, MinMaxSegmentsCoverEveryVisibleCellAlongTheRay) {
    expect_cursor_covers_visible_cells(AccelKind::MinMax, 61);
}
TEST(Cursor, BitfieldSegmentsCoverEveryVisibleCellAlongTheRay) {
    expect_cursor_covers_visible_cells(AccelKind::Bitfield, 62);
}
TEST(Cursor, BooleanSegmentsCoverEveryVisibleCellAlongTheRay) {
    expect_cursor_covers_visible_cells(AccelKind::Boolean, 63);
}
TEST(Cursor, DistanceSegmentsCoverEveryVisibleCellAlongTheRay) {
    expect_cursor_covers_visible_cells(AccelKind::Distance, 64);
}
TEST(Cursor, ChebyshevSegmentsCoverEveryVisibleCellAlongTheRay) {
    expect_cursor_covers_visible_cells(AccelKind::Chebyshev, 65);
}

// Structures added after this file was written (every kind but None and the five above) go
// through the same check automatically.
TEST(Cursor, EveryOtherKindSegmentsCoverEveryVisibleCellAlongTheRay) {
    const AccelKind known[] = {AccelKind::None,    AccelKind::MinMax,   AccelKind::Bitfield,
                               AccelKind::Boolean, AccelKind::Distance, AccelKind::Chebyshev};
    uint64_t seed = 70;
    for (AccelKind k : all_accel_kinds()) {
        if (std::find(std::begin(known), std::end(known), k) != std::end(known)) continue;
        SCOPED_TRACE(to_string(k));
        expect_cursor_covers_visible_cells(k, seed++);
        if (HasFatalFailure()) return;
    }
}

TEST(Cursor, NoAccelReturnsTheWholeIntervalOnce) {
    Rng rng{66};
    NoAccel none;
    for (int q = 0; q < 1000; ++q) {
        const RayParts r{{rng.uniform(), rng.uniform(), rng.uniform()},
                         {rng.uniform(), 1.f, -rng.uniform()}};
        const float t_near = 100.f * rng.uniform() - 10.f,
                    t_far = t_near + (q % 10 == 0 ? 0.f : 50.f * rng.uniform());
        NoAccel::Cursor c(none, r, t_near, t_far);
        Segment s;
        ASSERT_TRUE(c.next(s));
        ASSERT_EQ(s.t0, t_near);
        ASSERT_EQ(s.t1, t_far);
        ASSERT_FALSE(c.next(s));
        ASSERT_FALSE(c.next(s));
    }
}

// Nothing visible: the cursor may keep only slivers of the kMargin next to the ends, never a
// stretch through the volume.
TEST(Cursor, TransparentVolumeLeavesOnlyMarginSlivers) {
    Rng rng{67};
    for (AccelKind kind : {AccelKind::MinMax, AccelKind::Bitfield, AccelKind::Boolean,
                           AccelKind::Distance, AccelKind::Chebyshev}) {
        const Volume v = random_volume(VoxelType::UInt8, {17, 12, 9}, rng);
        const auto accel = make_accel(kind, v);
        accel->set_transfer_function(empty_lut(v.vis_range()));
        const float hi[3] = {16, 11, 8};
        for (int q = 0; q < 200; ++q) {
            RayParts r;
            float t_near, t_far;
            if (!random_ray(hi, rng, r, t_near, t_far)) continue;
            float covered = 0, dmax = 0;
            for (int a = 0; a < 3; ++a) dmax = std::max(dmax, std::abs(r.d[a]));
            visit_accel(*accel, [&](const auto& s) {
                using S = std::decay_t<decltype(s)>;
                typename S::Cursor c(s, r, t_near, t_far);
                Segment seg;
                while (c.next(seg)) covered += seg.t1 - seg.t0;
            });
            // Two margins of kMargin voxels (plus the nudge) in parameter units, with slack.
            EXPECT_LE(covered, 4.f * (RegionCursor<MinMaxOctree>::kMargin + 1e-3f) / dmax +
                                   1e-4f * (t_far - t_near))
                << to_string(kind) << ": a transparent volume kept " << covered << " of "
                << (t_far - t_near);
        }
    }
}

}  // namespace
}  // namespace lacuna
