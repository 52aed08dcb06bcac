// The orientation tests' helpers (issue 14): one anatomy stored in another voxel order, an
// asymmetric head phantom with L/R, A/P and S/I markers, and the picture criterion.
// Shared by tests/render/orientation_render_test.cpp, the viewer's and `partition`'s tests.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "lacuna/image.h"
#include "lacuna/orientation.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::test::orientation {

using Mat3 = std::array<std::array<double, 3>, 3>;

// The LPS direction cosines (Volume::direction) of a RAS direction matrix, and back.
inline void set_ras_direction(Volume& v, const Mat3& r) {
    const double flip[3] = {-1, -1, 1};
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col)
            v.direction[row * 3 + col] = flip[row] * r[row][col] + 0.0;
}
inline Mat3 ras_direction(const Volume& v) {
    const Affine a = index_to_world(v);
    Mat3 r{};
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) r[row][col] = a.m[row][col] / v.spacing[col];
    return r;
}
inline void set_ras_origin(Volume& v, Vec3d t) {
    v.origin = {-t.x + 0.0, -t.y + 0.0, t.z};
}

// A copy of `b` stored in another voxel order: new axis a is b's axis perm[a], reversed when
// flip[a]. The geometry is rewritten so every voxel keeps its world position.
inline Volume reorder(const Volume& b, std::array<int, 3> perm, std::array<bool, 3> flip) {
    const Vec3i db = b.dims();
    Vec3i dv;
    for (int a = 0; a < 3; ++a) dv[a] = db[perm[a]];
    Volume v(dv, b.type());
    for (int k = 0; k < dv.z; ++k)
        for (int j = 0; j < dv.y; ++j)
            for (int i = 0; i < dv.x; ++i) {
                const int iv[3] = {i, j, k};
                int ib[3];
                for (int a = 0; a < 3; ++a) ib[perm[a]] = flip[a] ? db[perm[a]] - 1 - iv[a] : iv[a];
                v.set_value(i, j, k, b.value(ib[0], ib[1], ib[2]));
            }
    const Affine ab = index_to_world(b);
    Mat3 rv{};
    Vec3d t{ab.t[0], ab.t[1], ab.t[2]};
    for (int a = 0; a < 3; ++a) {
        const int c = perm[a];
        v.spacing[a] = b.spacing[c];
        for (int r = 0; r < 3; ++r) {
            rv[r][a] = (flip[a] ? -1.0 : 1.0) * ab.m[r][c] / b.spacing[c];
            if (flip[a]) t[r] += double(db[c] - 1) * ab.m[r][c];
        }
    }
    set_ras_direction(v, rv);
    set_ras_origin(v, t);
    v.compute_range();
    return v;
}

// An asymmetric head phantom in world millimetres around the volume's centre: a faint body,
// a marker on the patient's right (value 220), one in front (160), one on top (100). Smooth
// edges, so resampling on a mirrored lattice moves values by ulps, not by whole steps.
inline Volume phantom() {
    Volume v({41, 49, 37}, VoxelType::UInt8);
    v.spacing = {1.0, 1.25, 1.5};
    set_ras_origin(v, {-20, -30, -27});  // centre (0, 0, 0)
    const Affine a = index_to_world(v);
    auto bump = [](double d, double radius, double value) {
        return value * std::clamp((radius - d) / 2.5, 0.0, 1.0);
    };
    for (int k = 0; k < 37; ++k)
        for (int j = 0; j < 49; ++j)
            for (int i = 0; i < 41; ++i) {
                const Vec3d w = a.apply({double(i), double(j), double(k)});
                const double body = std::sqrt(w.x * w.x / 256 + w.y * w.y / 484 + w.z * w.z / 400);
                double val = 50 * std::clamp((1 - body) * 5, 0.0, 1.0);
                val = std::max(val, bump(length(w - Vec3d{11, -2, 0}), 5, 220));
                val = std::max(val, bump(length(w - Vec3d{0, 17, -4}), 4.5, 160));
                val = std::max(val, bump(length(w - Vec3d{-3, -4, 16}), 4.5, 100));
                v.set_value(i, j, k, float(std::round(val)));
            }
    v.compute_range();
    return v;
}

inline TransferFunction phantom_tf() {
    TransferFunction tf;
    tf.name = "phantom";
    tf.domain = TfDomain::Value;
    tf.color = {{0, 0.5, 0.5, 0.5},   {60, 0.5, 0.5, 0.5},  {90, 0.1, 0.2, 1.0},
                {110, 0.1, 0.2, 1.0}, {150, 0.1, 1.0, 0.2}, {170, 0.1, 1.0, 0.2},
                {210, 1.0, 0.1, 0.1}, {255, 1.0, 0.1, 0.1}};
    tf.opacity = {{0, 0}, {35, 0}, {45, 0.03}, {60, 0.03}, {90, 0.9}, {255, 0.9}};
    return tf;
}
inline TransferLut phantom_lut() {
    return discretise(phantom_tf(), {0, 255});
}

struct Diff {
    size_t identical = 0, within_one = 0, pixels = 0;
    int max = 0;
};
inline Diff compare(const Image& a, const Image& b) {
    Diff d;
    d.pixels = size_t(a.width) * size_t(a.height);
    for (size_t p = 0; p < d.pixels; ++p) {
        int m = 0;
        for (int c = 0; c < 4; ++c)
            m = std::max(m, std::abs(int(a.rgba[p * 4 + c]) - int(b.rgba[p * 4 + c])));
        d.identical += m == 0;
        d.within_one += m <= 1;
        d.max = std::max(d.max, m);
    }
    return d;
}

// The criterion: byte-identical, or within 1 of 255 on at least 99.9% of the pixels.
inline void expect_same_picture(const Image& got, const Image& want, const std::string& what,
                                bool exact) {
    ASSERT_EQ(got.width, want.width);
    const Diff d = compare(got, want);
    if (exact)
        EXPECT_EQ(got.rgba, want.rgba)
            << what << ": " << d.identical << "/" << d.pixels << " identical";
    EXPECT_GE(double(d.within_one), 0.999 * double(d.pixels))
        << what << ": " << d.within_one << "/" << d.pixels << " within 1, max diff " << d.max;
    std::printf("  %s: %zu/%zu pixels identical, %zu within 1, max %d\n", what.c_str(), d.identical,
                d.pixels, d.within_one, d.max);
}

}  // namespace lacuna::test::orientation
