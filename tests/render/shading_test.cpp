// Analytic checks of the feature path (docs/shading.md): gradients and Phong/Lambert terms on a
// ball against its analytic normal, the PBR terms at normal incidence, shadow transmittance in a
// uniform medium, MIP against known volumes and brute force, clip planes and the crop box
// removing exactly their half-spaces, jitter determinism, and the light volume cache.
#include "render/shading.h"

#include <gtest/gtest.h>

#include <cmath>

#include "accel/no_accel.h"
#include "common/rng.h"
#include "conformance/conformance_util.h"
#include "core/gradient.h"
#include "core/spec_pow.h"
#include "lacuna/error.h"
#include "lacuna/renderer.h"
#include "render/feature_kernel.h"

namespace lacuna {
namespace {

// A ball with a smooth radial profile: value 1000 / (1 + exp((r - R) / 1.5)), centre c (index).
Volume ball(int n, float radius, Vec3d spacing = {1, 1, 1}) {
    Volume v({n, n, n}, VoxelType::Float32);
    v.spacing = spacing;
    const float c = 0.5f * float(n - 1);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const float r =
                    std::sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
                v.set_value(x, y, z, 1000.f / (1.f + std::exp((r - radius) / 1.5f)));
            }
    v.compute_range();
    return v;
}

// Step TF: opaque white where the value is >= `from` (LUT entries), transparent below.
TransferLut step_lut(const Volume& v, float from_value, Rgba colour = {1, 1, 1, 1}) {
    TransferLut lut;
    lut.vis = v.vis_range();
    lut.entries.assign(kDefaultLutSize, Rgba{});
    const int e0 = lut.map()(from_value);
    for (int e = e0; e < kDefaultLutSize; ++e) lut.entries[size_t(e)] = colour;
    return lut;
}

feature::Context context_for(const Volume& v, const FeatureOptions& f) {
    feature::Context c;
    c.f = &f;
    c.sp = {float(v.spacing.x), float(v.spacing.y), float(v.spacing.z)};
    c.inv_sp = {1.f / c.sp.x, 1.f / c.sp.y, 1.f / c.sp.z};
    return c;
}

TEST(Shading, OnTheFlyAndPrecomputedGradientsFollowTheBallsNormal) {
    // Anisotropic spacing: gradients are in world units, the ball is round in index space, so
    // the world normal is the index-space radial direction divided by the spacing.
    const Vec3d sp{1.0, 1.5, 0.75};
    const Volume v = ball(33, 10.f, sp);
    FeatureOptions f;
    feature::Context c = context_for(v, f);
    const Vec3i d = v.dims();
    const kernel::Grid<float, int64_t> g{v.data_as<float>(),
                                         d.x,
                                         ptrdiff_t(d.x) * d.y,
                                         float(d.x - 1),
                                         float(d.y - 1),
                                         float(d.z - 1),
                                         d.x - 2,
                                         d.y - 2,
                                         d.z - 2};
    test::Rng rng{3};
    for (int i = 0; i < 200; ++i) {
        // Random points on the r = 10 sphere.
        Vec3f u{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f};
        if (length(u) < 0.1f) continue;
        u = normalize(u);
        const Vec3f p = Vec3f{16, 16, 16} + u * 10.f;
        const Vec3f grad = feature::gradient(c, g, p.x, p.y, p.z);
        Vec3f n;
        ASSERT_TRUE(shading::normal_from_gradient(grad, u, n));
        const Vec3f expected =
            normalize(Vec3f{u.x / float(sp.x), u.y / float(sp.y), u.z / float(sp.z)});
        EXPECT_GT(dot(n, expected), std::cos(3.f * shading::kPi / 180.f)) << "point " << i;
    }
}

// core/gradient.h's argument, checked: the interpolated central differences of the voxels are
// the central differences (f(p + e) - f(p - e)) / 2 of the trilinear field f, in double
// precision here, wherever p +- 1 stays inside the grid; at a face, the border voxel repeated.
TEST(Shading, OnTheFlyGradientIsTheCentralDifferenceOfTheTrilinearField) {
    test::Rng rng{77};
    const int dims[3] = {9, 7, 8};
    Volume v({dims[0], dims[1], dims[2]}, VoxelType::Int16);
    for (int z = 0; z < dims[2]; ++z)
        for (int y = 0; y < dims[1]; ++y)
            for (int x = 0; x < dims[0]; ++x) v.set_value(x, y, z, float(rng.range(-3000, 3000)));
    v.compute_range();
    const int16_t* d = v.data_as<int16_t>();
    const ptrdiff_t sy = dims[0], sz = ptrdiff_t(dims[0]) * dims[1];
    const float hi[3] = {8, 6, 7}, inv_sp[3] = {1.f, 0.5f, 2.f};
    const int cell[3] = {7, 5, 6};
    auto vox = [&](int x, int y, int z) {
        x = std::clamp(x, 0, dims[0] - 1), y = std::clamp(y, 0, dims[1] - 1),
        z = std::clamp(z, 0, dims[2] - 1);
        return double(d[z * sz + y * sy + x]);
    };
    auto field = [&](double x, double y, double z) {  // trilinear, double precision
        const int i = std::min(int(x), cell[0]), j = std::min(int(y), cell[1]),
                  k = std::min(int(z), cell[2]);
        const double fx = x - i, fy = y - j, fz = z - k;
        double s = 0;
        for (int q = 0; q < 8; ++q) {
            const int a = q & 1, b = q >> 1 & 1, c = q >> 2;
            s += (a ? fx : 1 - fx) * (b ? fy : 1 - fy) * (c ? fz : 1 - fz) *
                 vox(i + a, j + b, k + c);
        }
        return s;
    };
    int interior = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const double p[3] = {rng.uniform() * hi[0], rng.uniform() * hi[1], rng.uniform() * hi[2]};
        float g[3];
        central_gradient(d, sy, sz, hi, cell, inv_sp, float(p[0]), float(p[1]), float(p[2]), g);
        const double q[3] = {double(float(p[0])), double(float(p[1])), double(float(p[2]))};
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside = inside && q[a] >= 1.0 && q[a] <= hi[a] - 1.0;
        for (int a = 0; a < 3; ++a) {
            double lo[3] = {q[0], q[1], q[2]}, up[3] = {q[0], q[1], q[2]};
            if (inside) {
                lo[a] -= 1, up[a] += 1;
                const double want =
                    (field(up[0], up[1], up[2]) - field(lo[0], lo[1], lo[2])) * 0.5 * inv_sp[a];
                ASSERT_NEAR(g[a], want, 2e-3 * (1 + std::abs(want)))
                    << "axis " << a << " trial " << trial;
            } else {
                // The border voxel repeated: interpolate v[i+1] - v[i-1] with clamped indices.
                const int i = std::min(int(q[0]), cell[0]), j = std::min(int(q[1]), cell[1]),
                          k = std::min(int(q[2]), cell[2]);
                const double f[3] = {q[0] - i, q[1] - j, q[2] - k};
                double s = 0;
                for (int c8 = 0; c8 < 8; ++c8) {
                    int o[3] = {i + (c8 & 1), j + (c8 >> 1 & 1), k + (c8 >> 2)};
                    double w = 1;
                    for (int e = 0; e < 3; ++e) w *= (c8 >> e & 1) ? f[e] : 1 - f[e];
                    int u[3] = {o[0], o[1], o[2]}, m[3] = {o[0], o[1], o[2]};
                    ++u[a], --m[a];
                    s += w * (vox(u[0], u[1], u[2]) - vox(m[0], m[1], m[2]));
                }
                ASSERT_NEAR(g[a], s * 0.5 * inv_sp[a], 2e-3 * (1 + std::abs(s)))
                    << "face, axis " << a;
            }
        }
        interior += inside;
    }
    EXPECT_GT(interior, 200);
    EXPECT_LT(interior, 3800);
}

TEST(Shading, LambertTermOfAShadedBallMatchesTheAnalyticNormal) {
    // Orthographic view along -z, headlight, Phong with only the diffuse term, an opaque step TF
    // at the ball's mid value: each pixel is the first opaque sample's N.V = sqrt(1 - rho^2/R^2).
    const int n = 41;
    const float R = 14.f;
    const Volume v = ball(n, R);
    for (GradientSource src : {GradientSource::OnTheFly, GradientSource::Precomputed}) {
        RayMarcher m(v);
        m.set_transfer_function(step_lut(v, 500.f));
        OrbitParams p;
        p.azimuth_deg = 0, p.elevation_deg = 90,
        p.projection = Projection::Orthographic;  // eye on +z, x right, y up
        const int size = 64;
        const Camera cam = Camera::orbit(m.bounds(), p, size, size);
        RenderOptions ro;
        ro.step = 0.25f;
        ro.features.shading = ShadingModel::Phong;
        ro.features.phong = {0.f, 1.f, 0.f, 1.f};
        ro.features.gradient = src;
        const RenderResult r = m.render(cam, ro);
        if (src == GradientSource::Precomputed)
            EXPECT_EQ(r.stats.gradient_volume_bytes, v.voxel_count() * 12);
        int checked = 0;
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const Ray ray = cam.generate(float(x), float(y));
                const float c = 0.5f * float(n - 1);
                const float rho = std::hypot(ray.origin.x - c, ray.origin.y - c);
                if (rho > 0.8f * R) continue;
                const float expected = std::sqrt(1.f - rho * rho / (R * R));
                EXPECT_NEAR(r.image.pixel(x, y)[0] / 255.f, expected, 0.05f) << x << "," << y;
                ++checked;
            }
        EXPECT_GT(checked, 250);
    }
}

TEST(Shading, PhongAndPbrTermsAtNormalIncidence) {
    const Vec3f n{0, 0, 1};
    // Phong: N = L = V: ambient + diffuse + specular.
    const Vec3f c = shading::phong({0.1f, 0.6f, 0.3f, 10.f}, {0.5f, 1.f, 0.f}, n, n, n, 1.f);
    EXPECT_FLOAT_EQ(c.x, 0.5f * 0.7f + 0.3f);
    EXPECT_FLOAT_EQ(c.y, 0.7f + 0.3f);
    // Light from 60 degrees: diffuse cos = 0.5, no specular toward the view when power is high.
    const Vec3f l{std::sin(shading::kPi / 3), 0, std::cos(shading::kPi / 3)};
    const Vec3f c2 = shading::phong({0.f, 1.f, 0.f, 1.f}, {1, 1, 1}, n, l, n, 2.f);
    EXPECT_NEAR(c2.x, 1.0f, 1e-5f);
    // PBR at N = L = V, white dielectric, roughness 1 (alpha 1): Disney diffuse = 1,
    // D = 1/pi, V = 1/4, F = 0.04: specular pi * D * V * F = 0.01.
    PbrParams pb;
    pb.roughness = 1.f, pb.metallic = 0.f, pb.ambient = 0.f;
    const Vec3f p = shading::pbr(pb, {1, 1, 1}, n, n, n, 1.f);
    EXPECT_NEAR(p.x, 1.f + 0.01f, 1e-4f);
    // Metal: no diffuse, F0 = albedo -> specular = albedo * 0.25 / alpha^3 at roughness 1.
    pb.metallic = 1.f;
    const Vec3f q = shading::pbr(pb, {0.5f, 0.5f, 0.5f}, n, n, n, 1.f);
    EXPECT_NEAR(q.x, 0.5f * 0.25f, 1e-4f);
    // Lit from behind: only ambient is left.
    pb.metallic = 0.f, pb.ambient = 0.3f;
    const Vec3f b = shading::pbr(pb, {1, 1, 1}, n, -n, n, 1.f);
    EXPECT_NEAR(b.x, 0.3f, 1e-5f);
    EXPECT_FLOAT_EQ(shading::spot_factor(1.f, 30.f), 1.f);
    EXPECT_FLOAT_EQ(shading::spot_factor(std::cos(0.6f), 30.f), 0.f);
}

// The specular power (core/spec_pow.h): integer powers n by binary exponentiation stay within
// 2n float ulps of the exact power (computed in double: each squaring doubles the relative error
// it inherits; for the default n = 24 that is < 3e-6, far below 1/255); other powers are
// std::pow itself.
TEST(Shading, SpecularPowerIsThePowerWithinUlps) {
    test::Rng rng{4242};
    double worst = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const float x = trial < 4 ? float(trial) / 3.f : rng.uniform();
        const int n = 1 + int(rng.uniform() * 255.f);
        const float got = simd::spec_pow(x, float(n));
        const double want = std::pow(double(x), double(n));
        if (want < 1e-30) {  // deep in the denormals both are ~0
            ASSERT_LE(got, 1e-29f) << x << "^" << n;
            continue;
        }
        const double rel = std::abs(double(got) - want) / want;
        worst = std::max(worst, rel);
        ASSERT_LE(rel, 2.0 * n * 6e-8) << x << "^" << n;
    }
    EXPECT_GT(worst, 0.0) << "binary exponentiation rounds somewhere";
    for (float p : {0.5f, 2.5f, 300.f, 0.f})
        for (float x : {0.f, 0.25f, 0.9f, 1.f})
            EXPECT_EQ(simd::spec_pow(x, p), std::pow(x, p)) << x << "^" << p;
    EXPECT_EQ(simd::spec_pow(0.5f, 24.f), std::ldexp(1.f, -24));  // exact powers of two stay exact
}

TEST(Shading, ShadowTransmittanceThroughAUniformMediumIsAnalytic) {
    // Uniform value, TF opacity a per unit distance: a shadow ray leaving the box after distance
    // D takes k = ceil(D/dts - 0.5) samples, transmittance (1 - a')^k, a' = 1 - (1-a)^dts.
    Volume v({20, 20, 20}, VoxelType::UInt8);
    for (int z = 0; z < 20; ++z)
        for (int y = 0; y < 20; ++y)
            for (int x = 0; x < 20; ++x) v.set_value(x, y, z, 100.f);
    v.set_value(0, 0, 0, 0.f);
    v.compute_range();
    TransferLut lut;
    lut.vis = v.vis_range();
    lut.entries.assign(kDefaultLutSize, Rgba{1, 1, 1, 0.1f});
    FeatureOptions f;
    f.shadows.enabled = true;
    f.shadows.step = 0.7f;
    feature::Context c = context_for(v, f);
    const auto sh = step_corrected_lut(lut, f.shadows.step);
    c.shadow_corr[0] = c.shadow_corr[1] = sh.data();
    c.map = lut.map();
    c.dts = f.shadows.step;
    const kernel::Grid<uint8_t, int64_t> g{v.data_as<uint8_t>(), 20, 400, 19, 19, 19, 18, 18, 18};
    static const NoAccel none;
    uint64_t n = 0;
    const float T = feature::transmittance(c, g, none, 10.f, 10.f, 10.f, {1, 0, 0}, INFINITY, n);
    const int k = int(std::ceil(9.f / 0.7f - 0.5f));
    EXPECT_EQ(n, uint64_t(k));
    EXPECT_NEAR(T, std::pow(1.f - 0.1f, 0.7f * k), 1e-5f);
    // A spot light 4 mm away stops the ray there.
    n = 0;
    const float T4 = feature::transmittance(c, g, none, 10.f, 10.f, 10.f, {0, 1, 0}, 4.f, n);
    EXPECT_NEAR(T4, std::pow(1.f - 0.1f, 0.7f * std::ceil(4.f / 0.7f - 0.5f)), 1e-5f);
}

TEST(Shading, ShadowsDarkenWhatIsBehindAnOccluder) {
    // A floor at z in [3, 5] and a slab at z in [14, 16] over y < 10; the eye looks down -z,
    // the light comes from direction (0, -1, 1). The slab's shadow falls on the floor at
    // y in [10, 19) (visible to the eye, beside the slab), the floor at y = 22 is lit. Every
    // orthographic ray has the same z lattice, so self-shadowing of the floor is equal in both.
    Volume v({24, 24, 24}, VoxelType::UInt8);
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            for (int z = 3; z <= 5; ++z) v.set_value(x, y, z, 200.f);
            if (y < 10)
                for (int z = 14; z <= 16; ++z) v.set_value(x, y, z, 200.f);
        }
    v.compute_range();
    RayMarcher m(v);
    m.set_transfer_function(step_lut(v, 90.f, {1, 1, 1, 0.5f}));
    OrbitParams p;
    p.azimuth_deg = 0, p.elevation_deg = 90,
    p.projection = Projection::Orthographic;  // eye on +z, x right, y up
    const Camera cam = Camera::orbit(m.bounds(), p, 48, 48);
    RenderOptions ro;
    ro.features.light.kind = LightKind::Directional;
    ro.features.light.direction = {0, -1, 1};
    ro.features.shadows.enabled = true;
    const RenderResult r = m.render(cam, ro);
    // The pixel whose ray passes nearest to (12, y).
    auto pixel_at = [&](float y) {
        int best_x = 0, best_y = 0;
        float best = INFINITY;
        for (int py = 0; py < 48; ++py)
            for (int px = 0; px < 48; ++px) {
                const Ray ray = cam.generate(float(px), float(py));
                const float d = std::hypot(ray.origin.x - 12.f, ray.origin.y - y);
                if (d < best) best = d, best_x = px, best_y = py;
            }
        return r.image.pixel(best_x, best_y)[0];
    };
    const int lit = pixel_at(22.f), dark = pixel_at(14.f);
    EXPECT_GT(lit, 60);
    EXPECT_LT(dark * 3, lit);
}

TEST(Shading, MipOfARampIsTheRampValueOfEachColumn) {
    // value = 10 * x: orthographic rays along z see max = 10 * x of their column.
    Volume v({26, 20, 20}, VoxelType::UInt16);
    for (int z = 0; z < 20; ++z)
        for (int y = 0; y < 20; ++y)
            for (int x = 0; x < 26; ++x) v.set_value(x, y, z, 10.f * float(x));
    v.compute_range();
    TransferLut lut;
    lut.vis = v.vis_range();
    lut.entries.resize(kDefaultLutSize);
    for (int e = 0; e < kDefaultLutSize; ++e)
        lut.entries[size_t(e)] = {float(e) / 1023.f, 0, 0, 1.f};
    RayMarcher m(v);
    m.set_transfer_function(lut);
    OrbitParams p;
    p.azimuth_deg = 0, p.elevation_deg = 90,
    p.projection = Projection::Orthographic;  // eye on +z, x right, y up
    const Camera cam = Camera::orbit(m.bounds(), p, 50, 50);
    RenderOptions ro;
    ro.features.blend = BlendMode::Mip;
    const RenderResult r = m.render(cam, ro);
    ro.features.blend = BlendMode::MinIp;
    const RenderResult rmin = m.render(cam, ro);
    int checked = 0;
    for (int x = 0; x < 50; ++x) {
        const Ray ray = cam.generate(float(x), 25.f);
        if (ray.origin.x < 0.f || ray.origin.x > 25.f) continue;
        const float expected = ray.origin.x / 25.f;  // the trilinear ramp along x, normalised
        EXPECT_NEAR(r.image.pixel(x, 25)[0] / 255.f, expected, 1.5f / 255.f + 1e-3f) << x;
        EXPECT_EQ(r.image.pixel(x, 25)[0], rmin.image.pixel(x, 25)[0]) << x;  // constant along z
        ++checked;
    }
    EXPECT_GT(checked, 30);
}

TEST(Shading, MipEqualsTheBruteForceMaximumAlongEachRay) {
    test::Rng rng{11};
    for (int trial = 0; trial < 5; ++trial) {
        const Volume v = test::random_volume(rng, 20);
        TransferLut lut;
        lut.vis = v.vis_range();
        lut.entries.resize(kDefaultLutSize);
        for (int e = 0; e < kDefaultLutSize; ++e)
            lut.entries[size_t(e)] = {float(e) / 1023.f, 1.f - float(e) / 1023.f, 0.5f,
                                      0.2f + 0.8f * float(e) / 1023.f};
        RayMarcher m(v);
        m.set_transfer_function(lut);
        const Camera cam = test::random_camera(v, rng, 24);
        RenderOptions ro;
        ro.step = 0.3f + rng.uniform();
        ro.keep_float = true;
        ro.features.blend = BlendMode::Mip;
        const RenderResult r = m.render(cam, ro);
        // Brute force: the value of every lattice sample, in double precision positions.
        const float min_sp = float(std::min({v.spacing.x, v.spacing.y, v.spacing.z}));
        const float dt = ro.step * min_sp;
        const Vec3i d = v.dims();
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                const Ray ray = cam.generate(float(x), float(y));
                const kernel::IndexRay ir{ray.origin.x, ray.origin.y, ray.origin.z,
                                          ray.dir.x,    ray.dir.y,    ray.dir.z};
                const float hi[3] = {float(d.x - 1), float(d.y - 1), float(d.z - 1)};
                float t0, t1;
                float expected = 0.f;
                if (kernel::intersect_box(ir, hi, t0, t1)) {
                    int best = -1;
                    for (int k = 0; t0 + (float(k) + 0.5f) * dt < t1; ++k) {
                        const float t = t0 + (float(k) + 0.5f) * dt;
                        const float px = std::clamp(ir.ox + t * ir.dx, 0.f, hi[0]),
                                    py = std::clamp(ir.oy + t * ir.dy, 0.f, hi[1]),
                                    pz = std::clamp(ir.oz + t * ir.dz, 0.f, hi[2]);
                        // Trilinear by hand.
                        const int i = std::min(int(px), d.x - 2), j = std::min(int(py), d.y - 2),
                                  kk = std::min(int(pz), d.z - 2);
                        const float fx = px - i, fy = py - j, fz = pz - kk;
                        float val = 0;
                        for (int c = 0; c < 8; ++c) {
                            const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
                            val += v.value(i + dx, j + dy, kk + dz) * (dx ? fx : 1 - fx) *
                                   (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
                        }
                        best = std::max(best, lut.map()(val));
                    }
                    if (best >= 0) expected = lut.entries[size_t(best)].a;
                }
                // The alpha of the max entry; float trilinear order may move a value across an
                // entry boundary, so allow one entry's worth.
                EXPECT_NEAR(r.rgba_float[(size_t(y) * 24 + x) * 4 + 3], expected,
                            0.8f / 1023.f + 1e-6f)
                    << "trial " << trial << " pixel " << x << "," << y;
            }
    }
}

// Renders through the feature path with nothing clipped (a crop box around everything).
RenderResult render_unclipped(const RayMarcher& m, const Camera& cam, RenderOptions ro) {
    ro.features.crop = true;
    ro.features.crop_box = {{-1, -1, -1}, m.bounds().hi + Vec3f{1, 1, 1}};
    return m.render(cam, ro);
}

TEST(Shading, ClipPlanesRemoveExactlyTheirHalfSpace) {
    const Volume v = ball(31, 12.f);
    RayMarcher m(v);
    TransferLut lut = step_lut(v, 200.f, {0.8f, 0.7f, 0.6f, 0.3f});
    m.set_transfer_function(lut);
    OrbitParams p;
    p.azimuth_deg = 0, p.elevation_deg = 90,
    p.projection = Projection::Orthographic;  // eye on +z, x right, y up
    const Camera cam = Camera::orbit(m.bounds(), p, 60, 60);
    RenderOptions ro;
    ro.background = {0, 0, 1};
    const RenderResult full = render_unclipped(m, cam, ro);
    // A plane parallel to the view direction (normal in the xy plane): each ray lies entirely on
    // one side, so a pixel is either background or the unclipped pixel.
    const ClipPlane plane{normalize(Vec3f{1.f, 0.6f, 0.f}), 14.f};
    ro.features.clip_planes = {plane};
    const RenderResult clipped = m.render(cam, ro);
    int kept = 0, removed = 0;
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 60; ++x) {
            const Ray ray = cam.generate(float(x), float(y));
            const float s = dot(plane.normal, ray.origin) - plane.d;  // constant along the ray
            const uint8_t* a = clipped.image.pixel(x, y);
            const uint8_t* b = full.image.pixel(x, y);
            if (s >= 1e-3f) {
                ++kept;
                EXPECT_TRUE(std::equal(a, a + 4, b)) << x << "," << y;
            } else if (s < -1e-3f) {
                ++removed;
                EXPECT_EQ(a[0], 0);
                EXPECT_EQ(a[2], 255);
            }
        }
    EXPECT_GT(kept, 300);
    EXPECT_GT(removed, 300);
    // The opposite plane keeps the complement; together the two halves hold every sample.
    ro.features.clip_planes = {{-plane.normal, -plane.d}};
    const RenderResult other = m.render(cam, ro);
    ro.count_samples = true;
    ro.features.clip_planes = {plane};
    const uint64_t s1 = m.render(cam, ro).stats.samples;
    ro.features.clip_planes = {{-plane.normal, -plane.d}};
    const uint64_t s2 = m.render(cam, ro).stats.samples;
    ro.features.clip_planes.clear();
    const uint64_t s_all = render_unclipped(m, cam, ro).stats.samples;
    EXPECT_GE(s1 + s2, s_all);            // samples exactly on the plane are kept by both
    EXPECT_LE(s1 + s2, s_all + 60 * 60);  // ... at most one per ray in practice
    (void)other;
}

TEST(Shading, CropBoxKeepsExactlyItsInside) {
    const Volume v = ball(31, 12.f);
    RayMarcher m(v);
    m.set_transfer_function(step_lut(v, 200.f, {0.8f, 0.7f, 0.6f, 0.3f}));
    OrbitParams p;
    p.azimuth_deg = 0, p.elevation_deg = 90,
    p.projection = Projection::Orthographic;  // eye on +z, x right, y up
    const Camera cam = Camera::orbit(m.bounds(), p, 60, 60);
    RenderOptions ro;
    ro.background = {0, 0, 1};
    const RenderResult full = render_unclipped(m, cam, ro);
    ro.features.crop = true;
    ro.features.crop_box = {{5.f, 8.f, -1.f}, {20.f, 26.f, 40.f}};  // all of z
    const RenderResult crop = m.render(cam, ro);
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 60; ++x) {
            const Ray ray = cam.generate(float(x), float(y));
            const bool in = ray.origin.x >= 5.f && ray.origin.x <= 20.f && ray.origin.y >= 8.f &&
                            ray.origin.y <= 26.f;
            const bool out = ray.origin.x < 4.99f || ray.origin.x > 20.01f ||
                             ray.origin.y < 7.99f || ray.origin.y > 26.01f;
            const uint8_t* a = crop.image.pixel(x, y);
            if (in) EXPECT_TRUE(std::equal(a, a + 4, full.image.pixel(x, y))) << x << "," << y;
            if (out) EXPECT_EQ(a[2], 255) << x << "," << y;
        }
    // A z slab outside the ball's visible shell: nothing left but background... except the
    // inner core, so use a slab at the far corner of the volume where everything is < 200.
    ro.features.crop_box = {{0, 0, 0}, {3, 3, 30}};
    const RenderResult empty = m.render(cam, ro);
    for (size_t i = 0; i < empty.image.rgba.size(); i += 4) ASSERT_EQ(empty.image.rgba[i + 2], 255);
}

TEST(Shading, JitterIsDeterministicPerPixel) {
    const Volume v = ball(31, 12.f);
    RayMarcher m(v);
    m.set_transfer_function(step_lut(v, 200.f, {0.8f, 0.7f, 0.6f, 0.3f}));
    const Camera cam = Camera::orbit(m.bounds(), OrbitParams{}, 40, 40);
    RenderOptions ro;
    ro.features.jitter = true;
    ro.features.jitter_seed = 9;
    ro.threads = 1;
    ro.keep_float = true;
    const RenderResult a = m.render(cam, ro);
    ro.threads = 2;
    ro.tile = 7;
    const RenderResult b = m.render(cam, ro);
    EXPECT_EQ(a.rgba_float, b.rgba_float);  // independent of threads and tiles
    ro.features.jitter_seed = 10;
    const RenderResult c = m.render(cam, ro);
    EXPECT_NE(a.rgba_float, c.rgba_float);  // another seed, another pattern
    ro.features.jitter = false;
    ro.features.crop = true;  // the feature path without jitter
    ro.features.crop_box = {{-1, -1, -1}, m.bounds().hi + Vec3f{1, 1, 1}};
    EXPECT_NE(a.rgba_float, m.render(cam, ro).rgba_float);
    // The offsets are in [0, 1) and differ between neighbouring pixels.
    float lo = 1, hi = 0;
    for (uint32_t y = 0; y < 64; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
            const float j = feature::jitter(x, y, 3);
            ASSERT_GE(j, 0.f);
            ASSERT_LT(j, 1.f);
            lo = std::min(lo, j), hi = std::max(hi, j);
        }
    EXPECT_LT(lo, 0.01f);
    EXPECT_GT(hi, 0.99f);
    EXPECT_NE(feature::jitter(1, 2, 3), feature::jitter(2, 1, 3));
}

TEST(Shading, GradientOpacityRemovesHomogeneousRegionsOnly) {
    // A uniform cube inside an empty volume: with gradient opacity only its faces remain, so a
    // ray through its centre accumulates less than without.
    Volume v({24, 24, 24}, VoxelType::UInt8);
    for (int z = 4; z < 20; ++z)
        for (int y = 4; y < 20; ++y)
            for (int x = 4; x < 20; ++x) v.set_value(x, y, z, 200.f);
    v.compute_range();
    RayMarcher m(v);
    m.set_transfer_function(step_lut(v, 150.f, {1, 1, 1, 0.05f}));
    OrbitParams p;
    p.azimuth_deg = 0, p.elevation_deg = 90,
    p.projection = Projection::Orthographic;  // eye on +z, x right, y up
    const Camera cam = Camera::orbit(m.bounds(), p, 32, 32);
    RenderOptions ro;
    ro.keep_float = true;
    const RenderResult plain = render_unclipped(m, cam, ro);
    ro.features.gradient_opacity = {true, 10.f, 20.f};
    const RenderResult mod = m.render(cam, ro);
    const size_t centre = (16 * 32 + 16) * 4 + 3;
    EXPECT_GT(plain.rgba_float[centre], 0.3f);
    EXPECT_GT(mod.rgba_float[centre], 0.f);  // the two faces the ray crosses
    EXPECT_LT(mod.rgba_float[centre], 0.5f * plain.rgba_float[centre]);
    for (size_t i = 3; i < plain.rgba_float.size(); i += 4)
        EXPECT_LE(mod.rgba_float[i], plain.rgba_float[i] + 1e-6f);  // it only multiplies
}

// The factor by its definition, in double and by another route: the segment [x_i, x_{i+1})
// holding m found by a scan from the right, the value as a weighted mean of the two ends.
double gradient_factor_reference(const std::vector<GradientOpacityPoint>& p, double m) {
    if (m < p.front().x) return p.front().a;
    if (m >= p.back().x) return p.back().a;
    size_t i = p.size() - 1;
    while (!(p[i].x <= m)) --i;  // the last point at or left of m (right-continuous at steps)
    const double w = (m - p[i].x) / (double(p[i + 1].x) - p[i].x);
    return (1.0 - w) * p[i].a + w * p[i + 1].a;
}

TEST(Shading, GradientOpacityPointsMatchTheirDefinition) {
    test::Rng rng(18);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<GradientOpacityPoint> pts;
        float x = 100.f * rng.uniform();
        const int n = rng.range(1, 7);
        for (int i = 0; i < n; ++i) {
            // Sometimes a step (two points at one x), never three.
            const bool step = i >= 1 && rng.coin(3) && !(i >= 2 && pts[size_t(i) - 2].x == x);
            if (i > 0 && !step) x += 1.f + 60.f * rng.uniform();
            const int kind = rng.range(0, 3);
            pts.push_back({x, kind == 0 ? 0.f : kind == 1 ? 1.f : rng.uniform()});
        }
        GradientOpacity g;
        g.enabled = true;
        g.points = pts;
        for (int k = 0; k < 400; ++k) {
            const float m = k < 2 * n ? pts[size_t(k / 2)].x  // at every point exactly
                                      : (x + 80.f) * rng.uniform();
            const float got = shading::gradient_opacity(g, m);
            // Float error: m - x and the width (< 64, widths >= 1) each within ulp(64)/2 = 4e-6.
            EXPECT_NEAR(got, gradient_factor_reference(pts, m), 1e-5)
                << "trial " << trial << " m " << m;
            // Exact where the definition is exact: at the points' values and on flat stretches.
            size_t i = 0;
            while (i + 1 < pts.size() && pts[i + 1].x <= m) ++i;
            const bool flat = m < pts.front().x || i + 1 == pts.size() || pts[i].a == pts[i + 1].a;
            const float flat_value = m < pts.front().x ? pts.front().a : pts[i].a;
            if (flat) EXPECT_EQ(got, flat_value) << "trial " << trial << " m " << m;
        }
    }
}

TEST(Shading, GradientOpacityRampIsItsTwoPointFunctionBitForBit) {
    // --gradient-opacity LO,HI is the points (LO, 0), (HI, 1): the same float per magnitude as
    // the ramp formula (m - lo) / (hi - lo), so images made with the ramp did not change.
    test::Rng rng(7);
    for (int trial = 0; trial < 100; ++trial) {
        const float lo = 50.f * rng.uniform(),
                    hi = trial % 10 == 0 ? lo : lo + 80.f * rng.uniform();
        GradientOpacity ramp;
        ramp.enabled = true;
        ramp.lo = lo, ramp.hi = hi;
        GradientOpacity pts = ramp;
        pts.points = {{lo, 0.f}, {hi, 1.f}};
        for (int k = 0; k < 200; ++k) {
            const float m = 150.f * rng.uniform();
            const float formula = m >= hi ? 1.f : m <= lo ? 0.f : (m - lo) / (hi - lo);
            EXPECT_EQ(shading::gradient_opacity(ramp, m), formula) << lo << " " << hi << " " << m;
            EXPECT_EQ(shading::gradient_opacity(pts, m), formula) << lo << " " << hi << " " << m;
        }
    }
}

TEST(Shading, GradientOpacityPointsRenderLikeTheRampTheyEqual) {
    // (0, 0), (10, 0), (20, 1) is the ramp 10,20 with a zero stretch in front: the same image.
    Volume v({24, 24, 24}, VoxelType::UInt8);
    for (int z = 4; z < 20; ++z)
        for (int y = 4; y < 20; ++y)
            for (int x = 4; x < 20; ++x) v.set_value(x, y, z, 120.f + 4.f * float(x));
    v.compute_range();
    RayMarcher m(v);
    m.set_transfer_function(step_lut(v, 100.f, {1, 0.8f, 0.6f, 0.3f}));
    OrbitParams p;
    p.azimuth_deg = 20, p.elevation_deg = 30;
    const Camera cam = Camera::orbit(m.bounds(), p, 32, 32);
    RenderOptions ro;
    ro.keep_float = true;
    ro.features.shading = ShadingModel::Phong;
    ro.features.gradient_opacity.enabled = true;
    ro.features.gradient_opacity.lo = 10.f;
    ro.features.gradient_opacity.hi = 20.f;
    const RenderResult ramp = m.render(cam, ro);
    ro.features.gradient_opacity.points = {{0.f, 0.f}, {10.f, 0.f}, {20.f, 1.f}};
    const RenderResult pts = m.render(cam, ro);
    EXPECT_EQ(ramp.rgba_float, pts.rgba_float);
    EXPECT_EQ(ramp.image.rgba, pts.image.rgba);
    // And another function gives another image (the points are read).
    ro.features.gradient_opacity.points = {{0.f, 1.f}, {10.f, 0.2f}};
    EXPECT_NE(m.render(cam, ro).rgba_float, ramp.rgba_float);
}

TEST(Shading, LightVolumeIsRecomputedOnLightAndTfChangesOnly) {
    const Volume v = ball(21, 7.f);
    RayMarcher m(v);
    m.set_transfer_function(step_lut(v, 300.f, {1, 1, 1, 0.5f}));
    OrbitParams p;
    const Camera cam = Camera::orbit(m.bounds(), p, 16, 16);
    RenderOptions ro;
    ro.features.shading = ShadingModel::Phong;
    ro.features.light.kind = LightKind::Directional;
    ro.features.light.direction = {1, 1, 0};
    ro.features.shadows.enabled = true;
    ro.features.shadows.light_volume = true;
    const RenderResult a = m.render(cam, ro);
    EXPECT_GT(a.stats.light_volume_seconds, 0.0);
    EXPECT_GT(a.stats.light_volume_bytes, 0u);
    EXPECT_GT(a.stats.shadow_samples, 0u);
    const RenderResult b = m.render(cam, ro);  // cached
    EXPECT_EQ(b.stats.light_volume_seconds, 0.0);
    EXPECT_EQ(b.stats.shadow_samples, 0u);
    EXPECT_EQ(a.image.rgba, b.image.rgba);
    ro.features.light.direction = {-1, 1, 0};  // light change
    EXPECT_GT(m.render(cam, ro).stats.shadow_samples, 0u);
    EXPECT_EQ(m.render(cam, ro).stats.shadow_samples, 0u);
    m.set_transfer_function(step_lut(v, 200.f, {1, 1, 1, 0.5f}));  // TF change
    EXPECT_GT(m.render(cam, ro).stats.shadow_samples, 0u);
}

TEST(Shading, InvalidOptionsThrow) {
    const Volume v = ball(9, 3.f);
    RayMarcher m(v);
    m.set_transfer_function(step_lut(v, 300.f));
    const Camera cam = Camera::orbit(m.bounds(), OrbitParams{}, 8, 8);
    auto bad = [&](auto&& set) {
        RenderOptions ro;
        ro.features.shading = ShadingModel::Phong;
        set(ro.features);
        EXPECT_THROW(m.render(cam, ro), Error);
    };
    bad([](FeatureOptions& f) { f.clip_planes = {{{0, 0, 0}, 1.f}}; });
    bad([](FeatureOptions& f) { f.crop = true, f.crop_box = {{2, 0, 0}, {1, 1, 1}}; });
    bad([](FeatureOptions& f) {
        f.light.kind = LightKind::Spot, f.light.position = f.light.target = {1, 1, 1};
    });
    bad([](FeatureOptions& f) {
        f.light.kind = LightKind::Directional, f.light.direction = {0, 0, 0};
    });
    bad([](FeatureOptions& f) { f.pbr.roughness = 0.f, f.shading = ShadingModel::Pbr; });
    bad([](FeatureOptions& f) { f.gradient_opacity = {true, 2.f, 1.f}; });
    auto points = [](std::vector<GradientOpacityPoint> p) {
        return [p](FeatureOptions& f) {
            f.gradient_opacity.enabled = true;
            f.gradient_opacity.points = p;
        };
    };
    bad(points({{5.f, 0.f}, {1.f, 1.f}}));               // unsorted
    bad(points({{1.f, 0.f}, {1.f, 0.5f}, {1.f, 1.f}}));  // three at one x
    bad(points({{0.f, 0.f}, {1.f, 1.5f}}));              // a > 1
    bad(points({{-1.f, 0.f}, {1.f, 1.f}}));              // x < 0
    bad(points({{0.f, 0.f}, {INFINITY, 1.f}}));          // x not finite
    bad([](FeatureOptions& f) { f.shadows.step = 0.f; });
    // A back TF needs a plane, and the same LUT layout.
    TransferLut back = step_lut(v, 100.f);
    m.set_back_transfer_function(back);
    RenderOptions ro;
    ro.features.jitter = true;
    EXPECT_THROW(m.render(cam, ro), Error);
    back.entries.resize(10);
    EXPECT_THROW(union_lut(step_lut(v, 300.f), back), Error);
}

}  // namespace
}  // namespace lacuna
