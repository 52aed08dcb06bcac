// render/ownership.h: the owned run of a ray equals the brute-force set of lattice samples whose
// kernel position lies in the box, and bricks that partition space take every sample once.
#include "render/ownership.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/rng.h"

namespace lacuna {
namespace {

bool in_box(const kernel::IndexRay& r, float t_base, float dt, int k, const float lo[3],
            const float hi[3]) {
    for (int a = 0; a < 3; ++a) {
        const float p = lattice_coordinate(r, a, t_base, dt, k);
        if (!(p >= lo[a] && p < hi[a])) return false;
    }
    return true;
}

kernel::IndexRay random_ray(test::Rng& rng) {
    kernel::IndexRay r{};
    float* o = &r.ox;
    for (int a = 0; a < 6; ++a)
        o[a] = a < 3 ? -20.f + 60.f * rng.uniform() : -1.f + 2.f * rng.uniform();
    if (rng.coin(4)) r.dy = 0.f;  // axis-parallel components
    if (rng.coin(8)) r.dx = -0.f;
    return r;
}

TEST(Ownership, OwnedRunIsExactlyTheSamplesInTheBox) {
    test::Rng rng{19};
    for (int it = 0; it < 4000; ++it) {
        const kernel::IndexRay r = random_ray(rng);
        const float t_base = 30.f * rng.uniform(), dt = 0.05f + rng.uniform();
        const int k_end = rng.range(0, 300);
        float lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = rng.coin(4) ? -INFINITY : float(rng.range(-5, 20));
            hi[a] = rng.coin(4) ? INFINITY : lo[a] + float(rng.range(1, 20));
            if (lo[a] == -INFINITY && hi[a] != INFINITY) hi[a] = float(rng.range(-5, 30));
        }
        int ka, kb;
        owned_run(r, t_base, dt, k_end, lo, hi, ka, kb);
        for (int k = 0; k < k_end; ++k)
            ASSERT_EQ(in_box(r, t_base, dt, k, lo, hi), k >= ka && k < kb)
                << "it " << it << " k " << k << " run [" << ka << ", " << kb << ")";
    }
}

// Integer planes (a kd split) at random positions: every sample of every ray in exactly one of
// the 2 x 2 x 2 boxes around them, including samples that fall exactly on a plane.
TEST(Ownership, BricksAroundPlanesTakeEverySampleOnce) {
    test::Rng rng{7};
    for (int it = 0; it < 500; ++it) {
        kernel::IndexRay r = random_ray(rng);
        if (it % 5 == 0) r = {0.f, 0.5f, 0.25f, 1.f, 0.f, 0.f};  // samples on planes x = integer
        const float t_base = 2.f * rng.uniform(), dt = it % 5 == 0 ? 0.5f : 0.1f + rng.uniform();
        const int k_end = 200;
        const float plane[3] = {float(rng.range(1, 20)), float(rng.range(1, 20)),
                                float(rng.range(1, 20))};
        std::vector<int> taken(size_t(k_end), 0);
        for (int b = 0; b < 8; ++b) {
            float lo[3], hi[3];
            for (int a = 0; a < 3; ++a) {
                const bool high = (b >> a) & 1;
                lo[a] = high ? plane[a] : -INFINITY;
                hi[a] = high ? INFINITY : plane[a];
            }
            int ka, kb;
            owned_run(r, t_base, dt, k_end, lo, hi, ka, kb);
            for (int k = ka; k < kb; ++k) ++taken[size_t(k)];
        }
        for (int k = 0; k < k_end; ++k) ASSERT_EQ(taken[size_t(k)], 1) << "it " << it << " k " << k;
    }
}

}  // namespace
}  // namespace lacuna
