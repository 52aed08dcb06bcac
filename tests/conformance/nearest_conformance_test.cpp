// Nearest-neighbour sampling (--interpolation nearest, lacuna/accel.h Interpolation).
//
// 1. The definition: a brute-force marcher written here (camera ray, index space, the lattice,
//    the voxel floor(p + 0.5) of the clamped position, the LUT, front-to-back compositing) gives
//    the renderer's float accumulations to the bit on every kernel path.
// 2. Exactness: every structure, built for Trilinear or for Nearest, on every kernel path, gives
//    the bytes and floats of the scalar --accel none render, unshaded and with features.
// 3. Holes: on an edge between two values that straddle the only visible value, structures built
//    for Nearest skip every sample, while a range structure cannot; the bitfield's and the grid's
//    sets are the bins of exactly the voxels they must cover (brute force).
#include <gtest/gtest.h>

#include <cstring>

#include "accel/bitfield_octree.h"
#include "accel/brick_grid.h"
#include "common/rng.h"
#include "conformance/conformance_util.h"
#include "core/simd_lanes.h"
#include "lacuna/accel.h"
#include "lacuna/error.h"
#include "lacuna/renderer.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"

namespace lacuna {
namespace {

using test::Rng;

// Premultiplied float RGBA per pixel, marched one sample at a time with nearest samples.
std::vector<float> brute_force_nearest(const Volume& v, const TransferLut& lut, const Camera& cam,
                                       const RenderOptions& o) {
    const std::vector<Rgba> table = step_corrected_lut(lut, o.step);
    const ValueToLut map = lut.map();
    const Vec3i d = v.dims();
    const Vec3f inv_sp = inverse_spacing(v);
    const float dt = sample_distance(v, o.step);
    const float hi[3] = {float(d.x - 1), float(d.y - 1), float(d.z - 1)};
    std::vector<float> out(size_t(cam.width()) * cam.height() * 4, 0.f);
    for (int y = 0; y < cam.height(); ++y)
        for (int x = 0; x < cam.width(); ++x) {
            const kernel::IndexRay r = index_ray(cam.generate(float(x), float(y)), inv_sp);
            float t0, t1;
            if (!kernel::intersect_box(r, hi, t0, t1)) continue;
            kernel::Accum a;
            const int k_end = lattice_end(t0, t1, dt);
            for (int k = 0; k < k_end && !(a.a >= o.ert); ++k) {
                const float t = t0 + (float(k) + 0.5f) * dt;
                const float p[3] = {std::clamp(r.ox + t * r.dx, 0.f, hi[0]),
                                    std::clamp(r.oy + t * r.dy, 0.f, hi[1]),
                                    std::clamp(r.oz + t * r.dz, 0.f, hi[2])};
                const int i = int(p[0] + 0.5f), j = int(p[1] + 0.5f), l = int(p[2] + 0.5f);
                const Rgba& c = table[size_t(map(v.value(i, j, l)))];
                const float w = 1.f - a.a;
                a.r += w * c.r;
                a.g += w * c.g;
                a.b += w * c.b;
                a.a += w * c.a;
            }
            float* px = &out[(size_t(y) * cam.width() + x) * 4];
            px[0] = a.r, px[1] = a.g, px[2] = a.b, px[3] = a.a;
        }
    return out;
}

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(Nearest, EveryKernelPathMarchesTheNearestVoxel) {
    const test::KernelPaths kp;
    Rng rng{77};
    int compared = 0;
    for (int trial = 0; trial < 10; ++trial) {
        const Volume v = test::random_volume(rng, 28);
        TransferLut lut = test::random_lut(v.vis_range(), rng);
        if (trial % 2) test::make_dense(lut, size_t(1) << 16, rng);
        RenderOptions o;
        o.interpolation = Interpolation::Nearest;
        o.keep_float = true;
        o.step = 0.2f + rng.uniform();
        o.ert = trial % 3 ? kNoEarlyTermination : 0.9f;
        const Camera cam = test::random_camera(v, rng, 23);
        const std::vector<float> ref = brute_force_nearest(v, lut, cam, o);
        RayMarcher m(v);
        m.set_transfer_function(lut);
        RenderOptions tri = o;
        tri.interpolation = Interpolation::Trilinear;
        const bool differs = !same_floats(m.render(cam, tri).rgba_float, ref);
        for (simd::Isa isa : kp.paths) {
            simd::set_isa(isa);
            ASSERT_TRUE(same_floats(m.render(cam, o).rgba_float, ref))
                << "trial " << trial << " " << to_string(v.type()) << " path "
                << simd::to_string(isa);
            ++compared;
        }
        // The test would notice trilinear samples: on most trials they give other floats.
        compared += differs ? 1000 : 0;
    }
    EXPECT_GT(compared, 1000 * 5) << "nearest and trilinear renders should differ on most trials";
}

TEST(Nearest, EveryStructureAndKernelPathIsExact) {
    const test::KernelPaths kp;
    Rng rng{4242};
    int compared = 0;
    for (int trial = 0; trial < 12; ++trial) {
        const Volume v = test::random_volume(rng, 33);
        TransferLut lut = test::random_lut(v.vis_range(), rng);
        if (trial % 4 >= 2) test::make_dense(lut, size_t(1) << 18, rng);
        RenderOptions o;
        o.interpolation = Interpolation::Nearest;
        o.keep_float = true;
        o.count_samples = true;
        o.step = 0.1f + 1.2f * rng.uniform();
        o.ert = trial % 2 ? 0.85f : kNoEarlyTermination;
        o.tile = rng.range(3, 17);
        if (trial % 3 == 1) {
            o.features.shading = ShadingModel::Phong;
            o.features.clip_planes.push_back({{0.6f, 0.8f, 0.f}, 2.f});
        }
        if (trial % 6 == 5) o.features.blend = BlendMode::Mip;
        const Camera cam = test::random_camera(v, rng, 29);
        RayMarcher m(v);
        m.set_transfer_function(lut);
        simd::set_isa(simd::Isa::Scalar);
        const RenderResult ref = m.render(cam, o);
        for (Interpolation built : {Interpolation::Trilinear, Interpolation::Nearest})
            for (AccelKind k : all_accel_kinds()) {
                AccelOptions ao;
                ao.interpolation = built;
                ao.leaf_cells = trial % 3 == 2 ? 2 : 8;
                auto accel = make_accel(k, v, ao);
                accel->set_transfer_function(lut);
                m.set_accel(accel.get());
                for (simd::Isa isa : kp.paths) {
                    simd::set_isa(isa);
                    const RenderResult r = m.render(cam, o);
                    const std::string what = "trial " + std::to_string(trial) + " " +
                                             to_string(v.type()) + " accel " + to_string(k) +
                                             " built for " + to_string(built) + " path " +
                                             simd::to_string(isa);
                    ASSERT_EQ(r.image.rgba, ref.image.rgba) << what;
                    ASSERT_TRUE(same_floats(r.rgba_float, ref.rgba_float))
                        << what << ": floats differ";
                    ASSERT_LE(r.stats.samples, ref.stats.samples) << what;
                    ++compared;
                }
                m.set_accel(nullptr);
            }
    }
    EXPECT_GT(compared, 200);
}

// x < 16: value 0, x >= 16: value 200; only LUT entries of values near 100 are visible. Every
// trilinear sample between x = 15 and 16 passes 100; no voxel has it.
Volume edge_volume() {
    Volume v({32, 24, 20}, VoxelType::UInt8, "edge");
    for (int z = 0; z < 20; ++z)
        for (int y = 0; y < 24; ++y)
            for (int x = 16; x < 32; ++x) v.set_value(x, y, z, 200.f);
    v.compute_range("edge");
    return v;
}

TEST(Nearest, SetsWithHolesSkipAnEdgeThatStraddlesTheVisibleValues) {
    const Volume v = edge_volume();
    TransferLut lut = test::spike_lut(v.vis_range(), v.vis_range().max > 0 ? 512 : 0, 0.8f);
    for (int e = 500; e <= 524; ++e) lut.entries[size_t(e)] = {0.9f, 0.5f, 0.2f, 0.8f};
    RayMarcher m(v);
    m.set_transfer_function(lut);
    OrbitParams p;
    p.azimuth_deg = 10.f;  // looking across the edge plane
    const Camera cam = Camera::orbit(m.bounds(), p, 32, 32);
    RenderOptions tri, near;
    near.interpolation = Interpolation::Nearest;
    // Trilinear: the edge is visible. Nearest: nothing is.
    const RenderResult tri_ref = m.render(cam, tri), near_ref = m.render(cam, near);
    EXPECT_NE(tri_ref.image.rgba, near_ref.image.rgba);
    ASSERT_GT(near_ref.stats.samples, 0u);
    for (AccelKind k : {AccelKind::MinMax, AccelKind::Bitfield, AccelKind::Grid}) {
        AccelOptions ao;
        ao.interpolation = Interpolation::Nearest;
        auto a = make_accel(k, v, ao);
        a->set_transfer_function(lut);
        m.set_accel(a.get());
        const RenderResult r = m.render(cam, near);
        EXPECT_EQ(r.image.rgba, near_ref.image.rgba) << to_string(k);
        if (k == AccelKind::MinMax)
            EXPECT_GT(r.stats.samples, 0u) << "a range structure keeps the edge's cells";
        else
            EXPECT_EQ(r.stats.samples, 0u) << to_string(k) << " built for nearest skips the edge";
        // A structure built for nearest would be wrong for trilinear samples: rejected.
        if (k != AccelKind::MinMax) EXPECT_THROW(m.render(cam, tri), Error) << to_string(k);
        m.set_accel(nullptr);
    }
}

// Brute force: a bitfield leaf built for nearest holds the bins of voxels [B*x, B*x + B] (clipped),
// a grid brick those of its apron voxels [B*b - 1, B*b + B + 1]; nothing more, nothing less.
TEST(Nearest, BitfieldLeavesAndGridBricksHoldTheBinsOfTheirVoxels) {
    Rng rng{9};
    for (int trial = 0; trial < 6; ++trial) {
        const Volume v = test::random_volume(rng, 40);
        AccelOptions ao;
        ao.interpolation = Interpolation::Nearest;
        ao.leaf_cells = trial % 2 ? 2 : 4;
        BitfieldOctree bf(v, ao);
        BrickGrid grid(v, ao);
        const TransferLut lut = test::random_lut(v.vis_range(), rng);
        bf.set_transfer_function(lut);
        grid.set_transfer_function(lut);
        const ValueToLut map = lut.map();
        const Vec3i d = v.dims();
        const int B = ao.leaf_cells;
        auto bins_of = [&](int lo_margin, int hi_margin, const int b[3], int nbins) {
            uint64_t m[2] = {0, 0};
            const int lo[3] = {std::max(B * b[0] - lo_margin, 0), std::max(B * b[1] - lo_margin, 0),
                               std::max(B * b[2] - lo_margin, 0)};
            const int hi[3] = {std::min(B * b[0] + B + hi_margin, d.x - 1),
                               std::min(B * b[1] + B + hi_margin, d.y - 1),
                               std::min(B * b[2] + B + hi_margin, d.z - 1)};
            for (int z = lo[2]; z <= hi[2]; ++z)
                for (int y = lo[1]; y <= hi[1]; ++y)
                    for (int x = lo[0]; x <= hi[0]; ++x) {
                        const int bin = int(int64_t(map(v.value(x, y, z))) * nbins / map.size());
                        m[bin >> 6] |= uint64_t(1) << (bin & 63);
                    }
            return m[0];
        };
        const Pyramid& pyr = bf.pyramid();
        for (int z = 0; z < pyr.n[0][2]; ++z)
            for (int y = 0; y < pyr.n[0][1]; ++y)
                for (int x = 0; x < pyr.n[0][0]; ++x) {
                    const int b[3] = {x, y, z};
                    ASSERT_EQ(bf.node_bits(pyr.index(0, x, y, z))[0], bins_of(0, 0, b, bf.bits()))
                        << "trial " << trial << " leaf " << x << "," << y << "," << z;
                }
        const int* nb = grid.bricks();
        for (int z = 0; z < nb[2]; ++z)
            for (int y = 0; y < nb[1]; ++y)
                for (int x = 0; x < nb[0]; ++x) {
                    const int b[3] = {x, y, z};
                    ASSERT_EQ(grid.brick_bins(x, y, z), bins_of(1, 1, b, 64))
                        << "trial " << trial << " brick " << x << "," << y << "," << z;
                }
    }
}

TEST(Nearest, InterpolationNamesParse) {
    EXPECT_EQ(parse_interpolation("nearest"), Interpolation::Nearest);
    EXPECT_EQ(parse_interpolation("trilinear"), Interpolation::Trilinear);
    EXPECT_EQ(to_string(Interpolation::Nearest), "nearest");
    EXPECT_THROW(parse_interpolation("cubic"), Error);
}

}  // namespace
}  // namespace lacuna
