// The batched kernel (SSE4.1 lanes for int32 offsets, plain loops for int64) against the one
// definition of a sample: kernel::trilinear + ValueToLut + front-to-back compositing, one sample
// at a time. Every composited float must agree to the bit, for every voxel type, awkward floats,
// rays that start and end outside the box (clamping), and segment splits anywhere (full batches
// and short tails).
#include <gtest/gtest.h>

#include <cstring>

#include "accel/accel_test_util.h"
#include "lacuna/renderer.h"
#include "render/ray_march_kernel.h"

namespace lacuna {
namespace {

using namespace accel_test;

template <class T, class Index>
kernel::Grid<T, Index> grid_of(const Volume& v) {
    const Vec3i d = v.dims();
    return kernel::Grid<T, Index>{v.data_as<T>(), ptrdiff_t(d.x), ptrdiff_t(d.x) * d.y,
                                  float(d.x - 1), float(d.y - 1), float(d.z - 1),
                                  d.x - 2,        d.y - 2,        d.z - 2};
}

uint32_t bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

template <class T>
void check_volume(const Volume& v, const TransferLut& lut, Rng& rng, const std::string& what) {
    const std::vector<Rgba> table = step_corrected_lut(lut, 0.7f);
    const ValueToLut map = lut.map();
    const auto g32 = grid_of<T, int32_t>(v);
    const auto g64 = grid_of<T, int64_t>(v);
    const Vec3i d = v.dims();
    for (int ray = 0; ray < 40; ++ray) {
        // A ray from a point around the box (up to 30% outside) in a random direction.
        kernel::IndexRay r;
        r.ox = (rng.uniform() * 1.6f - 0.3f) * float(d.x - 1);
        r.oy = (rng.uniform() * 1.6f - 0.3f) * float(d.y - 1);
        r.oz = (rng.uniform() * 1.6f - 0.3f) * float(d.z - 1);
        float dir[3], len = 0;
        for (float& c : dir) {
            c = rng.uniform() * 2.f - 1.f;
            if (rng.coin(8)) c = 0.f;  // axis-parallel rays
            len += c * c;
        }
        if (len == 0.f) dir[0] = len = 1.f;
        r.dx = dir[0] / std::sqrt(len), r.dy = dir[1] / std::sqrt(len),
        r.dz = dir[2] / std::sqrt(len);
        const float dt = 0.1f + rng.uniform();
        const float t_base = rng.uniform() * 3.f - 1.f;
        const int k_end = rng.range(1, 120);
        // Reference: one sample at a time.
        kernel::Accum ref;
        for (int k = 0; k < k_end; ++k) {
            const float t = t_base + (float(k) + 0.5f) * dt;
            const Rgba& c = table[size_t(
                map(kernel::trilinear(g32, r.ox + t * r.dx, r.oy + t * r.dy, r.oz + t * r.dz)))];
            const float w = 1.f - ref.a;
            ref.r += w * c.r, ref.g += w * c.g, ref.b += w * c.b, ref.a += w * c.a;
        }
        // Batched, in random splits (as the cursor's segments split a ray).
        for (int variant = 0; variant < 2; ++variant) {
            kernel::Accum acc;
            bool done = false;
            uint32_t n = 0;
            for (int k = 0; k < k_end;) {
                const int k1 = std::min(k_end, k + rng.range(1, 40));
                n += variant == 0 ? kernel::march(g32, r, t_base, dt, k, k1, table.data(), map, 2.f,
                                                  acc, done)
                                  : kernel::march(g64, r, t_base, dt, k, k1, table.data(), map, 2.f,
                                                  acc, done);
                k = k1;
            }
            const char* idx = variant == 0 ? "int32 offsets" : "int64 offsets";
            ASSERT_EQ(n, uint32_t(k_end)) << what << ", " << idx;
            ASSERT_EQ(bits(acc.r), bits(ref.r)) << what << ", " << idx << ", ray " << ray;
            ASSERT_EQ(bits(acc.g), bits(ref.g)) << what << ", " << idx << ", ray " << ray;
            ASSERT_EQ(bits(acc.b), bits(ref.b)) << what << ", " << idx << ", ray " << ray;
            ASSERT_EQ(bits(acc.a), bits(ref.a)) << what << ", " << idx << ", ray " << ray;
        }
        // The stream over runs with gaps (as skipping leaves them), against one sample at a
        // time over exactly the samples of the runs, with and without early termination.
        for (int variant = 0; variant < 4; ++variant) {
            const float ert = variant < 2 ? kNoEarlyTermination : 0.3f + 0.6f * rng.uniform();
            std::vector<std::pair<int, int>> runs;
            for (int k = rng.range(0, 5); k < k_end;) {
                const int k1 = std::min(k_end, k + rng.range(1, 30));
                runs.push_back({k, k1});
                k = k1 + rng.range(0, 12);
            }
            kernel::Accum want;
            uint32_t want_n = 0;
            bool stop = false;
            for (auto [k0, k1] : runs)
                for (int k = k0; k < k1 && !stop; ++k) {
                    const float t = t_base + (float(k) + 0.5f) * dt;
                    const Rgba& c = table[size_t(map(kernel::trilinear(
                        g32, r.ox + t * r.dx, r.oy + t * r.dy, r.oz + t * r.dz)))];
                    const float w = 1.f - want.a;
                    want.r += w * c.r, want.g += w * c.g, want.b += w * c.b, want.a += w * c.a;
                    ++want_n;
                    stop = want.a >= ert;
                }
            kernel::Accum acc;
            uint32_t n = 0;
            auto run_stream = [&](const auto& g) {
                kernel::RayStream s(g, r, t_base, dt, table.data(), map, ert, acc);
                for (auto [k0, k1] : runs)
                    if (!s.add(k0, k1)) break;
                s.finish();
                n = s.samples();
            };
            if (variant % 2 == 0)
                run_stream(g32);
            else
                run_stream(g64);
            const std::string idx = std::string(variant % 2 == 0 ? "int32" : "int64") +
                                    " stream, ert " + std::to_string(ert);
            ASSERT_EQ(n, want_n) << what << ", " << idx << ", ray " << ray;
            ASSERT_EQ(bits(acc.r), bits(want.r)) << what << ", " << idx << ", ray " << ray;
            ASSERT_EQ(bits(acc.g), bits(want.g)) << what << ", " << idx << ", ray " << ray;
            ASSERT_EQ(bits(acc.b), bits(want.b)) << what << ", " << idx << ", ray " << ray;
            ASSERT_EQ(bits(acc.a), bits(want.a)) << what << ", " << idx << ", ray " << ray;
        }
    }
}

TEST(Kernel, BatchedMarchEqualsOneSampleAtATimeToTheBit) {
    Rng rng{20261122};
    for (VoxelType t : kAllTypes)
        for (int trial = 0; trial < 6; ++trial) {
            const bool awkward = t == VoxelType::Float32 && trial % 2 == 1;
            Volume v = random_volume(t, random_dims(rng, 2, 19), rng, awkward);
            const TransferLut lut = random_lut(random_vis(v, rng), 1024, rng);
            const std::string what = std::string(to_string(t)) + " trial " + std::to_string(trial);
            visit_voxels(v, [&](const auto* data) {
                using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
                check_volume<T>(v, lut, rng, what);
            });
        }
}

}  // namespace
}  // namespace lacuna
