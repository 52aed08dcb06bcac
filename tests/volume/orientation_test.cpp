// The index-to-world (RAS) affine, orientation codes, world bounds, the geometry checks and the
// rigid volume frame the renderers use (lacuna/orientation.h).
#include "lacuna/orientation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "lacuna/error.h"

namespace lacuna {
namespace {

void set_lps(Volume& v, std::initializer_list<double> d) {
    int i = 0;
    for (double x : d) v.direction[i++] = x;
}

TEST(Orientation, AVolumeWithoutGeometryIsIndexTimesSpacing) {
    Volume v({4, 5, 6}, VoxelType::UInt8);
    v.spacing = {0.5, 2, 3};
    const Affine a = index_to_world(v);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) EXPECT_EQ(a.m[r][c], r == c ? v.spacing[c] : 0.0) << r << c;
        EXPECT_EQ(a.t[r], 0.0);
    }
    EXPECT_EQ(orientation_code(v), "RAS");
    const Box3f b = world_bounds(v);
    EXPECT_EQ(b.lo, (Vec3f{0, 0, 0}));
    EXPECT_EQ(b.hi, v.world_extent());
    EXPECT_TRUE(volume_frame(v).identity);
    EXPECT_NO_THROW(check_geometry(v, "v"));
}

TEST(Orientation, LpsDirectionAndOriginBecomeRasWithXAndYNegated) {
    Volume v({10, 20, 30}, VoxelType::UInt8);
    v.spacing = {1, 2, 3};
    set_lps(v, {1, 0, 0, 0, 1, 0, 0, 0, 1});  // LPS identity: a standard axial DICOM series
    v.origin = {10, 20, 30};
    const Affine a = index_to_world(v);
    EXPECT_EQ(orientation_code(v), "LPS");
    EXPECT_EQ(a.m[0][0], -1.0);
    EXPECT_EQ(a.m[1][1], -2.0);
    EXPECT_EQ(a.m[2][2], 3.0);
    EXPECT_EQ(a.t[0], -10.0);
    EXPECT_EQ(a.t[1], -20.0);
    EXPECT_EQ(a.t[2], 30.0);
    const Box3f b = world_bounds(v);
    EXPECT_EQ(b.lo, (Vec3f{-19, -58, 30}));
    EXPECT_EQ(b.hi, (Vec3f{-10, -20, 117}));
    const VolumeFrame f = volume_frame(v);
    EXPECT_FALSE(f.identity);
    EXPECT_TRUE(f.axis_aligned());
    // The frame maps voxel (i,j,k)'s world position to (i,j,k) * spacing.
    const Vec3d w = a.apply({3, 4, 5});
    const Vec3f q = f.point(Vec3f(w));
    EXPECT_NEAR(q.x, 3, 1e-5);
    EXPECT_NEAR(q.y, 8, 1e-5);
    EXPECT_NEAR(q.z, 15, 1e-5);
}

TEST(Orientation, CodesNameWhereEachIndexAxisPoints) {
    Volume v({4, 4, 4}, VoxelType::UInt8);
    // Sagittal storage: i runs anterior->posterior (P), j superior->inferior... in LPS terms:
    // column 0 = +P (LPS y), column 1 = -S (LPS -z), column 2 = +L (LPS x).
    set_lps(v, {0, 0, 1, 1, 0, 0, 0, -1, 0});
    EXPECT_EQ(orientation_code(v), "PIL");
    set_lps(v, {-1, 0, 0, 0, 1, 0, 0, 0, -1});  // R, P, I
    EXPECT_EQ(orientation_code(v), "RPI");
}

TEST(Orientation, AnObliqueFrameIsRigidAndInvertsTheAffine) {
    Volume v({9, 11, 13}, VoxelType::UInt8);
    v.spacing = {0.8, 1.1, 2.5};
    const double c = std::cos(0.5), s = std::sin(0.5);
    // RAS rotation about superior, stored as LPS (rows 0 and 1 negated).
    set_lps(v, {-c, s, 0, -s, -c, 0, 0, 0, 1});
    v.origin = {5, -7, 12};
    ASSERT_NO_THROW(check_geometry(v, "v"));
    const VolumeFrame f = volume_frame(v);
    EXPECT_FALSE(f.axis_aligned());
    const Affine a = index_to_world(v);
    for (Vec3d idx : {Vec3d{0, 0, 0}, Vec3d{8, 10, 12}, Vec3d{2.5, 7, 1}}) {
        const Vec3f q = f.point(Vec3f(a.apply(idx)));
        EXPECT_NEAR(q.x, idx.x * v.spacing.x, 1e-4);
        EXPECT_NEAR(q.y, idx.y * v.spacing.y, 1e-4);
        EXPECT_NEAR(q.z, idx.z * v.spacing.z, 1e-4);
    }
    const Vec3f d = f.vector(normalize(Vec3f{1, 2, 3}));
    EXPECT_NEAR(length(d), 1.f, 1e-6f);  // lengths (ray parameters in mm) are kept
}

TEST(Orientation, ZeroSingularNonFiniteOrShearedGeometryIsRefusedNamingTheField) {
    auto expect_error = [](const Volume& v, const std::string& field) {
        try {
            check_geometry(v, "f.nrrd");
            ADD_FAILURE() << "accepted, expected an error on " << field;
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.rfind("f.nrrd: " + field + ":", 0), 0u) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    };
    Volume v({4, 4, 4}, VoxelType::UInt8);
    Volume z = v;
    set_lps(z, {0, 0, 0, 0, 0, 0, 0, 0, 0});
    expect_error(z, "direction");
    Volume sing = v;
    set_lps(sing, {1, 0, 1, 0, 1, 0, 0, 0, 0});  // axes 0 and 2 equal
    expect_error(sing, "direction");
    Volume nan = v;
    nan.direction[4] = std::nan("");
    expect_error(nan, "direction");
    Volume shear = v;
    set_lps(shear, {1, 0.5, 0, 0, std::sqrt(0.75), 0, 0, 0, 1});  // unit columns, 60 degrees apart
    expect_error(shear, "direction");
    Volume org = v;
    org.origin.y = INFINITY;
    expect_error(org, "origin");
    Volume sp = v;
    sp.spacing.z = 0;
    expect_error(sp, "spacing");
}

// Geometry the renderers' float positions cannot hold rendered an empty picture without a word
// (0 samples per ray): refused, naming the field; just inside the limits is accepted.
TEST(Orientation, GeometryFloatCannotResolveIsRefusedNamingTheField) {
    auto error_field = [](const Volume& v) -> std::string {
        try {
            check_geometry(v, "f.nii");
            return "";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
            return m.substr(0, m.find(':', 7));  // "f.nii: <field>"
        }
    };
    const Volume v({8, 8, 8}, VoxelType::UInt8);
    auto with = [&](Vec3d spacing, Vec3d origin) {
        Volume w = v;
        w.spacing = spacing;
        w.origin = origin;
        return error_field(w);
    };
    EXPECT_EQ(with({1e-20, 1e-20, 1e-20}, {0, 0, 0}), "f.nii: spacing");
    EXPECT_EQ(with({1, 1e-16, 1}, {0, 0, 0}), "f.nii: spacing");
    EXPECT_EQ(with({1e-15, 1e-15, 1e-15}, {0, 0, 0}), "");
    EXPECT_EQ(with({2e14, 1, 1}, {0, 0, 0}), "f.nii: spacing");  // 1.6e15 mm across
    EXPECT_EQ(with({1e14, 1, 1}, {0, 0, 0}), "");
    EXPECT_EQ(with({1, 1, 1}, {0, 0, 2e15}), "f.nii: origin");
    // Far out compared with the finest voxel (2^19 = 524288) and twice the volume's size.
    EXPECT_EQ(with({1, 1, 1}, {1e6, 0, 0}), "f.nii: origin");
    EXPECT_EQ(with({1, 1, 1}, {0, -5e5, 0}), "");
    EXPECT_EQ(with({1e-3, 1e-3, 1e-3}, {0, 0, 600}), "f.nii: origin");
    EXPECT_EQ(with({1e-3, 1e-3, 1e-3}, {0, 0, 500}), "");
    // A volume whose long side is far in voxels of its short one is not refused for its own
    // size (its volume frame rounds as much): the twice-its-size clause.
    Volume longv({2, 2, 32768}, VoxelType::UInt8);
    longv.spacing = {1e-3, 1e-3, 1};
    EXPECT_EQ(error_field(longv), "");
    longv.origin = {0, 0, 70000};  // now far beyond twice its size too
    EXPECT_EQ(error_field(longv), "f.nii: origin");
    Volume aniso({1000, 1000, 2}, VoxelType::UInt8);
    aniso.spacing = {1, 1, 1e-4};
    aniso.origin = {-500, -500, 0};
    EXPECT_EQ(error_field(aniso), "");
}

}  // namespace
}  // namespace lacuna
