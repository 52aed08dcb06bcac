// Shared oracles of the growing-boxes and BSP tests: adversarial volumes, per-cell coverage and
// the exact "does box A hide part of box B from this view" test.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "accel/accel_test_util.h"
#include "slice/growing_boxes.h"

namespace lacuna::boxes_test {

using accel_test::Rng;

// Volumes that stress a partition: thin sheets, checkerboards, a constant volume, odd and
// minimal dims, random structured volumes of every type.
inline Volume adversarial_volume(int which, VoxelType t, Rng& rng) {
    float lo, hi;
    accel_test::type_limits(t, lo, hi);
    if (which >= 4) return accel_test::random_volume(t, accel_test::random_dims(rng, 2, 17), rng);
    const Vec3i dims = which == 3 ? Vec3i{rng.range(2, 3), rng.range(2, 9), rng.range(2, 5)}
                                  : Vec3i{rng.range(5, 15), rng.range(5, 15), rng.range(5, 15)};
    Volume v(dims, t, "adversarial");
    const int axis = rng.range(0, 2), at = rng.range(0, dims[axis] - 1);
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            for (int i = 0; i < dims.x; ++i) {
                const int p[3] = {i, j, k};
                float x = lo;
                switch (which) {
                    case 0:  // a one-voxel sheet
                        x = p[axis] == at ? hi : lo;
                        break;
                    case 1:  // a checkerboard
                        x = (i + j + k) % 2 ? hi : lo;
                        break;
                    case 2:  // constant
                        x = 0.5f * (lo + hi);
                        if (t != VoxelType::Float32) x = std::floor(x);
                        break;
                    default:  // random values
                        x = accel_test::random_value(t, lo, hi, rng);
                }
                v.set_value(i, j, k, x);
            }
    v.compute_range("adversarial");
    return v;
}

inline BoxesOptions random_options(Rng& rng) {
    BoxesOptions o;
    o.spread = rng.coin(4) ? 0.f : float(rng.range(1, 64));
    o.min_uniform = rng.range(1, 5);
    o.gradient = rng.coin(4) ? 0.f : 0.5f * rng.uniform();
    o.gradient_waste = rng.uniform();
    o.other_cost = float(rng.range(0, 200));
    o.thin = rng.range(0, 4);
    o.merge = !rng.coin(4);
    const float coalesce[] = {-1.f, 0.f, 0.1f, 0.25f, 0.5f, 1.f};
    o.coalesce = coalesce[rng.range(0, 5)];
    o.coalesce_edge = rng.coin() ? 32.f : float(rng.range(1, 16)) * 0.75f;
    o.threads = rng.range(1, 2);
    return o;
}

// Coverage count per cell of a box list (x fastest).
inline std::vector<int> coverage(const int cells[3], const std::vector<CellBox>& boxes) {
    std::vector<int> n(size_t(cells[0]) * cells[1] * cells[2], 0);
    for (const CellBox& b : boxes)
        for (int k = b.lo[2]; k < b.hi[2]; ++k)
            for (int j = b.lo[1]; j < b.hi[1]; ++j)
                for (int i = b.lo[0]; i < b.hi[0]; ++i)
                    if (i >= 0 && j >= 0 && k >= 0 && i < cells[0] && j < cells[1] && k < cells[2])
                        ++n[(size_t(k) * cells[1] + j) * cells[0] + i];
    return n;
}

inline bool inside(const CellBox& a, const CellBox& outer) {
    for (int x = 0; x < 3; ++x)
        if (a.lo[x] < outer.lo[x] || a.hi[x] > outer.hi[x]) return false;
    return true;
}

// Exact: is there a ray (from `key` as an eye, or along `key` as a direction) that passes
// through the interior of `front` and afterwards through the interior of `back`? Then `front`
// must come before `back` in any front-to-back order. Each axis gives linear constraints on the
// ray parameter s (eye + s (a - eye) with s > 1, or a + s dir with s > 0, a in front's interior);
// the open interval they leave must be non-empty.
inline bool hides(const CellBox& front, const CellBox& back, const double key[3], bool is_dir) {
    double lo = is_dir ? 0.0 : 1.0, hi = INFINITY;
    auto constrain = [&](double c, double r, bool less) {  // c s < r (less) or c s > r
        if (c == 0) {
            if (less ? !(0 < r) : !(0 > r)) hi = -INFINITY;
            return;
        }
        const double q = r / c;
        if ((c > 0) == less)
            hi = std::min(hi, q);
        else
            lo = std::max(lo, q);
    };
    for (int a = 0; a < 3; ++a) {
        const double nl = front.lo[a], nh = front.hi[a], fl = back.lo[a], fh = back.hi[a];
        if (is_dir) {
            constrain(key[a], fh - nl, true);
            constrain(key[a], fl - nh, false);
        } else {
            const double e = key[a];
            constrain(nl - e, fh - e, true);
            constrain(nh - e, fl - e, false);
        }
    }
    return hi - lo > 1e-9 * std::max(1.0, std::abs(lo));
}

// Every pair in `order` (front to back): a later box never hides an earlier one.
inline void expect_visibility_order(const std::vector<CellBox>& order, const double key[3],
                                    bool is_dir, const std::string& what) {
    for (size_t i = 0; i < order.size(); ++i)
        for (size_t j = i + 1; j < order.size(); ++j)
            ASSERT_FALSE(hides(order[j], order[i], key, is_dir))
                << what << ": " << to_string(order[j]) << " (position " << j << ") hides "
                << to_string(order[i]) << " (position " << i << ") from (" << key[0] << ", "
                << key[1] << ", " << key[2] << ")" << (is_dir ? " as direction" : " as eye");
}

}  // namespace lacuna::boxes_test
