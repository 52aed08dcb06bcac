// read_volume on the real MRIcron templates (expected values computed independently from the
// raw NIfTI bytes).
#include <gtest/gtest.h>

#include <vector>

#include "io/io_test_util.h"
#include "lacuna/io.h"

namespace lacuna {
namespace {

const std::string kTemplates = "/usr/share/mricron/templates/";

bool have(const std::string& name) {
    return std::filesystem::exists(kTemplates + name);
}

#define REQUIRE_TEMPLATE(name) \
    ASSERT_TRUE(have(name)) << kTemplates << name << " is installed by scripts/install-deps"

TEST(IoReader, ReadsCh2NiftiWithSpacingAndRange) {
    REQUIRE_TEMPLATE("ch2.nii.gz");
    std::vector<double> progress;
    ReadOptions opts;
    opts.progress = [&](double f) { progress.push_back(f); };
    const Volume v = read_volume(kTemplates + "ch2.nii.gz", opts);
    EXPECT_EQ(v.dims(), (Vec3i{181, 217, 181}));
    EXPECT_EQ(v.type(), VoxelType::UInt8);
    EXPECT_EQ(v.spacing, (Vec3d{1, 1, 1}));
    EXPECT_EQ(v.data_range().min, 0.f);
    EXPECT_EQ(v.data_range().max, 254.f);
    EXPECT_EQ(v.value(90, 108, 90), 33.f);
    // sform (code 4) origin (-90,-125,-71) in RAS is (90,125,-71) in LPS.
    EXPECT_EQ(v.origin, (Vec3d{90, 125, -71}));
    EXPECT_EQ(v.direction[0], -1.0);
    EXPECT_EQ(v.direction[4], -1.0);
    EXPECT_EQ(v.direction[8], 1.0);
    ASSERT_GE(progress.size(), 2u);
    EXPECT_EQ(progress.front(), 0.0);
    EXPECT_EQ(progress.back(), 1.0);
    for (size_t i = 1; i < progress.size(); ++i) EXPECT_GE(progress[i], progress[i - 1]);
}

TEST(IoReader, ReadsCh2betterWithHalfMillimetreSpacing) {
    REQUIRE_TEMPLATE("ch2better.nii.gz");
    const Volume v = read_volume(kTemplates + "ch2better.nii.gz");
    EXPECT_EQ(v.dims(), (Vec3i{301, 370, 316}));
    EXPECT_EQ(v.type(), VoxelType::UInt8);
    EXPECT_EQ(v.spacing, (Vec3d{0.5, 0.5, 0.5}));
    EXPECT_EQ(v.data_range().max, 130.f);
    // qform (code 1) with offset (-75,-107,-69.5) RAS.
    EXPECT_EQ(v.origin, (Vec3d{75, 107, -69.5}));
}

TEST(IoReader, ReadsFloatInia19) {
    REQUIRE_TEMPLATE("inia19-t1-brain.nii.gz");
    const Volume v = read_volume(kTemplates + "inia19-t1-brain.nii.gz");
    EXPECT_EQ(v.dims(), (Vec3i{168, 206, 128}));
    EXPECT_EQ(v.type(), VoxelType::Float32);
    EXPECT_EQ(v.spacing, (Vec3d{0.5, 0.5, 0.5}));
    EXPECT_EQ(v.data_range().min, 0.f);
    EXPECT_FLOAT_EQ(v.data_range().max, 383.175537109375f);
    EXPECT_FLOAT_EQ(v.value(84, 103, 64), 88.77368927001953f);
}

TEST(IoReader, ReadsAalLabels) {
    REQUIRE_TEMPLATE("aal.nii.gz");
    const Volume v = read_volume(kTemplates + "aal.nii.gz");
    EXPECT_EQ(v.dims(), (Vec3i{181, 217, 181}));
    EXPECT_EQ(v.type(), VoxelType::UInt8);
    EXPECT_EQ(v.data_range().max, 116.f);
}

TEST(IoReader, ReadsCh2betLikeCh2) {
    REQUIRE_TEMPLATE("ch2bet.nii.gz");
    const Volume v = read_volume(kTemplates + "ch2bet.nii.gz");
    EXPECT_EQ(v.dims(), (Vec3i{181, 217, 181}));
    EXPECT_EQ(v.type(), VoxelType::UInt8);
}

}  // namespace
}  // namespace lacuna
