// The conformance suite: every skipping structure gives the image of --accel none, byte for byte
// (and the float accumulations bit for bit), and never takes more samples. It runs over every
// AccelKind, so a new structure is covered by adding it to the enum.
//
// Cases: adversarial synthetic volumes (thin sheets, 0/max checkerboards, values on bin
// boundaries, odd dims), the real mricron datasets, and randomized volumes / TFs with
// single-entry opacity spikes / cameras inside and outside the volume, with and without ERT,
// and with every octree setting (leaf size, bit width, initial level, top-down).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>

#include "common/rng.h"
#include "conformance/conformance_util.h"
#include "core/simd_lanes.h"
#include "lacuna/accel.h"
#include "lacuna/io.h"
#include "lacuna/renderer.h"
#include "lacuna/synthetic.h"
#include "lacuna/transfer_function.h"

namespace lacuna {
namespace {

using test::random_camera;
using test::random_lut;
using test::Rng;
using test::spike_lut;

struct Case {
    std::string name;
    const Volume* volume;
    TransferLut lut;
    Camera camera;
    RenderOptions options;
    AccelOptions accel;
};

// Renders the case with every structure and compares with none.
void expect_all_structures_exact(const Case& c, std::vector<AccelKind> kinds = all_accel_kinds()) {
    RayMarcher m(*c.volume);
    m.set_transfer_function(c.lut);
    RenderOptions o = c.options;
    o.keep_float = true;
    o.count_samples = true;
    const RenderResult ref = m.render(c.camera, o);
    for (AccelKind k : kinds) {
        if (k == AccelKind::None) continue;
        auto accel = make_accel(k, *c.volume, c.accel);
        accel->set_transfer_function(c.lut);
        // As the TF change leaves the structure, then refined (the grid's cell mask and leap
        // map, a no-op for the others) on every kernel path (the leaping kernels are per ISA).
        const test::KernelPaths kp;
        for (size_t pass = 0; pass <= kp.paths.size(); ++pass) {
            const bool refined = pass > 0;
            if (pass == 1) accel->refine();
            if (refined) simd::set_isa(kp.paths[pass - 1]);
            m.set_accel(accel.get());
            const RenderResult r = m.render(c.camera, o);
            m.set_accel(nullptr);
            const std::string what =
                c.name + " accel " + to_string(k) +
                (refined ? " refined, path " + simd::to_string(kp.paths[pass - 1]) : "");
            ASSERT_EQ(r.image.rgba, ref.image.rgba) << what;
            ASSERT_EQ(0, std::memcmp(r.rgba_float.data(), ref.rgba_float.data(),
                                     ref.rgba_float.size() * sizeof(float)))
                << what << ": float accumulations differ";
            ASSERT_LE(r.stats.samples, ref.stats.samples) << what;
        }
    }
}

TEST(Conformance, AdversarialSyntheticVolumesAreExactForEveryStructure) {
    const SyntheticKind kinds[] = {SyntheticKind::ThinSheets,    SyntheticKind::Checkerboard,
                                   SyntheticKind::BinBoundaries, SyntheticKind::Tree,
                                   SyntheticKind::SphereShells,  SyntheticKind::NoiseBlobs,
                                   SyntheticKind::MarschnerLobb};
    const VoxelType types[] = {VoxelType::UInt8, VoxelType::Int16, VoxelType::UInt16,
                               VoxelType::Float32};
    Rng rng{42};
    for (SyntheticKind kind : kinds)
        for (VoxelType type : types) {
            SyntheticOptions so;
            so.dims = {rng.range(9, 41), rng.range(9, 41), rng.range(9, 41)};
            so.type = type;
            so.seed = uint32_t(rng.next());
            const Volume v = generate(kind, so);
            const ValueToLut map(v.vis_range(), kDefaultLutSize);
            // Spikes exactly on the entries of the data's extreme and middle values, plus a
            // random multi-bump TF.
            const int entries[] = {map(v.data_range().max), map(v.data_range().min) + 1,
                                   map(0.5f * (v.data_range().min + v.data_range().max))};
            for (int e : entries) {
                Case c{to_string(kind) + "/" + to_string(type) + "/spike" + std::to_string(e),
                       &v,
                       spike_lut(v.vis_range(), std::min(e, kDefaultLutSize - 1)),
                       random_camera(v, rng, 40),
                       RenderOptions{},
                       AccelOptions{}};
                c.options.ert = rng.range(0, 1) ? 0.99f : 2.f;
                c.options.step = 0.2f + rng.uniform();
                expect_all_structures_exact(c);
            }
            Case c{to_string(kind) + "/" + to_string(type) + "/random",
                   &v,
                   random_lut(v.vis_range(), rng),
                   random_camera(v, rng, 40),
                   RenderOptions{},
                   AccelOptions{}};
            expect_all_structures_exact(c);
        }
}

TEST(Conformance, RandomVolumesTfsAndCamerasAreExact) {
    Rng rng{7};
    for (int trial = 0; trial < 40; ++trial) {
        const Vec3i dims{rng.range(2, 37), rng.range(2, 37), rng.range(2, 37)};
        const VoxelType type = VoxelType(rng.range(0, 3));
        Volume v(dims, type);
        // Sparse random content: mostly the minimum, a few random-valued voxels and blobs.
        const float hi =
            type == VoxelType::UInt8 ? 255.f : (type == VoxelType::Float32 ? 1.f : 4000.f);
        const int points = rng.range(1, 60);
        for (int p = 0; p < points; ++p) {
            const int x = rng.range(0, dims.x - 1), y = rng.range(0, dims.y - 1),
                      z = rng.range(0, dims.z - 1);
            const float val =
                type == VoxelType::Float32 ? hi * rng.uniform() : std::floor(hi * rng.uniform());
            v.set_value(x, y, z, val);
        }
        v.set_value(0, 0, 0, hi);  // a known range
        v.compute_range();
        AccelOptions ao;
        ao.leaf_cells = 1 << rng.range(1, 4);
        ao.bitfield_bits = 8 << rng.range(0, 4);
        ao.bidirectional = rng.range(0, 1) == 1;
        ao.initial_level = rng.range(-1, 3);
        ao.distance_block = rng.range(1, 5);
        TransferLut lut;
        if (rng.range(0, 1)) {
            // A spike on the entry of one of the voxels we set (so something is visible).
            lut = spike_lut(v.vis_range(), ValueToLut(v.vis_range(), kDefaultLutSize)(
                                               v.value(rng.range(0, dims.x - 1), 0, 0)));
            lut.entries[size_t(ValueToLut(v.vis_range(), kDefaultLutSize)(hi))].a = 0.4f;
        } else {
            lut = random_lut(v.vis_range(), rng);
        }
        Case c{"random trial " + std::to_string(trial),
               &v,
               lut,
               random_camera(v, rng, 32),
               RenderOptions{},
               ao};
        c.options.step = 0.1f + 1.5f * rng.uniform();
        c.options.ert = rng.range(0, 1) ? 0.9f : 2.f;
        expect_all_structures_exact(c);
    }
}

TEST(Conformance, RealDatasetsAreExactForEveryStructure) {
    const std::string dir = "/usr/share/mricron/templates/";
    struct Real {
        const char* file;
        const char* preset;
    };
    const Real reals[] = {{"ch2.nii.gz", "mr-skin"},
                          {"ch2bet.nii.gz", "mr-brain"},
                          {"ch2.nii.gz", "mr-gap"},
                          {"inia19-t1-brain.nii.gz", "mr-brain"},
                          {"aal.nii.gz", "mr-default"}};
    Rng rng{99};
    for (const Real& r : reals) {
        const Volume v = read_volume(dir + r.file);
        const TransferLut lut = discretise(preset(r.preset), v.vis_range());
        for (int view = 0; view < 2; ++view) {
            Case c{std::string(r.file) + "/" + r.preset + "/view" + std::to_string(view),
                   &v,
                   lut,
                   random_camera(v, rng, 48),
                   RenderOptions{},
                   AccelOptions{}};
            c.options.ert = view == 0 ? 0.99f : 2.f;
            expect_all_structures_exact(c);
        }
    }
}

TEST(Conformance, EveryOctreeSettingIsExact) {
    SyntheticOptions so;
    so.dims = {45, 38, 51};
    const Volume v = generate(SyntheticKind::Tree, so);
    const TransferLut lut = discretise(preset("mr-gap"), v.vis_range());
    Rng rng{5};
    const Camera cam = random_camera(v, rng, 40);
    for (int leaf : {2, 4, 8, 16, 32, 64})
        for (int bits : {8, 16, 32, 64, 128})
            for (int level : {-1, 0, 1, 2}) {
                AccelOptions ao;
                ao.leaf_cells = leaf;
                ao.bitfield_bits = bits;
                ao.initial_level = level;
                ao.bidirectional = (leaf + bits + level) % 2 == 0;
                Case c{"leaf " + std::to_string(leaf) + " bits " + std::to_string(bits) +
                           " level " + std::to_string(level),
                       &v,
                       lut,
                       cam,
                       RenderOptions{},
                       ao};
                expect_all_structures_exact(
                    c, {AccelKind::Bitfield, AccelKind::MinMax, AccelKind::Boolean});
            }
}

TEST(Conformance, StructuresSkipSamplesOnSparseVolumes) {
    // Not a timing test: the structures must actually remove samples where space is empty.
    SyntheticOptions so;
    so.dims = {64, 64, 64};
    const Volume v = generate(SyntheticKind::Tree, so);
    const TransferLut lut = discretise(preset("mr-default"), v.vis_range());
    RayMarcher m(v);
    m.set_transfer_function(lut);
    OrbitParams p;
    const Camera cam = Camera::orbit(m.bounds(), p, 48, 48);
    const uint64_t none = m.render(cam, RenderOptions{}).stats.samples;
    for (AccelKind k : all_accel_kinds()) {
        if (k == AccelKind::None) continue;
        auto a = make_accel(k, v);
        a->set_transfer_function(lut);
        m.set_accel(a.get());
        const uint64_t s = m.render(cam, RenderOptions{}).stats.samples;
        EXPECT_LT(s * 2, none) << to_string(k) << " took " << s << " of " << none;
        m.set_accel(nullptr);
    }
}

// Every kernel path this CPU runs (scalar, SSE4.1, AVX2, AVX-512: core/simd_lanes.h) gives the
// bytes and float accumulations of the scalar --accel none render, for every structure, with and
// without early termination, on every voxel type.
TEST(Conformance, EveryKernelPathIsExactForEveryStructure) {
    const test::KernelPaths kp;
    const std::vector<simd::Isa>& paths = kp.paths;
    ASSERT_GE(paths.size(), 2u) << "at least the scalar path and one SIMD path";
    Rng rng{2026};
    int compared = 0;
    for (int trial = 0; trial < 16; ++trial) {
        const Volume v = test::random_volume(rng, 33);
        TransferLut lut = random_lut(v.vis_range(), rng);
        if (trial % 4 >= 2) test::make_dense(lut, size_t(1) << 18, rng);
        RenderOptions o;
        o.keep_float = true;
        o.count_samples = true;
        o.step = 0.1f + 1.2f * rng.uniform();
        o.ert = trial % 2 ? 0.85f : 2.f;
        o.tile = rng.range(3, 17);
        const Camera cam = random_camera(v, rng, 29);
        RayMarcher m(v);
        m.set_transfer_function(lut);
        simd::set_isa(simd::Isa::Scalar);
        const RenderResult ref = m.render(cam, o);
        for (AccelKind k : all_accel_kinds()) {
            auto accel = make_accel(k, v);
            accel->set_transfer_function(lut);
            m.set_accel(accel.get());
            for (int refined = 0; refined < 2; ++refined)
                for (simd::Isa isa : paths) {
                    if (refined && isa == paths.front()) accel->refine();
                    simd::set_isa(isa);
                    const RenderResult r = m.render(cam, o);
                    const std::string what = "trial " + std::to_string(trial) + " " +
                                             to_string(v.type()) + " accel " + to_string(k) +
                                             " path " + simd::to_string(isa) +
                                             (refined ? " refined" : "");
                    ASSERT_EQ(r.image.rgba, ref.image.rgba) << what;
                    ASSERT_EQ(0, std::memcmp(r.rgba_float.data(), ref.rgba_float.data(),
                                             ref.rgba_float.size() * sizeof(float)))
                        << what << ": float accumulations differ";
                    if (k == AccelKind::None) ASSERT_EQ(r.sample_counts, ref.sample_counts) << what;
                    ++compared;
                }
            m.set_accel(nullptr);
        }
    }
    EXPECT_GT(compared, 100);
}

}  // namespace
}  // namespace lacuna
