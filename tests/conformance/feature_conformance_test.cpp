// Conformance of the feature path (docs/shading.md): every shading, lighting, clipping, blend
// and jitter option, with every skipping structure, gives the image of --accel none with the
// same options, byte for byte (and the float accumulations bit for bit), and never takes more
// samples. Random small volumes with blobs, random TFs with single-entry spikes, random cameras
// inside and outside the volume, with and without early ray termination.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>

#include "conformance/conformance_util.h"
#include "core/simd_lanes.h"
#include "lacuna/accel.h"
#include "lacuna/renderer.h"

namespace lacuna {
namespace {

using test::Rng;

struct FeatureCase {
    const char* name;
    std::function<void(FeatureOptions&, const Volume&, Rng&)> set;
    bool two_tfs = false;
};

ClipPlane random_plane(const Volume& v, Rng& rng) {
    const Vec3f e = v.world_extent();
    ClipPlane p;
    p.normal = {rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f};
    if (length(p.normal) < 1e-3f) p.normal = {1, 0, 0};
    const Vec3f at{e.x * rng.uniform(), e.y * rng.uniform(), e.z * rng.uniform()};
    p.d = dot(p.normal, at);
    return p;
}

Light random_light(const Volume& v, Rng& rng, LightKind kind) {
    const Vec3f e = v.world_extent();
    Light l;
    l.kind = kind;
    l.direction = {rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f + 1e-3f};
    l.position = {e.x * (2.f * rng.uniform() - 0.5f), e.y * (2.f * rng.uniform() - 0.5f),
                  e.z * (2.f * rng.uniform() - 0.5f)};
    l.target = e * 0.5f;
    if (length(l.target - l.position) < 1e-2f) l.position.x += 1.f;
    l.cone_deg = 20.f + 50.f * rng.uniform();
    return l;
}

// 2..6 points over [0, 0.4 * (value width + 1)] per mm, sorted, one pair sharing an x (a step)
// at random, factors 0, 1 or uniform: zero stretches, steps, interior maxima.
GradientOpacity random_gradient_points(const Volume& v, Rng& r) {
    GradientOpacity g;
    g.enabled = true;
    const float top = (v.data_range().width() + 1.f) * 0.4f;
    const int n = r.range(2, 6);
    float x = 0.f;
    for (int i = 0; i < n; ++i) {
        if (i == 0 || !r.coin() || (i >= 2 && g.points[size_t(i) - 2].x == x))
            x += top / float(n) * (0.05f + r.uniform());
        const int kind = r.range(0, 2);
        g.points.push_back({x, kind == 0 ? 0.f : kind == 1 ? 1.f : r.uniform()});
    }
    return g;
}

std::vector<FeatureCase> feature_cases() {
    return {
        {"phong", [](FeatureOptions& f, const Volume&, Rng&) { f.shading = ShadingModel::Phong; }},
        {"phong gradient volume",
         [](FeatureOptions& f, const Volume&, Rng&) {
             f.shading = ShadingModel::Phong;
             f.gradient = GradientSource::Precomputed;
         }},
        {"pbr head", [](FeatureOptions& f, const Volume&, Rng&) { f.shading = ShadingModel::Pbr; }},
        {"phong spot + clip",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Phong;
             f.light = random_light(v, r, LightKind::Spot);
             f.clip_planes.push_back(random_plane(v, r));
         }},
        {"pbr gradient volume directional",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Pbr;
             f.gradient = GradientSource::Precomputed;
             f.light = random_light(v, r, LightKind::Directional);
         }},
        {"pbr directional",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Pbr;
             f.light = random_light(v, r, LightKind::Directional);
         }},
        {"gradient opacity",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.gradient_opacity = {true, 0.f, (v.data_range().width() + 1.f) * 0.3f * r.uniform()};
         }},
        {"gradient opacity + pbr",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Pbr;
             const float a = (v.data_range().width() + 1.f) * 0.2f * r.uniform();
             f.gradient_opacity = {true, a, 2.f * a};
         }},
        // Piecewise-linear factors over |grad|: random points (with a step and zero stretches,
        // which must stay exactly zero), alone and with Phong as a shaded Slicer preset does.
        {"gradient opacity points",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.gradient_opacity = random_gradient_points(v, r);
         }},
        {"gradient opacity points + phong",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Phong;
             f.phong = {0.1f, 0.9f, 0.2f, 10.f};  // Slicer's CT-Bone terms
             f.gradient_opacity = random_gradient_points(v, r);
         }},
        {"shadows directional",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Phong;
             f.light = random_light(v, r, LightKind::Directional);
             f.shadows.enabled = true;
             f.shadows.step = 0.3f + r.uniform();
         }},
        {"shadows spot",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Pbr;
             f.light = random_light(v, r, LightKind::Spot);
             f.shadows.enabled = true;
         }},
        {"shadows head unshaded",
         [](FeatureOptions& f, const Volume&, Rng&) { f.shadows.enabled = true; }},
        {"light volume",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.shading = ShadingModel::Phong;
             f.light = random_light(v, r, r.coin() ? LightKind::Spot : LightKind::Directional);
             f.shadows.enabled = true;
             f.shadows.light_volume = true;
             f.shadows.light_volume_stride = r.range(1, 3);
         }},
        {"clip planes",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             const int n = r.range(1, 3);
             for (int i = 0; i < n; ++i) f.clip_planes.push_back(random_plane(v, r));
         }},
        {"crop box",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             const Vec3f e = v.world_extent();
             f.crop = true;
             for (int a = 0; a < 3; ++a) {
                 const float p = e[a] * r.uniform(), q = e[a] * r.uniform();
                 f.crop_box.lo[a] = std::min(p, q);
                 f.crop_box.hi[a] = std::max(p, q) + 0.5f;
             }
         }},
        {"two TFs",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.clip_planes.push_back(random_plane(v, r));
         },
         true},
        {"two TFs + clip + phong shadows",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.clip_planes.push_back(random_plane(v, r));
             f.clip_planes.push_back(random_plane(v, r));
             f.shading = ShadingModel::Phong;
             f.light = random_light(v, r, LightKind::Directional);
             f.shadows.enabled = true;
         },
         true},
        {"mip", [](FeatureOptions& f, const Volume&, Rng&) { f.blend = BlendMode::Mip; }},
        {"minip", [](FeatureOptions& f, const Volume&, Rng&) { f.blend = BlendMode::MinIp; }},
        {"average", [](FeatureOptions& f, const Volume&, Rng&) { f.blend = BlendMode::Average; }},
        {"mip + clip + two TFs",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.blend = BlendMode::Mip;
             f.clip_planes.push_back(random_plane(v, r));
             f.clip_planes.push_back(random_plane(v, r));
         },
         true},
        {"jitter",
         [](FeatureOptions& f, const Volume&, Rng& r) {
             f.jitter = true;
             f.jitter_seed = uint32_t(r.next());
         }},
        {"jitter + pbr + crop + average",
         [](FeatureOptions& f, const Volume& v, Rng& r) {
             f.jitter = true;
             f.shading = ShadingModel::Pbr;
             f.crop = true;
             f.crop_box = {{0, 0, 0}, v.world_extent() * (0.3f + 0.7f * r.uniform())};
             if (r.coin()) f.blend = BlendMode::Average;
         }},
    };
}

void expect_exact(const std::string& name, const Volume& v, const TransferLut& front,
                  const TransferLut* back, const Camera& cam, const RenderOptions& ro,
                  const AccelOptions& ao) {
    RayMarcher m(v);
    m.set_transfer_function(front);
    if (back) m.set_back_transfer_function(*back);
    const TransferLut skip_lut = back ? union_lut(front, *back) : front;
    RenderOptions o = ro;
    o.keep_float = true;
    o.count_samples = true;
    const RenderResult ref = m.render(cam, o);
    for (AccelKind k : all_accel_kinds()) {
        if (k == AccelKind::None) continue;
        auto accel = make_accel(k, v, ao);
        accel->set_transfer_function(skip_lut);
        accel->refine();  // the grid's visible-cell mask (a no-op for the others)
        // A fresh marcher per structure: its caches (light volume) are rebuilt with the
        // structure, so an accelerated light volume is compared too.
        RayMarcher ma(v);
        ma.set_transfer_function(front);
        if (back) ma.set_back_transfer_function(*back);
        ma.set_accel(accel.get());
        const RenderResult r = ma.render(cam, o);
        ASSERT_EQ(r.image.rgba, ref.image.rgba) << name << " accel " << to_string(k);
        ASSERT_EQ(0, std::memcmp(r.rgba_float.data(), ref.rgba_float.data(),
                                 ref.rgba_float.size() * sizeof(float)))
            << name << " accel " << to_string(k) << ": float accumulations differ";
        ASSERT_LE(r.stats.samples, ref.stats.samples) << name << " accel " << to_string(k);
        ASSERT_LE(r.stats.shadow_samples, ref.stats.shadow_samples)
            << name << " accel " << to_string(k);
    }
}

TEST(FeatureConformance, EveryOptionIsExactForEveryStructure) {
    Rng rng{2024};
    const auto cases = feature_cases();
    for (const FeatureCase& fc : cases) {
        for (int trial = 0; trial < 4; ++trial) {
            const Volume v = test::random_volume(rng, 22);
            const ValueToLut map(v.vis_range(), kDefaultLutSize);
            TransferLut front = trial % 2 == 0
                                    ? test::spike_lut(v.vis_range(), map(v.value(0, 0, 0)))
                                    : test::random_lut(v.vis_range(), rng);
            if (trial % 2 == 0) front.entries[size_t(map(v.data_range().max * 0.5f))].a = 0.5f;
            const TransferLut back_lut = test::random_lut(v.vis_range(), rng);
            AccelOptions ao;
            ao.leaf_cells = 1 << rng.range(1, 3);
            ao.bitfield_bits = 8 << rng.range(0, 4);
            ao.bidirectional = rng.coin();
            ao.distance_block = rng.range(1, 4);
            RenderOptions ro;
            ro.step = 0.2f + 1.2f * rng.uniform();
            ro.ert = rng.coin() ? 0.95f : kNoEarlyTermination;
            fc.set(ro.features, v, rng);
            const Camera cam = test::random_camera(v, rng, 20);
            expect_exact(std::string(fc.name) + " trial " + std::to_string(trial), v, front,
                         fc.two_tfs ? &back_lut : nullptr, cam, ro, ao);
        }
    }
}

// Every kernel path this CPU runs (core/simd_lanes.h: the scalar path is feature::composite_ray,
// one sample at a time; SSE4.1, AVX2 and AVX-512 run the batched ShadedStream with the lanes of
// core/simd_shading.h, and on a refined grid AVX2/AVX-512 the leaping shaded lanes) gives the
// bytes, float accumulations and per-pixel sample counts of the scalar --accel none render, for
// every feature option and structure, with and without early termination. Half the trials use a
// dense LUT (every entry different, so a value one ulp off lands in another entry and shows).
TEST(FeatureConformance, EveryShadingPathIsExactForEveryStructure) {
    const test::KernelPaths kp;
    const std::vector<simd::Isa>& paths = kp.paths;
    ASSERT_GE(paths.size(), 2u) << "at least the scalar path and one SIMD path";
    Rng rng{2031};
    int compared = 0;
    for (const FeatureCase& fc : feature_cases()) {
        for (int trial = 0; trial < 3; ++trial) {
            const Volume v = test::random_volume(rng, 26);
            TransferLut front = test::random_lut(v.vis_range(), rng);
            if (trial == 1) test::make_dense(front, size_t(1) << 16, rng);
            const TransferLut back_lut = test::random_lut(v.vis_range(), rng);
            const TransferLut* back = fc.two_tfs && trial != 1 ? &back_lut : nullptr;
            RenderOptions o;
            o.keep_float = true;
            o.count_samples = true;
            o.step = 0.2f + 1.2f * rng.uniform();
            o.ert = trial == 2 ? kNoEarlyTermination : 0.8f + 0.19f * rng.uniform();
            o.tile = rng.range(3, 17);
            fc.set(o.features, v, rng);
            if (fc.two_tfs && !back) o.features.clip_planes.push_back(random_plane(v, rng));
            const Camera cam = test::random_camera(v, rng, 21);
            RayMarcher m(v);
            m.set_transfer_function(front);
            if (back) m.set_back_transfer_function(*back);
            simd::set_isa(simd::Isa::Scalar);
            const RenderResult ref = m.render(cam, o);
            const TransferLut skip_lut = back ? union_lut(front, *back) : front;
            for (AccelKind k : all_accel_kinds()) {
                auto accel = make_accel(k, v);
                accel->set_transfer_function(skip_lut);
                RayMarcher ma(v);
                ma.set_transfer_function(front);
                if (back) ma.set_back_transfer_function(*back);
                ma.set_accel(accel.get());
                // Each structure as the TF change leaves it, then refined (the grid's
                // visible-cell mask skips whole lattice batches on the SIMD paths).
                for (int refined = 0; refined < 2; ++refined)
                    for (simd::Isa isa : paths) {
                        if (refined && isa == paths.front()) accel->refine();
                        simd::set_isa(isa);
                        const RenderResult r = ma.render(cam, o);
                        const std::string what = std::string(fc.name) + " trial " +
                                                 std::to_string(trial) + " " + to_string(v.type()) +
                                                 " accel " + to_string(k) + " path " +
                                                 simd::to_string(isa) + (refined ? " refined" : "");
                        ASSERT_EQ(r.image.rgba, ref.image.rgba) << what;
                        ASSERT_EQ(0, std::memcmp(r.rgba_float.data(), ref.rgba_float.data(),
                                                 ref.rgba_float.size() * sizeof(float)))
                            << what << ": float accumulations differ";
                        if (k == AccelKind::None)
                            ASSERT_EQ(r.sample_counts, ref.sample_counts) << what;
                        ASSERT_LE(r.stats.samples, ref.stats.samples) << what;
                        ++compared;
                    }
            }
        }
    }
    EXPECT_GT(compared, 500);
}

// The refined grid's shaded lanes (simd::march_shaded_lanes8 with leaping, taken for Phong with a
// head or directional light) on volumes whose background is transparent, so the leap map has
// long empty stretches: every path equals the scalar --accel none render.
TEST(FeatureConformance, ShadedLeapingLanesAreExactOnSparseVolumes) {
    const test::KernelPaths kp;
    Rng rng{4242};
    int compared = 0;
    for (int trial = 0; trial < 12; ++trial) {
        const Volume v = test::random_volume(rng, 48);
        TransferLut lut = test::random_lut(v.vis_range(), rng);
        const ValueToLut map = lut.map();
        // The background (the volume's minimum, most voxels) and a band above it transparent.
        const int band = map(v.data_range().min) + rng.range(0, 40);
        for (int e = 0; e <= std::min(band, int(lut.entries.size()) - 1); ++e)
            lut.entries[size_t(e)].a = 0.f;
        if (trial % 3 == 1) test::make_dense(lut, size_t(1) << 14, rng), lut.entries[0].a = 0.f;
        RenderOptions o;
        o.keep_float = true;
        o.step = 0.2f + 1.2f * rng.uniform();
        o.ert = trial % 2 ? kNoEarlyTermination : 0.8f + 0.19f * rng.uniform();
        o.features.shading = ShadingModel::Phong;
        o.features.light.kind = trial % 4 < 2 ? LightKind::Head : LightKind::Directional;
        o.features.light.direction = {rng.uniform() - 0.5f, rng.uniform() - 0.5f, 0.5f};
        o.features.jitter = trial % 3 == 2;
        const Camera cam = test::random_camera(v, rng, 23);
        RayMarcher m(v);
        m.set_transfer_function(lut);
        simd::set_isa(simd::Isa::Scalar);
        const RenderResult ref = m.render(cam, o);
        auto accel = make_accel(AccelKind::Grid, v);
        accel->set_transfer_function(lut);
        accel->refine();
        m.set_accel(accel.get());
        for (simd::Isa isa : kp.paths) {
            simd::set_isa(isa);
            const RenderResult r = m.render(cam, o);
            const std::string what = "trial " + std::to_string(trial) + " " + to_string(v.type()) +
                                     " path " + simd::to_string(isa);
            ASSERT_EQ(r.image.rgba, ref.image.rgba) << what;
            ASSERT_EQ(0, std::memcmp(r.rgba_float.data(), ref.rgba_float.data(),
                                     ref.rgba_float.size() * sizeof(float)))
                << what << ": float accumulations differ";
            ASSERT_LE(r.stats.samples, ref.stats.samples) << what;
            ++compared;
        }
    }
    EXPECT_GT(compared, 20);
}

TEST(FeatureConformance, AcceleratedShadowRaysEqualUnacceleratedOnes) {
    Rng rng{77};
    for (int trial = 0; trial < 6; ++trial) {
        const Volume v = test::random_volume(rng, 24);
        const TransferLut lut = test::random_lut(v.vis_range(), rng);
        RenderOptions ro;
        ro.keep_float = true;
        ro.ert = trial % 2 ? 0.9f : kNoEarlyTermination;
        ro.features.shading = ShadingModel::Phong;
        ro.features.light =
            random_light(v, rng, trial % 3 == 0 ? LightKind::Spot : LightKind::Directional);
        ro.features.shadows.enabled = true;
        ro.features.shadows.light_volume = trial >= 4;
        const Camera cam = test::random_camera(v, rng, 24);
        for (AccelKind k :
             {AccelKind::Bitfield, AccelKind::MinMax, AccelKind::Distance, AccelKind::KdTree}) {
            auto accel = make_accel(k, v);
            accel->set_transfer_function(lut);
            RayMarcher a(v), b(v);
            a.set_transfer_function(lut);
            b.set_transfer_function(lut);
            a.set_accel(accel.get());
            b.set_accel(accel.get());
            RenderOptions slow = ro;
            slow.features.shadows.accelerate = false;
            const RenderResult fast = a.render(cam, ro), ref = b.render(cam, slow);
            ASSERT_EQ(fast.image.rgba, ref.image.rgba) << "trial " << trial << " " << to_string(k);
            ASSERT_EQ(0, std::memcmp(fast.rgba_float.data(), ref.rgba_float.data(),
                                     ref.rgba_float.size() * sizeof(float)));
            ASSERT_LE(fast.stats.shadow_samples, ref.stats.shadow_samples);
        }
    }
}

TEST(FeatureConformance, MipSkipsSamplesWithValueStructures) {
    // Not a timing test: MIP through the min-max and bitfield octrees must drop samples on a
    // sparse volume (their region maximum query), and stay exact.
    // A hollow box: 200 on the faces, 0 inside, one brighter corner voxel (so 200 is not the
    // end of the table and rays do not stop there). Once a ray has entered through a face, no
    // interior node can raise its maximum.
    Volume v({48, 48, 48}, VoxelType::UInt8);
    for (int z = 0; z < 48; ++z)
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x)
                if (x == 0 || y == 0 || z == 0 || x == 47 || y == 47 || z == 47)
                    v.set_value(x, y, z, 200.f);
    v.set_value(0, 0, 0, 255.f);
    v.compute_range();
    TransferLut lut;
    lut.vis = v.vis_range();
    lut.entries.assign(kDefaultLutSize, Rgba{1, 1, 1, 1});
    RayMarcher m(v);
    m.set_transfer_function(lut);
    OrbitParams p;
    p.elevation_deg = 90.f, p.projection = Projection::Orthographic;  // through two faces
    const Camera cam = Camera::orbit(m.bounds(), p, 32, 32);
    RenderOptions ro;
    ro.features.blend = BlendMode::Mip;
    const RenderResult ref = m.render(cam, ro);
    AccelOptions ao;
    ao.leaf_cells = 2;  // thin leaves along the faces, so the interior is most of the ray
    for (AccelKind k : {AccelKind::MinMax, AccelKind::Bitfield}) {
        auto a = make_accel(k, v, ao);
        a->set_transfer_function(lut);
        m.set_accel(a.get());
        const RenderResult r = m.render(cam, ro);
        m.set_accel(nullptr);
        EXPECT_EQ(r.image.rgba, ref.image.rgba) << to_string(k);
        EXPECT_LT(r.stats.samples * 2, ref.stats.samples) << to_string(k);
    }
}

}  // namespace
}  // namespace lacuna
