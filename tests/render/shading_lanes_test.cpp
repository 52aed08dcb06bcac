// The SIMD lanes of the shaded path (core/simd_shading.h) against the scalar functions they
// stand for, bit for bit and lane by lane: trilinear values, LUT entries and opacity masks of
// lattice samples, on-the-fly and gradient-volume gradients (kernel::trilinear,
// feature::gradient), and Phong / PBR shading of gradients (shading::normal_from_gradient,
// phong_h, pbr_h), including zero gradients, normals facing away from the viewer, grazing lights
// and positions on and past the box faces. The image-level check of every path is
// FeatureConformance.EveryShadingPathIsExactForEveryStructure.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "common/rng.h"
#include "conformance/conformance_util.h"
#include "core/simd_shading.h"
#include "render/feature_kernel.h"
#include "render/shading.h"

namespace lacuna {
namespace {

using test::Rng;

bool same_bits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

Vec3f random_unit(Rng& rng) {
    for (;;) {
        const Vec3f v{2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f,
                      2.f * rng.uniform() - 1.f};
        if (length(v) > 0.1f) return normalize(v);
    }
}

// A random position in the box, sometimes on a face, on a cell boundary or slightly outside.
float coordinate(Rng& rng, float hi) {
    switch (rng.range(0, 5)) {
        case 0:
            return 0.f;
        case 1:
            return hi;
        case 2:
            return float(rng.range(0, int(hi)));
        case 3:
            return -0.5f + (hi + 1.f) * rng.uniform();
        default:
            return hi * rng.uniform();
    }
}

template <class T>
void check_samples_and_gradients(const Volume& v, const T* data, Rng& rng, simd::Isa isa) {
    const Vec3i d = v.dims();
    const kernel::Grid<T, int64_t> g = kernel::make_grid<int64_t>(data, d);
    FeatureOptions f;
    f.shading = ShadingModel::Phong;
    feature::Context c;
    c.f = &f;
    c.sp = {float(v.spacing.x), float(v.spacing.y), float(v.spacing.z)};
    c.inv_sp = {float(1.0 / v.spacing.x), float(1.0 / v.spacing.y), float(1.0 / v.spacing.z)};
    const TransferLut lut = test::random_lut(v.vis_range(), rng);
    c.map = lut.map();
    c.raw[0] = c.raw[1] = lut.entries.data();
    const int dims[3] = {d.x, d.y, d.z};
    const simd::ShadeGrid sg = feature::shade_grid(c, dims);
    // Precomputed-gradient stand-in: any float grid of the same geometry.
    std::vector<float> gvol[3];
    for (auto& a : gvol) {
        a.resize(v.voxel_count());
        for (float& x : a) x = 100.f * rng.uniform() - 50.f;
    }
    const float* grad[3] = {gvol[0].data(), gvol[1].data(), gvol[2].data()};
    for (int trial = 0; trial < 200; ++trial) {
        // Lattice samples of a random ray; positions anywhere in (or just outside) the box.
        const simd::ShadeRay r{
            {coordinate(rng, g.hi_x), coordinate(rng, g.hi_y), coordinate(rng, g.hi_z)},
            {2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f},
            -2.f + 4.f * rng.uniform(),
            0.05f + rng.uniform()};
        alignas(32) int32_t k[8];
        for (int l = 0; l < 8; ++l) k[l] = rng.range(0, 40);
        alignas(32) float x[8], y[8], z[8], val[8], gx[8], gy[8], gz[8], hx[8], hy[8], hz[8];
        alignas(32) int32_t e[8];
        unsigned mask = 0;
#if LACUNA_SIMD_X86
        if (isa == simd::Isa::Sse41) {
            mask = unsigned(simd::samples4(sg, r, data, k, x, y, z, val, e)) |
                   unsigned(simd::samples4(sg, r, data, k + 4, x + 4, y + 4, z + 4, val + 4, e + 4))
                       << 4;
            simd::gradients4(sg, data, x, y, z, gx, gy, gz);
            simd::gradients4(sg, data, x + 4, y + 4, z + 4, gx + 4, gy + 4, gz + 4);
            simd::volume_gradients4(sg, grad, x, y, z, hx, hy, hz);
            simd::volume_gradients4(sg, grad, x + 4, y + 4, z + 4, hx + 4, hy + 4, hz + 4);
        } else {
            mask = unsigned(simd::samples8(sg, r, data, k, x, y, z, val, e));
            simd::gradients8(sg, data, x, y, z, gx, gy, gz);
            simd::volume_gradients8(sg, grad, x, y, z, hx, hy, hz);
        }
#endif
        for (int l = 0; l < 8; ++l) {
            const float t = r.t_base + (float(k[l]) + 0.5f) * r.dt;
            const float px = r.o[0] + t * r.d[0], py = r.o[1] + t * r.d[1],
                        pz = r.o[2] + t * r.d[2];
            ASSERT_TRUE(same_bits(px, x[l]) && same_bits(py, y[l]) && same_bits(pz, z[l]))
                << "lane " << l;
            const float ref = kernel::trilinear(g, px, py, pz);
            ASSERT_TRUE(same_bits(ref, val[l]))
                << ref << " vs " << val[l] << " at " << px << "," << py << "," << pz;
            ASSERT_EQ(c.map(ref), e[l]);
            ASSERT_EQ(lut.entries[size_t(e[l])].a > 0.f, bool(mask >> l & 1u));
            c.grad[0] = nullptr;
            const Vec3f gr = feature::gradient(c, g, px, py, pz);
            ASSERT_TRUE(same_bits(gr.x, gx[l]) && same_bits(gr.y, gy[l]) && same_bits(gr.z, gz[l]))
                << "on-the-fly gradient, lane " << l << " at " << px << "," << py << "," << pz;
            for (int a = 0; a < 3; ++a) c.grad[a] = grad[a];
            const Vec3f gp = feature::gradient(c, g, px, py, pz);
            ASSERT_TRUE(same_bits(gp.x, hx[l]) && same_bits(gp.y, hy[l]) && same_bits(gp.z, hz[l]))
                << "gradient volume, lane " << l;
        }
    }
}

std::vector<simd::Isa> lane_paths() {
    std::vector<simd::Isa> p;
    for (simd::Isa i : {simd::Isa::Sse41, simd::Isa::Avx2})
        if (simd::isa_supported(i)) p.push_back(i);
    return p;
}

TEST(ShadingLanes, SamplesAndGradientsEqualTheScalarOnes) {
    Rng rng{4242};
    for (simd::Isa isa : lane_paths()) {
        for (int vol = 0; vol < 12; ++vol) {
            Volume v = test::random_volume(rng, 14);
            v.spacing = {0.5 + rng.uniform(), 0.5 + rng.uniform(), 0.5 + 2.0 * rng.uniform()};
            visit_voxels(v,
                         [&](const auto* data) { check_samples_and_gradients(v, data, rng, isa); });
            if (HasFailure()) return;
        }
    }
}

TEST(ShadingLanes, PhongAndPbrEqualTheScalarOnes) {
    if (!simd::isa_supported(simd::Isa::Avx2)) GTEST_SKIP() << "no AVX2";
    Rng rng{99};
    for (int trial = 0; trial < 2000; ++trial) {
        const Vec3f view = random_unit(rng);
        // Lights toward the eye, grazing, from behind, and exactly opposite (no half vector).
        Vec3f l = random_unit(rng);
        if (trial % 7 == 0) l = view;
        if (trial % 11 == 0) l = -view;
        const float li = trial % 5 == 0 ? 0.f : 2.f * rng.uniform();
        Vec3f h{0, 0, 1};
        const bool h_ok = shading::half_vector(l, view, h);
        const simd::ShadeLight L{
            {l.x, l.y, l.z}, {view.x, view.y, view.z}, {h.x, h.y, h.z}, h_ok, li};
        const PhongParams pp{rng.uniform(), rng.uniform(), rng.uniform(),
                             trial % 13 == 0 ? 0.f : 64.f * rng.uniform()};
        const PbrParams pb{0.01f + rng.uniform(), rng.uniform(), rng.uniform()};
        alignas(32) float gx[8], gy[8], gz[8], r[8], g[8], b[8], r2[8], g2[8], b2[8];
        Rgba in[8];
        for (int j = 0; j < 8; ++j) {
            const float s = rng.coin() ? 1e-3f : 300.f * rng.uniform();
            const Vec3f gr = j == 3 ? Vec3f{0, 0, 0} : random_unit(rng) * s;  // one zero gradient
            gx[j] = gr.x, gy[j] = gr.y, gz[j] = gr.z;
            in[j] = {rng.uniform(), rng.uniform(), rng.uniform(), 1.f};
            r[j] = r2[j] = in[j].r, g[j] = g2[j] = in[j].g, b[j] = b2[j] = in[j].b;
        }
        const int n = 1 + trial % 8;
        simd::phong8({pp.ambient, pp.diffuse, pp.specular, pp.power}, L, gx, gy, gz, r, g, b, n);
        if (h_ok) simd::pbr8({pb.roughness, pb.metallic, pb.ambient}, L, gx, gy, gz, r2, g2, b2);
        for (int j = 0; j < n; ++j) {
            Vec3f rgb{in[j].r, in[j].g, in[j].b}, rgb2 = rgb, nrm;
            if (shading::normal_from_gradient({gx[j], gy[j], gz[j]}, view, nrm)) {
                rgb = shading::phong_h(pp, rgb, nrm, l, h, h_ok, li);
                rgb2 = shading::pbr_h(pb, rgb2, nrm, l, view, h, li);
                // phong_h and pbr_h are what phong() and pbr() compute.
                const Vec3f p =
                    shading::phong(pp, Vec3f{in[j].r, in[j].g, in[j].b}, nrm, l, view, li);
                ASSERT_TRUE(same_bits(p.x, rgb.x) && same_bits(p.y, rgb.y) &&
                            same_bits(p.z, rgb.z));
            }
            ASSERT_TRUE(same_bits(rgb.x, r[j]) && same_bits(rgb.y, g[j]) && same_bits(rgb.z, b[j]))
                << "phong trial " << trial << " lane " << j << ": " << rgb.x << " vs " << r[j];
            if (h_ok)
                ASSERT_TRUE(same_bits(rgb2.x, r2[j]) && same_bits(rgb2.y, g2[j]) &&
                            same_bits(rgb2.z, b2[j]))
                    << "pbr trial " << trial << " lane " << j << ": " << rgb2.x << " vs " << r2[j];
        }
    }
}

}  // namespace
}  // namespace lacuna
