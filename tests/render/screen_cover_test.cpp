// The screen cover (src/render/screen_cover.h) against brute force: the grid's surface runs are
// exactly the occupied bricks with an unoccupied or missing one among their 26 neighbours; every
// pixel the reference marcher (--accel none) gives any opacity is covered, on sparse volumes
// seen from many sides, perspective and orthographic, with anisotropic spacing and a flipped
// orientation; the cover leaves out most of the rays that enter the box (so the skip is real);
// and the grid's image, which skips every uncovered pixel, is the reference image byte for byte.
#include "render/screen_cover.h"

#include <gtest/gtest.h>

#include <cstring>

#include "../conformance/conformance_util.h"
#include "accel/brick_grid.h"
#include "lacuna/camera.h"
#include "lacuna/orientation.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {
namespace {

// A few small balls of value 200 in a zero volume (the TF sees values above 100 only).
Volume balls(Vec3i dims, Vec3d spacing, uint32_t seed) {
    Volume v(dims, VoxelType::UInt8);
    v.spacing = spacing;
    uint32_t s = seed;
    auto rnd = [&](int n) {
        s = s * 1664525u + 1013904223u;
        return int((s >> 8) % uint32_t(n));
    };
    for (int b = 0; b < 4; ++b) {
        const int cx = rnd(dims.x), cy = rnd(dims.y), cz = rnd(dims.z), r = 1 + rnd(3);
        for (int k = std::max(0, cz - r); k <= std::min(dims.z - 1, cz + r); ++k)
            for (int j = std::max(0, cy - r); j <= std::min(dims.y - 1, cy + r); ++j)
                for (int i = std::max(0, cx - r); i <= std::min(dims.x - 1, cx + r); ++i)
                    if ((i - cx) * (i - cx) + (j - cy) * (j - cy) + (k - cz) * (k - cz) <= r * r)
                        v.set_value(i, j, k, 200);
    }
    v.set_value(0, 0, 0, 255);  // a corner voxel: the cover reaches the grid's border
    v.compute_range();
    return v;
}

TransferFunction threshold_tf() {
    TransferFunction tf;
    tf.name = "threshold";
    tf.color = {{0.0, 1, 0.5, 0.25}, {1.0, 1, 1, 1}};
    tf.opacity = {{0.0, 0}, {100.0 / 255, 0}, {101.0 / 255, 0.6f}, {1.0, 0.8f}};
    return tf;
}

TEST(ScreenCover, SurfaceRunsAreTheOccupiedBricksWithAnEmptyNeighbour) {
    for (uint32_t seed : {1u, 2u, 3u, 4u}) {
        for (int leaf : {2, 4, 8}) {
            const Volume v = balls({37, 29, 41}, {1, 1, 1}, seed);
            AccelOptions o;
            o.leaf_cells = leaf;
            BrickGrid g(v, o);
            g.set_transfer_function(discretise(threshold_tf(), v.vis_range()));
            ASSERT_EQ(g.surface_runs(), nullptr) << "no runs before refine()";
            g.refine();
            ASSERT_NE(g.surface_runs(), nullptr);
            const int* nb = g.bricks();
            std::vector<int> in_run(size_t(nb[0]) * nb[1] * nb[2], 0);
            for (const BrickGrid::BrickRun& r : *g.surface_runs()) {
                ASSERT_LE(r.x0, r.x1);
                for (int x = r.x0; x <= r.x1; ++x)
                    ++in_run[(size_t(r.z) * nb[1] + r.y) * nb[0] + x];
            }
            auto occ = [&](int x, int y, int z) {
                return x >= 0 && y >= 0 && z >= 0 && x < nb[0] && y < nb[1] && z < nb[2] &&
                       g.occupied(x, y, z);
            };
            int surface = 0;
            for (int z = 0; z < nb[2]; ++z)
                for (int y = 0; y < nb[1]; ++y)
                    for (int x = 0; x < nb[0]; ++x) {
                        bool expect = false;
                        if (occ(x, y, z))
                            for (int d = 0; d < 27; ++d)
                                expect =
                                    expect || !occ(x + d % 3 - 1, y + d / 3 % 3 - 1, z + d / 9 - 1);
                        surface += expect;
                        ASSERT_EQ(in_run[(size_t(z) * nb[1] + y) * nb[0] + x], expect ? 1 : 0)
                            << "brick " << x << "," << y << "," << z << " leaf " << leaf;
                    }
            EXPECT_GT(surface, 0);
        }
    }
}

TEST(ScreenCover, CoversEveryPixelTheReferenceGivesOpacityAndSkipsMostOthers) {
    struct Case {
        Vec3i dims;
        Vec3d spacing;
        bool flip;
    };
    const Case cases[] = {{{40, 33, 47}, {1, 1, 1}, false},
                          {{52, 31, 29}, {0.7, 1.3, 1.9}, false},
                          {{33, 45, 38}, {1.1, 0.9, 0.6}, true}};
    const test::KernelPaths kp;
    int checked = 0;
    uint64_t skipped_rays = 0, box_rays = 0;
    for (int ci = 0; ci < 3; ++ci) {
        Volume v = balls(cases[ci].dims, cases[ci].spacing, 17u + uint32_t(ci));
        if (cases[ci].flip) {  // index x toward the patient's right, z inferior
            const double d[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1};
            std::memcpy(v.direction, d, sizeof d);
            v.origin = {12, -7, 30};
        }
        const TransferLut lut = discretise(threshold_tf(), v.vis_range());
        AccelOptions o;
        o.leaf_cells = 4;
        BrickGrid grid(v, o);
        grid.set_transfer_function(lut);
        grid.refine();
        RayMarcher none(v), skipping(v);
        none.set_transfer_function(lut);
        skipping.set_transfer_function(lut);
        skipping.set_accel(&grid);
        const VolumeFrame vf = volume_frame(v);
        for (int view = 0; view < 10; ++view) {
            OrbitParams p;
            p.azimuth_deg = 37.f * float(view) + 5.f;
            p.elevation_deg = -70.f + 15.f * float(view);
            p.projection = view % 3 == 2 ? Projection::Orthographic : Projection::Perspective;
            p.zoom = view % 4 == 3 ? 2.2f : 1.f;
            const int w = 97 + 13 * view, h = 61 + 7 * view;
            const Camera cam = Camera::orbit(none.bounds(), p, w, h);
            RenderOptions ro;
            ro.keep_float = true;
            ro.count_samples = true;
            ro.ert = view % 2 ? kNoEarlyTermination : 0.95f;
            if (view % 5 == 4) {  // the shaded leaping lanes skip the uncovered pixels too
                ro.features.shading = ShadingModel::Phong;
                ro.features.light.kind = LightKind::Directional;
                ro.features.light.direction = {0.3f, -0.5f, 0.8f};
            }
            const RenderResult ref = none.render(cam, ro);
            RenderResult got;
            for (simd::Isa isa : kp.paths) {  // every kernel path skips the uncovered pixels
                simd::set_isa(isa);
                got = skipping.render(cam, ro);
                ASSERT_EQ(ref.image.rgba, got.image.rgba)
                    << "case " << ci << " view " << view << " path " << int(isa);
                ASSERT_EQ(ref.stats.rays, got.stats.rays) << "every ray that enters the box counts";
            }
            simd::set_isa(kp.saved);
            const std::optional<ScreenCover> cover =
                ScreenCover::build(grid, v, to_volume_frame(vf, cam));
            ASSERT_TRUE(cover.has_value()) << "case " << ci << " view " << view;
            ASSERT_EQ(cover->width(), w);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const size_t i = size_t(y) * size_t(w) + size_t(x);
                    if (ref.rgba_float[i * 4 + 3] > 0.f)
                        ASSERT_TRUE(cover->covered(x, y))
                            << "case " << ci << " view " << view << " pixel " << x << "," << y;
                    if (ref.sample_counts[i] > 0) {
                        ++box_rays;
                        skipped_rays += !cover->covered(x, y);
                    }
                    if (!cover->covered(x, y)) ASSERT_EQ(got.sample_counts[i], 0u);
                }
            ++checked;
        }
    }
    EXPECT_EQ(checked, 30);
    // Four small balls and a corner voxel: many rays through the box see nothing, and the cover
    // knows it.
    EXPECT_GT(double(skipped_rays), 0.3 * double(box_rays));  // 45% when written
}

TEST(ScreenCover, IsOffWithoutRunsAndWhenTheEyeIsInsideTheGrid) {
    const Volume v = balls({40, 40, 40}, {1, 1, 1}, 5u);
    BrickGrid grid(v, AccelOptions{});
    grid.set_transfer_function(discretise(threshold_tf(), v.vis_range()));
    RayMarcher m(v);
    const Camera outside = Camera::orbit(m.bounds(), OrbitParams{}, 64, 64);
    EXPECT_FALSE(ScreenCover::build(grid, v, outside).has_value()) << "not refined";
    grid.refine();
    EXPECT_TRUE(ScreenCover::build(grid, v, outside).has_value());
    const Camera inside = Camera::from_basis({20, 20, 20}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, 0.5f,
                                             64, 64, Projection::Perspective);
    EXPECT_FALSE(ScreenCover::build(grid, v, inside).has_value());
    grid.set_transfer_function(discretise(threshold_tf(), v.vis_range()));
    EXPECT_FALSE(ScreenCover::build(grid, v, outside).has_value()) << "a TF change drops the runs";
}

}  // namespace
}  // namespace lacuna
