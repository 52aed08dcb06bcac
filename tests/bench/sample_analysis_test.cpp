// The ideal sample count (src/render/sample_analysis.h) against the reference renderer and a
// brute-force count: naive per-cell corner ranges, and compositing every sample (not only the
// visible ones) to find where early ray termination stops.
#include "render/sample_analysis.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lacuna/accel.h"
#include "lacuna/renderer.h"
#include "lacuna/synthetic.h"
#include "render/ray_march_kernel.h"

namespace lacuna {
namespace {

TransferLut constant_lut(ValueRange vis, float opacity) {
    TransferLut lut;
    lut.vis = vis;
    lut.entries.assign(kDefaultLutSize, Rgba{0.8f, 0.7f, 0.6f, opacity});
    return lut;
}

// Opacity `a` on entries [lo, hi], zero elsewhere.
TransferLut band_lut(ValueRange vis, int lo, int hi, float a) {
    TransferLut lut = constant_lut(vis, 0.f);
    for (int e = lo; e <= hi; ++e) lut.entries[size_t(e)].a = a;
    return lut;
}

Camera orbit_camera(const Volume& v, float az, float el, int size,
                    Projection proj = Projection::Perspective, float zoom = 1.f) {
    OrbitParams p;
    p.azimuth_deg = az;
    p.elevation_deg = el;
    p.projection = proj;
    p.zoom = zoom;
    return Camera::orbit(RayMarcher(v).bounds(), p, size, size);
}

uint64_t reference_samples(const Volume& v, const TransferLut& lut, const Camera& cam,
                           const RenderOptions& ro, const Accel* accel = nullptr) {
    RayMarcher m(v);
    m.set_transfer_function(lut);
    m.set_accel(accel);
    return m.render(cam, ro).stats.samples;
}

RenderOptions options(float ert) {
    RenderOptions ro;
    ro.ert = ert;
    ro.threads = 2;
    return ro;
}

// Brute force: the reference lattice, a naive visibility test per sample's cell (8 corners
// through Volume::value, every entry of the range inspected), and compositing of every sample.
uint64_t brute_force(const Volume& v, const TransferLut& lut, const Camera& cam,
                     const RenderOptions& ro) {
    const std::vector<Rgba> table = step_corrected_lut(lut, ro.step);
    const ValueToLut map = lut.map();
    const Vec3i d = v.dims();
    const float hi[3] = {float(d.x - 1), float(d.y - 1), float(d.z - 1)};
    const float dt = ro.step * float(std::min({v.spacing.x, v.spacing.y, v.spacing.z}));
    uint64_t n = 0;
    visit_voxels(v, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        const kernel::Grid<T, int64_t> g{
            data, d.x, ptrdiff_t(d.x) * d.y, hi[0], hi[1], hi[2], d.x - 2, d.y - 2, d.z - 2};
        for (int py = 0; py < cam.height(); ++py)
            for (int px = 0; px < cam.width(); ++px) {
                const Ray wr = cam.generate(float(px), float(py));
                const float o[3] = {wr.origin.x * float(1.0 / v.spacing.x),
                                    wr.origin.y * float(1.0 / v.spacing.y),
                                    wr.origin.z * float(1.0 / v.spacing.z)};
                const float dir[3] = {wr.dir.x * float(1.0 / v.spacing.x),
                                      wr.dir.y * float(1.0 / v.spacing.y),
                                      wr.dir.z * float(1.0 / v.spacing.z)};
                // Box clip, as the reference does it.
                float t0 = 0.f, t1 = INFINITY;
                bool hit = true;
                for (int a = 0; a < 3 && hit; ++a) {
                    if (dir[a] == 0.f) {
                        hit = !(o[a] < 0.f || o[a] > hi[a]);
                        continue;
                    }
                    const float inv = 1.f / dir[a];
                    float ta = (0.f - o[a]) * inv, tb = (hi[a] - o[a]) * inv;
                    if (ta > tb) std::swap(ta, tb);
                    t0 = std::max(t0, ta);
                    t1 = std::min(t1, tb);
                }
                if (!hit || !(t0 < t1)) continue;
                const int k_end = std::max(int(std::ceil((t1 - t0) / dt - 0.5f)), 0);
                float acc = 0.f;
                for (int k = 0; k < k_end; ++k) {
                    const float t = t0 + (float(k) + 0.5f) * dt;
                    float p[3];
                    int c[3];
                    for (int a = 0; a < 3; ++a) {
                        p[a] = std::clamp(o[a] + t * dir[a], 0.f, hi[a]);
                        c[a] = std::min(int(p[a]), (a == 0 ? d.x : a == 1 ? d.y : d.z) - 2);
                    }
                    float lo = INFINITY, top = -INFINITY;
                    for (int corner = 0; corner < 8; ++corner) {
                        const float x = v.value(c[0] + (corner & 1), c[1] + ((corner >> 1) & 1),
                                                c[2] + ((corner >> 2) & 1));
                        lo = std::min(lo, x);
                        top = std::max(top, x);
                    }
                    bool visible = false;
                    for (int e = map(lo); e <= map(top); ++e)
                        visible |= lut.entries[size_t(e)].a > 0.f;
                    if (visible) ++n;
                    // Every sample composited, visible or not (the reference's order).
                    const float a = table[size_t(map(kernel::trilinear(g, p[0], p[1], p[2])))].a;
                    const float w = 1.f - acc;
                    acc += w * a;
                    if (acc >= ro.ert) break;
                }
            }
    });
    return n;
}

TEST(SampleAnalysis, AllCellsVisibleCountsEveryReferenceSample) {
    SyntheticOptions so;
    so.dims = {21, 17, 26};
    const Volume v = generate(SyntheticKind::NoiseBlobs, so);
    const TransferLut lut = constant_lut({0, 255}, 0.02f);
    for (float ert : {2.f, 0.99f, 0.5f}) {
        const Camera cam = orbit_camera(v, 37, 21, 24);
        EXPECT_GT(reference_samples(v, lut, cam, options(ert)), 0u);
        EXPECT_EQ(count_visible_cell_samples(v, lut, cam, options(ert)),
                  reference_samples(v, lut, cam, options(ert)))
            << "ert " << ert;
    }
}

TEST(SampleAnalysis, TransparentTransferFunctionCountsZero) {
    SyntheticOptions so;
    so.dims = {20, 20, 20};
    const Volume v = generate(SyntheticKind::SphereShells, so);
    const TransferLut lut = constant_lut({0, 255}, 0.f);
    const Camera cam = orbit_camera(v, 10, 30, 16);
    EXPECT_GT(reference_samples(v, lut, cam, options(2.f)), 0u);
    EXPECT_EQ(count_visible_cell_samples(v, lut, cam, options(2.f)), 0u);
    EXPECT_EQ(VisibleCells(v, lut).visible_count(), 0u);
}

// A plane of 255 at j = 10 in a volume of 0, seen orthographically along -y (azimuth 0,
// elevation 0, the anterior view): the visible cells are j = 9 and j = 10, i.e. y in [9, 11),
// which holds the lattice samples y = 10.75, 10.25, 9.75, 9.25 of every ray. With opacity 1 and ERT
// the first of them (value 63.75, opaque) ends the ray.
TEST(SampleAnalysis, HandBuiltPlaneCountsFourSamplesPerRay) {
    Volume v({6, 17, 6}, VoxelType::UInt8);
    for (int k = 0; k < 6; ++k)
        for (int i = 0; i < 6; ++i) v.set_value(i, 10, k, 255);
    v.compute_range();
    const TransferLut lut = band_lut({0, 255}, 1, kDefaultLutSize - 1, 1.f);
    const VisibleCells cells(v, lut);
    EXPECT_EQ(cells.visible_count(), size_t(5 * 2 * 5));
    EXPECT_TRUE(cells.visible(0, 9, 0));
    EXPECT_TRUE(cells.visible(4, 10, 4));
    EXPECT_FALSE(cells.visible(2, 8, 2));
    EXPECT_FALSE(cells.visible(2, 11, 2));
    const Camera cam = orbit_camera(v, 0, 0, 8, Projection::Orthographic);
    RayMarcher m(v);
    m.set_transfer_function(lut);
    const RenderStats ref = m.render(cam, options(2.f)).stats;
    ASSERT_GT(ref.rays, 0u);
    EXPECT_EQ(count_visible_cell_samples(v, lut, cells, cam, options(2.f)), 4 * ref.rays);
    EXPECT_EQ(count_visible_cell_samples(v, lut, cells, cam, options(0.99f)), 1 * ref.rays);
}

// The same plane under nearest sampling: of y = 9.25, 9.75, 10.25, 10.75 only 9.75 and 10.25 read
// voxel j = 10 (floor(y + 0.5)), so two samples per ray are visible, one with ERT; and a grid
// built for nearest takes exactly those.
TEST(SampleAnalysis, NearestCountsSamplesWhoseVoxelIsVisible) {
    Volume v({6, 17, 6}, VoxelType::UInt8);
    for (int k = 0; k < 6; ++k)
        for (int i = 0; i < 6; ++i) v.set_value(i, 10, k, 255);
    v.compute_range();
    const TransferLut lut = band_lut({0, 255}, 1, kDefaultLutSize - 1, 1.f);
    const VisibleCells cells(v, lut);
    const Camera cam = orbit_camera(v, 0, 0, 8, Projection::Orthographic);
    RayMarcher m(v);
    m.set_transfer_function(lut);
    RenderOptions o = options(2.f);
    o.interpolation = Interpolation::Nearest;
    const RenderStats ref = m.render(cam, o).stats;
    ASSERT_GT(ref.rays, 0u);
    EXPECT_EQ(count_visible_cell_samples(v, lut, cells, cam, o), 2 * ref.rays);
    AccelOptions ao;
    ao.interpolation = Interpolation::Nearest;
    ao.leaf_cells = 2;
    auto grid = make_accel(AccelKind::Grid, v, ao);
    grid->set_transfer_function(lut);
    m.set_accel(grid.get());
    EXPECT_GE(m.render(cam, o).stats.samples, 2 * ref.rays);
    RenderOptions e = options(0.99f);
    e.interpolation = Interpolation::Nearest;
    EXPECT_EQ(count_visible_cell_samples(v, lut, cells, cam, e), 1 * ref.rays);
}

TEST(SampleAnalysis, MatchesBruteForceOnSyntheticVolumes) {
    struct Case {
        SyntheticKind kind;
        Vec3i dims;
        int lo, hi;  // opacity band in LUT entries
        float az, el, zoom;
    };
    const Case cases[] = {
        {SyntheticKind::Tree, {24, 24, 24}, 300, 1023, 30, 20, 1.f},
        {SyntheticKind::NoiseBlobs, {17, 23, 19}, 200, 600, 200, -35, 1.f},
        {SyntheticKind::SphereShells, {22, 22, 22}, 500, 800, 95, 60, 1.f},
        {SyntheticKind::ThinSheets, {19, 16, 21}, 1023, 1023, 300, 10, 1.f},
        {SyntheticKind::NoiseBlobs, {20, 20, 20}, 100, 1023, 45, 15, 6.f},  // eye inside the box
    };
    for (const Case& c : cases) {
        SyntheticOptions so;
        so.dims = c.dims;
        Volume v = generate(c.kind, so);
        // Full uint8 range: no value sits on a LUT rounding boundary, so the conservative
        // widening of cell_ranges never differs from the brute force's exact mapping.
        v.set_vis_range({0, 255});
        const TransferLut lut = band_lut({0, 255}, c.lo, c.hi, 0.3f);
        const Camera cam = orbit_camera(v, c.az, c.el, 20, Projection::Perspective, c.zoom);
        for (float ert : {2.f, 0.99f, 0.6f}) {
            const uint64_t fast = count_visible_cell_samples(v, lut, cam, options(ert));
            if (ert > 1.f)
                EXPECT_GT(fast, 0u) << to_string(c.kind) << ": the case must see something";
            EXPECT_EQ(fast, brute_force(v, lut, cam, options(ert)))
                << to_string(c.kind) << " ert " << ert;
            EXPECT_LE(fast, reference_samples(v, lut, cam, options(ert))) << to_string(c.kind);
        }
    }
}

// Exact structures must sample every visible cell, so none takes fewer samples than the ideal.
TEST(SampleAnalysis, NoStructureTakesFewerSamplesThanTheIdeal) {
    SyntheticOptions so;
    so.dims = {32, 32, 32};
    Volume v = generate(SyntheticKind::Tree, so);
    const TransferLut lut = band_lut(v.vis_range(), 400, 1023, 0.2f);
    const Camera cam = orbit_camera(v, 120, 25, 24);
    for (float ert : {2.f, 0.99f}) {
        const uint64_t ideal = count_visible_cell_samples(v, lut, cam, options(ert));
        for (AccelKind k : all_accel_kinds()) {
            auto accel = make_accel(k, v);
            accel->set_transfer_function(lut);
            EXPECT_GE(reference_samples(v, lut, cam, options(ert), accel.get()), ideal)
                << to_string(k) << " ert " << ert;
        }
    }
}

TEST(SampleAnalysis, CountDoesNotDependOnThreads) {
    SyntheticOptions so;
    so.dims = {28, 20, 24};
    const Volume v = generate(SyntheticKind::NoiseBlobs, so);
    const TransferLut lut = band_lut(v.vis_range(), 250, 900, 0.1f);
    const Camera cam = orbit_camera(v, 70, 40, 33);
    RenderOptions one = options(0.99f), many = options(0.99f);
    one.threads = 1;
    many.threads = 2;
    many.tile = 5;
    EXPECT_EQ(count_visible_cell_samples(v, lut, cam, one),
              count_visible_cell_samples(v, lut, cam, many));
}

}  // namespace
}  // namespace lacuna
