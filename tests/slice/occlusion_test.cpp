// Occlusion culling and clipping: at threshold 1 the image is the image without occlusion, byte
// for byte; at 0.95 every pixel differs by at most the remaining transmittance 1 - T, and voxels
// are really skipped; the map's projection and back-projection agree; the adaptive number of map
// updates moves toward the best-performing count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "common/rng.h"
#include "lacuna/synthetic.h"
#include "slice/box_sources.h"
#include "slice/occlusion_clipping.h"
#include "slice/occlusion_map.h"
#include "slice/random_bsp_source.h"
#include "slice/slice_renderer.h"

namespace lacuna {
namespace {

using test::RandomBspSource;
using test::Rng;

// Dense, fairly opaque: most of the volume is hidden behind its front layers.
TransferFunction opaque_tf() {
    TransferFunction tf;
    tf.name = "opaque";
    tf.color = {{0.0, 0.9f, 0.6f, 0.3f}, {1.0, 0.3f, 0.6f, 1.0f}};
    tf.opacity = {{0.0, 0}, {0.2, 0}, {0.25, 0.4f}, {1.0, 0.9f}};
    return tf;
}

struct Scene {
    Volume volume;
    TransferLut lut;
};

// Dense scenes: the Marschner-Lobb signal (visible almost everywhere) and a solid sphere.
Scene dense(Vec3i dims, VoxelType t, uint32_t seed,
            SyntheticKind kind = SyntheticKind::MarschnerLobb) {
    SyntheticOptions o;
    o.dims = dims;
    o.type = t;
    o.seed = seed;
    Scene s{generate(kind, o), {}};
    s.lut = discretise(opaque_tf(), s.volume.vis_range());
    return s;
}

Camera camera(const SliceRenderer& r, Rng& rng, int size) {
    OrbitParams p;
    p.azimuth_deg = 360.f * rng.uniform();
    p.elevation_deg = -60.f + 120.f * rng.uniform();
    p.zoom = 0.8f + 1.5f * rng.uniform();
    p.projection = rng.coin() ? Projection::Orthographic : Projection::Perspective;
    return Camera::orbit(r.bounds(), p, size, size);
}

TEST(OcclusionClipping, ThresholdOneIsByteIdenticalAndBelowIsBounded) {
    Rng rng{99};
    uint64_t skipped_views = 0;
    for (int vol = 0; vol < 3; ++vol) {
        const Scene s =
            dense({28 + vol * 3, 26, 30 - vol * 2}, vol == 1 ? VoxelType::Int16 : VoxelType::UInt8,
                  11 + vol, vol == 2 ? SyntheticKind::Sphere : SyntheticKind::MarschnerLobb);
        SliceRenderer r(s.volume);
        r.set_transfer_function(s.lut);
        AccelOptions ao;
        ao.kd_min_volume = 0.002f;  // many small boxes: culling and clipping at work
        auto kd = make_box_source("kdtree", s.volume, ao);
        kd->set_transfer_function(s.lut);
        RandomBspSource bsp(s.volume, 40 + uint64_t(vol), 8);
        bsp.set_transfer_function(s.lut);
        for (int view = 0; view < 4; ++view) {
            const Camera cam = camera(r, rng, 48);
            // One box (view 0): no map update fits in a frame.
            r.set_box_source(view == 0 ? nullptr : (view == 1 ? kd.get() : &bsp));
            SliceOptions o;
            o.keep_float = true;
            const SliceResult ref = r.render(cam, o);
            for (OcclusionMode mode :
                 {OcclusionMode::CullClip, OcclusionMode::CullOnly, OcclusionMode::MapOnly}) {
                const std::string what = "volume " + std::to_string(vol) + " view " +
                                         std::to_string(view) + " " + to_string(mode);
                o.occlusion.mode = mode;
                o.occlusion.updates = 6;
                o.occlusion.map_size = view == 3 ? 16 : 64;
                o.occlusion.threshold = 1.f;
                const SliceResult same = r.render(cam, o);
                ASSERT_EQ(same.image.rgba, ref.image.rgba) << what;
                ASSERT_EQ(0, std::memcmp(same.rgba_float.data(), ref.rgba_float.data(),
                                         ref.rgba_float.size() * 4))
                    << what;
                o.occlusion.threshold = 0.95f;
                const SliceResult approx = r.render(cam, o);
                float worst = 0;
                for (size_t i = 0; i < ref.rgba_float.size(); ++i)
                    worst = std::max(worst, std::abs(approx.rgba_float[i] - ref.rgba_float[i]));
                ASSERT_LE(worst, 0.05f + 1e-5f) << what;
                int worst8 = 0;
                for (size_t i = 0; i < ref.image.rgba.size(); ++i)
                    worst8 = std::max(worst8,
                                      std::abs(int(approx.image.rgba[i]) - int(ref.image.rgba[i])));
                ASSERT_LE(worst8, 14) << what;  // ceil(255 * 0.05) + rounding
                if (mode == OcclusionMode::MapOnly) {
                    ASSERT_EQ(approx.image.rgba, ref.image.rgba) << what;
                    EXPECT_EQ(approx.stats.voxels_culled + approx.stats.voxels_clipped, 0.0);
                }
                if (mode != OcclusionMode::MapOnly && approx.stats.skipped_fraction() > 0.05) {
                    ++skipped_views;
                    EXPECT_LT(approx.stats.samples, ref.stats.samples) << what;
                }
                EXPECT_LE(approx.stats.map_updates, 6) << what;
                if (view >= 2) EXPECT_GT(approx.stats.map_updates, 0) << what;  // 100+ boxes
            }
            o.occlusion = {};
        }
    }
    // Not vacuous: the dense volumes hide most voxels from most views.
    EXPECT_GE(skipped_views, 8u);
}

TEST(OcclusionClipping, SameBytesForAnyThreadCount) {
    const Scene s = dense({33, 29, 31}, VoxelType::UInt8, 5);
    SliceRenderer r(s.volume);
    r.set_transfer_function(s.lut);
    AccelOptions ao;
    ao.kd_min_volume = 0.002f;
    RandomBspSource bsp(s.volume, 9, 8);
    bsp.set_transfer_function(s.lut);
    r.set_box_source(&bsp);
    Rng rng{8};
    const Camera cam = camera(r, rng, 57);
    SliceOptions o;
    o.occlusion.mode = OcclusionMode::CullClip;
    o.threads = 1;
    const SliceResult ref = r.render(cam, o);
    for (int t : {2, 3}) {
        o.threads = t;
        const SliceResult x = r.render(cam, o);
        ASSERT_EQ(x.image.rgba, ref.image.rgba) << t << " threads";
        EXPECT_EQ(x.stats.voxels_clipped, ref.stats.voxels_clipped);
        EXPECT_EQ(x.stats.map_updates, ref.stats.map_updates);
    }
}

TEST(OcclusionMap, BackProjectionInvertsProjection) {
    Rng rng{4};
    for (int t = 0; t < 50; ++t) {
        OrbitParams p;
        p.azimuth_deg = 360.f * rng.uniform();
        p.elevation_deg = -70.f + 140.f * rng.uniform();
        p.projection = rng.coin() ? Projection::Orthographic : Projection::Perspective;
        const Vec3i dims{30, 20, 25};
        const Vec3d sp{1.0, 1.5, 0.8};
        const Camera cam = Camera::orbit({{0, 0, 0}, {29.f, 28.5f, 19.2f}}, p, 32, 32);
        OcclusionMap m(cam, dims, sp, 64);
        ASSERT_TRUE(m.valid_geometry());
        for (int k = 0; k < 20; ++k) {
            const Vec3d x{29 * rng.uniform_d(), 19 * rng.uniform_d(), 24 * rng.uniform_d()};
            double u, v;
            m.project(x, u, v);
            const MapRect b = m.back_project({u, v, u, v}, x[m.axis()]);
            const int a1 = (m.axis() + 1) % 3, a2 = (m.axis() + 2) % 3;
            ASSERT_NEAR(b.u0, x[a1], 1e-9);
            ASSERT_NEAR(b.v0, x[a2], 1e-9);
        }
    }
}

TEST(OcclusionMap, VisibleRectangleCoversTransparentCellsAndOutside) {
    OrbitParams p;
    p.projection = Projection::Orthographic;
    p.elevation_deg = 90.f;
    const Camera cam = Camera::orbit({{0, 0, 0}, {15.f, 15.f, 15.f}}, p, 64, 64);
    OcclusionMap m(cam, {16, 16, 16}, {1, 1, 1}, 8);
    ASSERT_EQ(m.axis(), 2);
    std::vector<float> ox, oy, oz, dx, dy, dz;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const Ray r = cam.generate(float(x), float(y));
            ox.push_back(r.origin.x), oy.push_back(r.origin.y), oz.push_back(r.origin.z);
            dx.push_back(r.dir.x), dy.push_back(r.dir.y), dz.push_back(r.dir.z);
        }
    m.assign_pixels(ox, oy, oz, dx, dy, dz);
    // Opaque everywhere except the pixels whose rays cross x < 4 (index space).
    std::vector<float> alpha(64 * 64, 1.f);
    float last = 0;  // the largest x of a transparent pixel's ray
    for (size_t i = 0; i < alpha.size(); ++i)
        if (ox[i] < 4.f) {
            alpha[i] = 0.f;
            last = std::max(last, ox[i]);
        }
    m.update(alpha.data(), 1);
    const MapRect all = m.project_box({0, 0, 0}, {15, 15, 15});
    const MapRect vis = m.visible(all, 0.95f);
    ASSERT_FALSE(vis.empty());
    EXPECT_LE(vis.u0, 0.0 + 1e-9);
    EXPECT_GE(vis.u1, last);
    EXPECT_LE(vis.u1, last + 15.0 / 8);  // at most one cell beyond
    const MapRect hidden = m.visible(m.project_box({8, 8, 0}, {12, 12, 3}), 0.95f);
    EXPECT_TRUE(hidden.empty());
    // Sticking out of the map: the outside strip is visible.
    const MapRect out = m.visible(m.project_box({8, 8, 0}, {12, 30, 3}), 0.95f);
    EXPECT_FALSE(out.empty());
    const BoxClip bc = clip_box(m, {8, 8, 0}, {12, 12, 3}, 0.95f);
    EXPECT_TRUE(bc.culled);
    const BoxClip part = clip_box(m, {0, 0, 0}, {12, 12, 3}, 0.95f);
    EXPECT_FALSE(part.culled);
    EXPECT_LT(part.hi[0], 12.0);
    EXPECT_GE(part.hi[0], last);
}

TEST(AdaptiveUpdates, PollsEveryNthFrameAndMovesTowardTheBest) {
    AdaptiveOptions o;  // k = 9, hw = 3, n = 10, c = 0.02
    AdaptiveUpdates a(o);
    // Performance: skipping grows with k up to 5 updates, then saturates; each update costs c.
    auto skipped = [](int k) { return std::min(k, 5) * 0.1; };
    std::vector<int> polled;
    for (int f = 0; f < 400; ++f) {
        const int k = a.desired();
        if (f % 10 != 0)
            EXPECT_EQ(k, a.centre()) << "frame " << f;
        else
            polled.push_back(k);
        a.report(skipped(k), k);
    }
    EXPECT_EQ(a.centre(), 5);
    // The first window polls every slot once: 6..12 in the order of their age.
    ASSERT_GE(polled.size(), 7u);
    std::vector<int> first(polled.begin(), polled.begin() + 7);
    std::sort(first.begin(), first.end());
    EXPECT_EQ(first, (std::vector<int>{6, 7, 8, 9, 10, 11, 12}));
}

}  // namespace
}  // namespace lacuna
