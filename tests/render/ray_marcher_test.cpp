// The reference ray marcher against analytic answers: Beer-Lambert transmittance through a
// homogeneous medium, a sphere's silhouette, determinism across thread counts, ERT bounds.
#include <gtest/gtest.h>

#include <cmath>

#include "lacuna/camera.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {
namespace {

TransferFunction constant_tf(float opacity) {
    TransferFunction tf;
    tf.name = "constant";
    tf.color = {{0.0, 1, 1, 1}, {1.0, 1, 1, 1}};
    tf.opacity = {{0.0, opacity}, {1.0, opacity}};
    return tf;
}

// Orthographic camera looking straight down -z through the volume.
Camera top_down(const RayMarcher& m, int size) {
    OrbitParams p;
    p.projection = Projection::Orthographic;
    p.elevation_deg = 90.f;
    p.azimuth_deg = 0.f;
    p.zoom = 4.f;  // the image covers only the middle of the box: every ray crosses all of z
    return Camera::orbit(m.bounds(), p, size, size);
}

TEST(RayMarcher, HomogeneousMediumTransmittanceIsBeerLambert) {
    Volume v({17, 17, 65}, VoxelType::UInt8);
    for (int k = 0; k < 65; ++k)
        for (int j = 0; j < 17; ++j)
            for (int i = 0; i < 17; ++i) v.set_value(i, j, k, 200);
    v.compute_range();
    const float a = 0.03f;  // opacity per unit length
    const double sigma = -std::log(1.0 - a);
    const double length = 64.0;  // the box spans z in [0, 64]
    RayMarcher m(v);
    m.set_transfer_function(discretise(constant_tf(a), v.vis_range()));
    // Steps that divide the 64-unit path: the sampled length is exactly L, so only float
    // rounding separates the result from exp(-sigma L).
    for (float step : {1.f, 0.5f, 0.25f, 0.4f, 0.8f, 0.32f}) {
        RenderOptions o;
        o.step = step;
        o.ert = kNoEarlyTermination;
        o.keep_float = true;
        const RenderResult r = m.render(top_down(m, 8), o);
        const double expected = std::exp(-sigma * length);
        for (size_t p = 0; p < 64; ++p) {
            const double transmittance = 1.0 - r.rgba_float[p * 4 + 3];
            ASSERT_NEAR(transmittance, expected, 1e-3) << "step " << step << " pixel " << p;
        }
    }
    // A step that does not divide L samples round(L/dt) steps: the error is at most the
    // absorption of half a step.
    for (float step : {0.7f, 0.3f}) {
        RenderOptions o;
        o.step = step;
        o.ert = kNoEarlyTermination;
        o.keep_float = true;
        const RenderResult r = m.render(top_down(m, 4), o);
        const double expected = std::exp(-sigma * length);
        const double bound = expected * (std::exp(sigma * step / 2) - 1) + 1e-5;
        for (size_t p = 0; p < 16; ++p)
            ASSERT_NEAR(1.0 - r.rgba_float[p * 4 + 3], expected, bound) << "step " << step;
    }
}

TEST(RayMarcher, SamplesAtFixedMultiplesOfTheStep) {
    Volume v({9, 9, 41}, VoxelType::UInt8);
    v.compute_range();
    v.set_vis_range({0, 1});
    RayMarcher m(v);
    m.set_transfer_function(discretise(constant_tf(0.f), v.vis_range()));
    RenderOptions o;
    o.step = 0.5f;
    o.count_samples = true;
    const RenderResult r = m.render(top_down(m, 4), o);
    // 40 units of z at 0.5: exactly 80 samples per ray, t_k = (k + 0.5) * 0.5.
    for (uint32_t c : r.sample_counts) EXPECT_EQ(c, 80u);
    EXPECT_EQ(r.stats.samples, 80u * 16u);
    EXPECT_EQ(r.stats.rays, 16u);
}

TEST(RayMarcher, SphereSilhouetteIsWhereGeometryPutsIt) {
    const int n = 48;
    const float c = (n - 1) / 2.f, radius = 15.f;
    Volume v({n, n, n}, VoxelType::UInt8);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const float d =
                    std::sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c));
                v.set_value(i, j, k, d <= radius ? 255 : 0);
            }
    v.compute_range();
    TransferFunction tf;
    tf.color = {{0.0, 1, 1, 1}};
    tf.opacity = {{0.0, 0.f}, {0.49, 0.f}, {0.5, 0.8f}, {1.0, 0.8f}};
    RayMarcher m(v);
    m.set_transfer_function(discretise(tf, v.vis_range()));
    for (Projection proj : {Projection::Orthographic, Projection::Perspective}) {
        OrbitParams p;
        p.projection = proj;
        p.azimuth_deg = 37.f;
        p.elevation_deg = 21.f;
        const int size = 96;
        const Camera cam = Camera::orbit(m.bounds(), p, size, size);
        RenderOptions o;
        o.keep_float = true;
        const RenderResult r = m.render(cam, o);
        int inside = 0, outside = 0;
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const Ray ray = cam.generate(float(x), float(y));
                // Distance from the sphere's centre to the ray's line.
                const Vec3f to_c = Vec3f{c, c, c} - ray.origin;
                const float along = dot(to_c, ray.dir);
                const float dist = length(to_c - ray.dir * along);
                const float alpha = r.rgba_float[(size_t(y) * size + x) * 4 + 3];
                // Half a voxel of interpolation blur plus the binary voxelisation: 1.5 voxels.
                if (dist < radius - 1.5f) {
                    EXPECT_GT(alpha, 0.5f) << "pixel " << x << "," << y;
                    ++inside;
                } else if (dist > radius + 1.5f) {
                    EXPECT_EQ(alpha, 0.f) << "pixel " << x << "," << y;
                    ++outside;
                }
            }
        EXPECT_GT(inside, 100);
        EXPECT_GT(outside, 100);
    }
}

TEST(RayMarcher, SameBytesForAnyThreadCount) {
    const int n = 40;
    Volume v({n, n + 3, n - 5}, VoxelType::Float32);
    for (int k = 0; k < n - 5; ++k)
        for (int j = 0; j < n + 3; ++j)
            for (int i = 0; i < n; ++i)
                v.set_value(i, j, k, std::sin(0.3f * i) * std::cos(0.2f * j) + 0.05f * k);
    v.compute_range();
    TransferFunction tf;
    tf.color = {{0.0, 0.2f, 0.4f, 1}, {1.0, 1, 0.6f, 0.1f}};
    tf.opacity = {{0.0, 0.f}, {0.3, 0.f}, {0.6, 0.3f}, {1.0, 0.05f}};
    RayMarcher m(v);
    m.set_transfer_function(discretise(tf, v.vis_range()));
    OrbitParams p;
    p.azimuth_deg = 12.f;
    const Camera cam = Camera::orbit(m.bounds(), p, 70, 53);
    RenderOptions o;
    o.tile = 8;
    o.threads = 1;
    const Image ref = m.render(cam, o).image;
    for (int t : {2, 3, 7}) {
        o.threads = t;
        EXPECT_EQ(m.render(cam, o).image.rgba, ref.rgba) << t << " threads";
    }
}

TEST(RayMarcher, EarlyRayTerminationErrorIsBoundedByThreshold) {
    Volume v({32, 32, 32}, VoxelType::UInt8);
    for (int k = 0; k < 32; ++k)
        for (int j = 0; j < 32; ++j)
            for (int i = 0; i < 32; ++i) v.set_value(i, j, k, (i * 7 + j * 3 + k * 5) % 256);
    v.compute_range();
    TransferFunction tf;
    tf.color = {{0.0, 1, 0, 0}, {0.5, 0, 1, 0}, {1.0, 0, 0, 1}};
    tf.opacity = {{0.0, 0.1f}, {1.0, 0.5f}};
    RayMarcher m(v);
    m.set_transfer_function(discretise(tf, v.vis_range()));
    const Camera cam = Camera::orbit(m.bounds(), OrbitParams{}, 48, 48);
    RenderOptions full, ert;
    full.ert = kNoEarlyTermination;
    full.keep_float = ert.keep_float = true;
    ert.ert = 0.95f;
    const RenderResult a = m.render(cam, full), b = m.render(cam, ert);
    EXPECT_LT(b.stats.samples, a.stats.samples);
    for (size_t i = 0; i < a.rgba_float.size(); ++i)
        ASSERT_LE(std::abs(a.rgba_float[i] - b.rgba_float[i]), 1.f - 0.95f + 1e-5f);
}

TEST(RayMarcher, FullyTransparentTfLeavesTheBackground) {
    Volume v({10, 11, 12}, VoxelType::Int16);
    v.set_value(5, 5, 5, 1000);
    v.compute_range();
    RayMarcher m(v);
    m.set_transfer_function(discretise(constant_tf(0.f), v.vis_range()));
    RenderOptions o;
    o.background = {0.2f, 0.4f, 0.6f};
    const RenderResult r = m.render(Camera::orbit(m.bounds(), OrbitParams{}, 16, 16), o);
    for (size_t p = 0; p < 256; ++p) {
        EXPECT_EQ(r.image.rgba[p * 4 + 0], 51);
        EXPECT_EQ(r.image.rgba[p * 4 + 1], 102);
        EXPECT_EQ(r.image.rgba[p * 4 + 2], 153);
    }
}

TEST(RayMarcher, OpacityCorrectionKeepsZeroAndComposesAcrossSteps) {
    TransferLut lut;
    lut.vis = {0, 1};
    lut.entries = {{1, 1, 1, 0.f}, {1, 1, 1, 0.5f}, {1, 1, 1, 1.f}};
    const auto half = step_corrected_lut(lut, 0.5f);
    EXPECT_EQ(half[0].a, 0.f);
    EXPECT_EQ(half[2].a, 1.f);
    // Two half steps absorb what one full step does: (1 - a')^2 == 1 - a.
    EXPECT_NEAR((1 - half[1].a) * (1 - half[1].a), 0.5f, 1e-6f);
}

}  // namespace
}  // namespace lacuna
