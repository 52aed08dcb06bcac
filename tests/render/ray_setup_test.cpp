// The batched ray set-up of the lane paths (core/simd_lanes.h setup_rays8) against the scalar
// definition: Camera::generate, index_ray and kernel::intersect_box, bit for bit, for random
// cameras (perspective and orthographic, inside and outside the box, non-square images),
// anisotropic spacing and pixels anywhere, including rays parallel to a face.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "common/rng.h"
#include "core/simd_lanes.h"
#include "lacuna/orientation.h"
#include "render/pixel_driver.h"

namespace lacuna {
namespace {

uint32_t bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

TEST(RaySetup, EightRaysAtOnceEqualTheScalarSetUpToTheBit) {
    if (!simd::isa_supported(simd::Isa::Avx2)) GTEST_SKIP() << "this CPU has no AVX2 path";
    test::Rng rng{4242};
    int hits = 0, misses = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const Vec3f extent{10.f + 200.f * rng.uniform(), 10.f + 200.f * rng.uniform(),
                           10.f + 200.f * rng.uniform()};
        const Box3f box{{0, 0, 0}, extent};
        OrbitParams p;
        p.azimuth_deg = rng.coin(4) ? 90.f * float(rng.range(0, 3)) : 360.f * rng.uniform();
        p.elevation_deg = rng.coin(4) ? 0.f : -80.f + 160.f * rng.uniform();
        p.projection = rng.coin(3) ? Projection::Orthographic : Projection::Perspective;
        if (rng.coin(3)) {
            p.has_target = true;
            p.target = {extent.x * rng.uniform(), extent.y * rng.uniform(),
                        extent.z * rng.uniform()};
            p.distance = 1.f + 300.f * rng.uniform();
        }
        p.zoom = 0.5f + 3.f * rng.uniform();
        const int w = rng.range(1, 700), h = rng.range(1, 700);
        const Camera cam = Camera::orbit(box, p, w, h);
        const Vec3f sp{0.3f + 2.f * rng.uniform(), 0.3f + 2.f * rng.uniform(),
                       0.3f + 2.f * rng.uniform()};
        const Vec3f inv_sp{1.f / sp.x, 1.f / sp.y, 1.f / sp.z};
        const float hi[3] = {extent.x * inv_sp.x, extent.y * inv_sp.y, extent.z * inv_sp.z};
        const float isp[3] = {inv_sp.x, inv_sp.y, inv_sp.z};
        alignas(32) float px[8], py[8];
        for (int i = 0; i < 8; ++i) {
            px[i] = float(rng.coin(5) ? (rng.coin() ? 0 : w - 1) : rng.range(0, w - 1));
            py[i] = float(rng.coin(5) ? (rng.coin() ? 0 : h - 1) : rng.range(0, h - 1));
        }
        simd::RayBatch8 rb;
        simd::setup_rays8(camera_view(cam), px, py, isp, hi, rb);
        for (int i = 0; i < 8; ++i) {
            const kernel::IndexRay r = index_ray(cam.generate(px[i], py[i]), inv_sp);
            float t0, t1;
            const bool hit = kernel::intersect_box(r, hi, t0, t1);
            const std::string what =
                "trial " + std::to_string(trial) + " lane " + std::to_string(i);
            ASSERT_EQ(bits(rb.ox[i]), bits(r.ox)) << what;
            ASSERT_EQ(bits(rb.oy[i]), bits(r.oy)) << what;
            ASSERT_EQ(bits(rb.oz[i]), bits(r.oz)) << what;
            ASSERT_EQ(bits(rb.dx[i]), bits(r.dx)) << what;
            ASSERT_EQ(bits(rb.dy[i]), bits(r.dy)) << what;
            ASSERT_EQ(bits(rb.dz[i]), bits(r.dz)) << what;
            ASSERT_EQ(rb.hit[i] != 0, hit) << what;
            if (hit) {
                ASSERT_EQ(bits(rb.t_near[i]), bits(t0)) << what;
                ASSERT_EQ(bits(rb.t_far[i]), bits(t1)) << what;
                ++hits;
            } else {
                ++misses;
            }
        }
    }
    EXPECT_GT(hits, 500);
    EXPECT_GT(misses, 100);
}

// Oriented volumes (lacuna/orientation.h): the camera is moved into the volume frame once, so
// every ray of the moved camera is the world camera's ray moved by the rigid map (up to the
// rounding of the basis), and the batched set-up of the moved camera is the scalar one, bit for
// bit, whatever the rotation or mirroring.
TEST(RaySetup, CamerasMovedIntoAnObliqueVolumeFrameGiveTheMappedWorldRaysOnEveryPath) {
    test::Rng rng{1414};
    int compared = 0;
    for (int trial = 0; trial < 60; ++trial) {
        Volume v({rng.range(2, 90), rng.range(2, 90), rng.range(2, 90)}, VoxelType::UInt8);
        v.spacing = {0.3 + 2.0 * rng.uniform_d(), 0.3 + 2.0 * rng.uniform_d(),
                     0.3 + 2.0 * rng.uniform_d()};
        // A random rotation from a random unit quaternion, mirrored on odd trials.
        double q[4];
        double n = 0;
        for (double& c : q) c = rng.uniform_d() - 0.5, n += c * c;
        for (double& c : q) c /= std::sqrt(n);
        const double a = q[0], b = q[1], c = q[2], d = q[3];
        double r[3][3] = {
            {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
            {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
            {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
        if (trial % 2)
            for (auto& row : r) row[0] = -row[0];
        for (int row = 0; row < 3; ++row)
            for (int col = 0; col < 3; ++col) v.direction[row * 3 + col] = r[row][col];
        v.origin = {200 * rng.uniform_d() - 100, 200 * rng.uniform_d() - 100,
                    200 * rng.uniform_d() - 100};
        const VolumeFrame f = volume_frame(v);
        ASSERT_FALSE(f.identity);
        OrbitParams p;
        p.azimuth_deg = 360.f * rng.uniform();
        p.elevation_deg = -85.f + 170.f * rng.uniform();
        p.projection = rng.coin(3) ? Projection::Orthographic : Projection::Perspective;
        const int w = rng.range(1, 300), h = rng.range(1, 300);
        const Camera world = Camera::orbit(world_bounds(v), p, w, h);
        const Camera cam = to_volume_frame(f, world);
        const Vec3f inv_sp = inverse_spacing(v);
        const Vec3i dims = v.dims();
        const float hi[3] = {float(dims.x - 1), float(dims.y - 1), float(dims.z - 1)};
        const float isp[3] = {inv_sp.x, inv_sp.y, inv_sp.z};
        alignas(32) float px[8], py[8];
        for (int i = 0; i < 8; ++i) {
            px[i] = float(rng.range(0, w - 1));
            py[i] = float(rng.range(0, h - 1));
        }
        for (int i = 0; i < 8; ++i) {
            const Ray wr = world.generate(px[i], py[i]), vr = cam.generate(px[i], py[i]);
            const Vec3f o = f.point(wr.origin), dir = f.vector(wr.dir);
            const float scale = 1.f + length(wr.origin) + length(Vec3f(f.from));
            for (int k = 0; k < 3; ++k) {
                ASSERT_NEAR(vr.origin[k], o[k], 1e-5f * scale) << trial;
                ASSERT_NEAR(vr.dir[k], dir[k], 1e-5f) << trial;
            }
        }
        if (!simd::isa_supported(simd::Isa::Avx2)) continue;
        simd::RayBatch8 rb;
        simd::setup_rays8(camera_view(cam), px, py, isp, hi, rb);
        for (int i = 0; i < 8; ++i) {
            const kernel::IndexRay r = index_ray(cam.generate(px[i], py[i]), inv_sp);
            float t0, t1;
            const bool hit = kernel::intersect_box(r, hi, t0, t1);
            ASSERT_EQ(bits(rb.ox[i]), bits(r.ox)) << trial;
            ASSERT_EQ(bits(rb.oy[i]), bits(r.oy)) << trial;
            ASSERT_EQ(bits(rb.oz[i]), bits(r.oz)) << trial;
            ASSERT_EQ(bits(rb.dx[i]), bits(r.dx)) << trial;
            ASSERT_EQ(bits(rb.dy[i]), bits(r.dy)) << trial;
            ASSERT_EQ(bits(rb.dz[i]), bits(r.dz)) << trial;
            ASSERT_EQ(rb.hit[i] != 0, hit) << trial;
            if (hit) {
                ASSERT_EQ(bits(rb.t_near[i]), bits(t0)) << trial;
                ASSERT_EQ(bits(rb.t_far[i]), bits(t1)) << trial;
            }
            ++compared;
        }
    }
    if (simd::isa_supported(simd::Isa::Avx2)) EXPECT_GT(compared, 400);
}

}  // namespace
}  // namespace lacuna
