#include "lacuna/camera.h"

#include <gtest/gtest.h>

namespace lacuna {
namespace {

// Projects a world point onto the image plane of a perspective camera; returns pixel coords.
bool project(const Camera& cam, Vec3f p, float& px, float& py) {
    // Search by comparing with generated rays: use the centre ray and the pixel footprint.
    const Ray c = cam.generate(cam.width() / 2.f - 0.5f, cam.height() / 2.f - 0.5f);
    const Ray rx = cam.generate(cam.width() / 2.f + 0.5f, cam.height() / 2.f - 0.5f);
    const Ray ry = cam.generate(cam.width() / 2.f - 0.5f, cam.height() / 2.f + 0.5f);
    const Vec3f d = p - cam.eye();
    const float depth = dot(d, cam.forward());
    if (depth <= 0) return false;
    // Directions scaled to unit depth.
    auto at_depth = [&](Vec3f dir) { return dir / dot(dir, cam.forward()); };
    const Vec3f dc = at_depth(c.dir), dx = at_depth(rx.dir) - dc, dy = at_depth(ry.dir) - dc;
    const Vec3f q = d / depth - dc;
    px = cam.width() / 2.f + dot(q, dx) / dot(dx, dx);
    py = cam.height() / 2.f + dot(q, dy) / dot(dy, dy);
    return true;
}

TEST(Camera, DefaultOrbitFramesTheWholeVolume) {
    const Box3f b{{0, 0, 0}, {180, 216, 180}};
    for (float az : {0.f, 30.f, 95.f, 200.f})
        for (float el : {-60.f, 0.f, 15.f, 80.f}) {
            OrbitParams p;
            p.azimuth_deg = az;
            p.elevation_deg = el;
            const Camera cam = Camera::orbit(b, p, 320, 200);
            for (int c = 0; c < 8; ++c) {
                const Vec3f corner{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y,
                                   c & 4 ? b.hi.z : b.lo.z};
                float px, py;
                ASSERT_TRUE(project(cam, corner, px, py));
                EXPECT_GE(px, 0.f);
                EXPECT_LE(px, 320.f);
                EXPECT_GE(py, 0.f);
                EXPECT_LE(py, 200.f);
            }
        }
}

TEST(Camera, RaysAreUnitLengthAndOrthographicRaysParallel) {
    const Box3f b{{0, 0, 0}, {10, 20, 30}};
    OrbitParams p;
    p.projection = Projection::Orthographic;
    const Camera cam = Camera::orbit(b, p, 64, 48);
    const Ray a = cam.generate(0, 0), c = cam.generate(63, 47);
    EXPECT_NEAR(length(a.dir), 1.f, 1e-6f);
    EXPECT_EQ(a.dir, c.dir);
    EXPECT_GT(length(a.origin - c.origin), 1.f);
    p.projection = Projection::Perspective;
    const Camera persp = Camera::orbit(b, p, 64, 48);
    EXPECT_NEAR(length(persp.generate(5, 7).dir), 1.f, 1e-6f);
    EXPECT_EQ(persp.generate(0, 0).origin, persp.generate(63, 47).origin);
}

// World is patient RAS (+x right, +y anterior, +z superior): azimuth 0 is the anterior view, the
// eye in front of the face looking toward posterior, superior up, the patient's right on the
// screen's left; azimuth 90 looks from the patient's left.
TEST(Camera, AzimuthZeroIsTheAnteriorViewAndNinetyTheLeftView) {
    const Box3f b{{0, 0, 0}, {10, 10, 10}};
    OrbitParams p;
    p.azimuth_deg = 0;
    p.elevation_deg = 0;
    const Camera cam = Camera::orbit(b, p, 10, 10);
    EXPECT_NEAR(cam.forward().y, -1.f, 1e-6f);
    EXPECT_GT(cam.eye().y, 10.f);
    EXPECT_NEAR(cam.up().z, 1.f, 1e-6f);
    EXPECT_NEAR(cam.right().x, -1.f, 1e-6f);  // screen right = patient's left
    p.azimuth_deg = 90;
    const Camera left = Camera::orbit(b, p, 10, 10);
    EXPECT_NEAR(left.forward().x, 1.f, 1e-6f);
    EXPECT_LT(left.eye().x, 0.f);
    EXPECT_NEAR(left.right().y, -1.f, 1e-6f);  // screen right = posterior: the face on the left
    // Looking straight down: anterior is up on the screen, the patient's right on the right.
    p.azimuth_deg = 0;
    p.elevation_deg = 90;
    const Camera top = Camera::orbit(b, p, 10, 10);
    EXPECT_NEAR(top.forward().z, -1.f, 1e-6f);
    EXPECT_NEAR(top.up().y, 1.f, 1e-6f);
    EXPECT_NEAR(top.right().x, 1.f, 1e-6f);
}

}  // namespace
}  // namespace lacuna
