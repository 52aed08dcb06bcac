// The slice renderer: every box source gives the bytes of the one-box 'Basic' render (kd-tree
// subvolumes and random BSP partitions with every empty leaf dropped, on random and adversarial
// volumes, random orthographic and perspective cameras, eyes inside the volume); the same bytes
// for any thread count and tile size; Beer-Lambert through a homogeneous slab; close to the ray
// marcher.
#include "slice/slice_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>

#include "common/rng.h"
#include "lacuna/error.h"
#include "lacuna/renderer.h"
#include "lacuna/synthetic.h"
#include "slice/box_sources.h"
#include "slice/random_bsp_source.h"

namespace lacuna {
namespace {

using test::RandomBspSource;
using test::Rng;

TransferFunction band_tf(double a, double b, float opacity) {
    TransferFunction tf;
    tf.name = "band";
    tf.color = {{0.0, 1, 0.2f, 0.1f}, {0.5, 0.2f, 1, 0.3f}, {1.0, 0.9f, 0.9f, 1}};
    tf.opacity = {{0.0, 0}, {a, 0}, {a, opacity * 0.5f}, {b, opacity}};
    if (b < 1.0) tf.opacity.insert(tf.opacity.end(), {{b, 0}, {1.0, 0}});
    return tf;
}

Camera random_camera(const SliceRenderer& r, Rng& rng, int size, bool inside = false,
                     float zoom = 0.f) {
    OrbitParams p;
    p.azimuth_deg = 360.f * rng.uniform();
    p.elevation_deg = -80.f + 160.f * rng.uniform();
    p.zoom = zoom > 0.f ? zoom : 0.7f + 2.f * rng.uniform();
    p.projection = rng.coin() ? Projection::Orthographic : Projection::Perspective;
    if (inside) {
        p.projection = Projection::Perspective;
        p.distance = 0.2f * length(r.bounds().extent());
        p.fov_y_deg = 70.f;
    }
    return Camera::orbit(r.bounds(), p, size, size);
}

void expect_same(const SliceResult& a, const SliceResult& b, const std::string& what) {
    ASSERT_EQ(a.image.rgba, b.image.rgba) << what;
    if (!a.rgba_float.empty() && !b.rgba_float.empty())
        ASSERT_EQ(0, std::memcmp(a.rgba_float.data(), b.rgba_float.data(),
                                 a.rgba_float.size() * sizeof(float)))
            << what << ": float accumulations differ";
}

struct VolumeCase {
    std::string name;
    Volume volume;
    TransferLut lut;
};

std::vector<VolumeCase> cases() {
    std::vector<VolumeCase> out;
    auto add = [&](const std::string& name, SyntheticKind k, Vec3i dims, VoxelType t,
                   const TransferFunction& tf) {
        SyntheticOptions o;
        o.dims = dims;
        o.type = t;
        o.seed = 7;
        Volume v = generate(k, o);
        TransferLut lut = discretise(tf, v.vis_range());
        out.push_back({name, std::move(v), std::move(lut)});
    };
    add("tree", SyntheticKind::Tree, {23, 19, 26}, VoxelType::UInt8, band_tf(0.3, 0.6, 0.5f));
    add("blobs-int16", SyntheticKind::NoiseBlobs, {21, 24, 17}, VoxelType::Int16,
        band_tf(0.2, 0.9, 0.3f));
    add("sheets", SyntheticKind::ThinSheets, {19, 17, 21}, VoxelType::UInt8,
        band_tf(0.9, 1.0, 0.8f));
    add("checker-float", SyntheticKind::Checkerboard, {12, 13, 11}, VoxelType::Float32,
        band_tf(0.7, 1.0, 0.4f));
    add("bins", SyntheticKind::BinBoundaries, {18, 16, 20}, VoxelType::UInt16,
        band_tf(0.25, 0.5, 0.9f));
    add("shells", SyntheticKind::SphereShells, {25, 25, 25}, VoxelType::UInt8,
        band_tf(0.6, 0.8, 0.7f));
    return out;
}

TEST(SliceRenderer, EveryBoxSourceGivesTheBasicBytes) {
    Rng rng{2024};
    for (const VolumeCase& c : cases()) {
        SliceRenderer r(c.volume);
        r.set_transfer_function(c.lut);
        AccelOptions ao;
        auto kd = make_box_source("kdtree", c.volume, ao);
        kd->set_transfer_function(c.lut);
        auto boxes = make_box_source("boxes", c.volume, ao);
        boxes->set_transfer_function(c.lut);
        RandomBspSource bsp(c.volume, rng.next(), 7);
        bsp.set_transfer_function(c.lut);
        for (int view = 0; view < 10; ++view) {
            // View 5: eye inside the volume; view 7: voxels smaller than a pixel.
            const Camera cam =
                random_camera(r, rng, view == 7 ? 23 : 40, view == 5, view == 7 ? 0.3f : 0.f);
            SliceOptions o;
            o.keep_float = true;
            o.ert = view % 2 ? 0.95f : kNoEarlyTermination;
            o.step = view % 3 == 0 ? 0.5f : 0.37f + rng.uniform();
            r.set_box_source(nullptr);
            const SliceResult basic = r.render(cam, o);
            ASSERT_GT(basic.stats.samples, 0u) << c.name;
            const std::string what =
                c.name + " view " + std::to_string(view) + " " + to_string(cam);
            r.set_box_source(kd.get());
            const SliceResult a = r.render(cam, o);
            expect_same(a, basic, what + " kdtree");
            r.set_box_source(&bsp);
            const SliceResult b = r.render(cam, o);
            expect_same(b, basic, what + " random bsp");
            r.set_box_source(boxes.get());
            const SliceResult gb = r.render(cam, o);
            expect_same(gb, basic, what + " growing boxes");
            EXPECT_LE(a.stats.samples, basic.stats.samples);
            if (HasFatalFailure()) return;
        }
    }
}

TEST(SliceRenderer, SameBytesForAnyThreadCountAndTile) {
    SyntheticOptions so;
    so.dims = {30, 27, 33};
    so.seed = 3;
    const Volume v = generate(SyntheticKind::Tree, so);
    const TransferLut lut = discretise(band_tf(0.3, 0.6, 0.6f), v.vis_range());
    SliceRenderer r(v);
    r.set_transfer_function(lut);
    auto kd = make_box_source("kdtree", v);
    kd->set_transfer_function(lut);
    r.set_box_source(kd.get());
    Rng rng{5};
    const Camera cam = random_camera(r, rng, 61);
    SliceOptions o;
    o.keep_float = true;
    o.threads = 1;
    o.tile = 32;
    const SliceResult ref = r.render(cam, o);
    for (int threads : {2, 3, 4})
        for (int tile : {7, 16, 64}) {
            o.threads = threads;
            o.tile = tile;
            expect_same(r.render(cam, o), ref,
                        "threads " + std::to_string(threads) + " tile " + std::to_string(tile));
        }
}

// Orthographic, straight down z through a homogeneous slab: transmittance exp(-sigma L).
TEST(SliceRenderer, HomogeneousMediumTransmittanceIsBeerLambert) {
    Volume v({17, 17, 65}, VoxelType::UInt8);
    for (int k = 0; k < 65; ++k)
        for (int j = 0; j < 17; ++j)
            for (int i = 0; i < 17; ++i) v.set_value(i, j, k, 200);
    v.compute_range();
    const float a = 0.03f;
    TransferFunction tf;
    tf.color = {{0.0, 1, 1, 1}, {1.0, 1, 1, 1}};
    tf.opacity = {{0.0, a}, {1.0, a}};
    SliceRenderer r(v);
    r.set_transfer_function(discretise(tf, v.vis_range()));
    OrbitParams p;
    p.projection = Projection::Orthographic;
    p.elevation_deg = 90.f;
    p.zoom = 4.f;
    const Camera cam = Camera::orbit(r.bounds(), p, 8, 8);
    const double expected = std::exp(std::log(1.0 - a) * 64.0);
    for (float step : {1.f, 0.5f, 0.25f}) {
        SliceOptions o;
        o.step = step;
        o.keep_float = true;
        const SliceResult res = r.render(cam, o);
        for (size_t px = 0; px < 64; ++px)
            ASSERT_NEAR(1.0 - res.rgba_float[px * 4 + 3], expected, 0.02)
                << "step " << step << " pixel " << px;
    }
}

// Two samplings of the same integral: the slicer and the ray marcher agree to a few levels.
TEST(SliceRenderer, CloseToTheRayMarcher) {
    SyntheticOptions so;
    so.dims = {32, 32, 32};
    const Volume v = generate(SyntheticKind::SphereShells, so);
    const TransferLut lut = discretise(band_tf(0.2, 0.8, 0.2f), v.vis_range());
    SliceRenderer s(v);
    s.set_transfer_function(lut);
    RayMarcher m(v);
    m.set_transfer_function(lut);
    OrbitParams p;
    p.projection = Projection::Orthographic;
    p.azimuth_deg = 30.f;
    const Camera cam = Camera::orbit(m.bounds(), p, 48, 48);
    SliceOptions so2;
    so2.step = 0.25f;
    RenderOptions ro;
    ro.step = 0.25f;
    ro.ert = kNoEarlyTermination;
    const SliceResult a = s.render(cam, so2);
    const RenderResult b = m.render(cam, ro);
    double sum = 0;
    int worst = 0;
    for (size_t i = 0; i < a.image.rgba.size(); ++i) {
        const int d = std::abs(int(a.image.rgba[i]) - int(b.image.rgba[i]));
        sum += d;
        worst = std::max(worst, d);
    }
    EXPECT_LT(sum / double(a.image.rgba.size()), 1.5);
    EXPECT_LE(worst, 40);
}

TEST(BoxSources, UnknownNamesAreErrors) {
    Volume v({4, 4, 4}, VoxelType::UInt8);
    v.compute_range();
    EXPECT_THROW(make_box_source("bitfield", v), Error);
    EXPECT_THROW(make_box_source("", v), Error);
    EXPECT_EQ(std::string(make_box_source("none", v)->name()), "volume");
}

}  // namespace
}  // namespace lacuna
