#include "volume/resample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "lacuna/error.h"

namespace lacuna {
namespace {

// An affine field f(x, y, z) = a + bx + cy + dz in index coordinates: trilinear interpolation
// reproduces it exactly, so every resampled voxel has an analytic answer.
struct Linear {
    double a, b, c, d;
    double operator()(double x, double y, double z) const { return a + b * x + c * y + d * z; }
};

Volume linear_volume(Vec3i dims, VoxelType type, const Linear& f) {
    Volume v(dims, type);
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            for (int i = 0; i < dims.x; ++i) v.set_value(i, j, k, float(f(i, j, k)));
    v.spacing = {0.5, 1.25, 2.0};
    v.compute_range();
    return v;
}

// Input index coordinate of output voxel i (corner-aligned).
double pos(int i, int n_in, int n_out) {
    return double(i) * double(n_in - 1) / double(n_out - 1);
}

void expect_linear(const Volume& in, const Volume& out, const Linear& f, double tol) {
    const Vec3i di = in.dims(), d = out.dims();
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const double want = f(pos(i, di.x, d.x), pos(j, di.y, d.y), pos(k, di.z, d.z));
                ASSERT_NEAR(out.value(i, j, k), want, tol)
                    << "voxel " << i << "," << j << "," << k << " of " << to_string(out);
            }
}

TEST(Resample, Float32ReproducesALinearFieldUpAndDown) {
    const Linear f{1.5, 0.25, -0.75, 2.0};
    const Volume in = linear_volume({9, 7, 5}, VoxelType::Float32, f);
    for (Vec3i d : {Vec3i{17, 4, 13}, Vec3i{3, 20, 2}, Vec3i{9, 7, 5}}) {
        const Volume out = resample_trilinear(in, d, 2);
        EXPECT_EQ(out.type(), VoxelType::Float32);
        expect_linear(in, out, f, 1e-5);
    }
}

TEST(Resample, IntegerTypesRoundTheLinearFieldToNearest) {
    // Integer-valued at the input voxels; in between the exact value is rounded, so the error is
    // at most half a unit.
    struct Case {
        VoxelType type;
        Linear f;
    };
    for (const Case& c :
         {Case{VoxelType::UInt8, {10, 3, 5, 7}}, Case{VoxelType::UInt16, {100, 300, -20, 700}},
          Case{VoxelType::Int16, {-1000, 37, 11, -40}}}) {
        const Volume in = linear_volume({8, 6, 7}, c.type, c.f);
        const Volume out = resample_trilinear(in, {13, 11, 3}, 0);
        EXPECT_EQ(out.type(), c.type);
        expect_linear(in, out, c.f, 0.5 + 1e-9);
    }
}

TEST(Resample, SameDimsIsTheIdentityAndThreadsDoNotMatter) {
    const Volume in = linear_volume({6, 5, 9}, VoxelType::Int16, {-3, 5, -7, 11});
    const Volume same = resample_trilinear(in, in.dims(), 2);
    ASSERT_EQ(same.bytes(), in.bytes());
    EXPECT_EQ(std::memcmp(same.data(), in.data(), in.bytes()), 0);
    const Volume a = resample_trilinear(in, {31, 17, 23}, 1);
    const Volume b = resample_trilinear(in, {31, 17, 23}, 2);
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.bytes()), 0);
}

TEST(Resample, KeepsTheWorldExtentAndTheVisualizationRange) {
    Volume in = linear_volume({9, 7, 5}, VoxelType::UInt8, {0, 10, 5, 20});
    in.set_vis_range({5.f, 150.f});
    const Volume out = resample_trilinear(in, {33, 13, 41});
    const Vec3f a = in.world_extent(), b = out.world_extent();
    EXPECT_NEAR(a.x, b.x, 1e-4);
    EXPECT_NEAR(a.y, b.y, 1e-4);
    EXPECT_NEAR(a.z, b.z, 1e-4);
    EXPECT_EQ(out.vis_range().min, 5.f);
    EXPECT_EQ(out.vis_range().max, 150.f);
    // Corners coincide: the data range of an affine field is attained at the corners.
    EXPECT_EQ(out.data_range().min, in.data_range().min);
    EXPECT_EQ(out.data_range().max, in.data_range().max);
}

TEST(Resample, RejectsDegenerateDims) {
    const Volume in = linear_volume({4, 4, 4}, VoxelType::UInt8, {0, 1, 1, 1});
    EXPECT_THROW(resample_trilinear(in, {1, 4, 4}), Error);
    EXPECT_THROW(resample_trilinear(in, {4, 4, kMaxDim + 1}), Error);
}

}  // namespace
}  // namespace lacuna
