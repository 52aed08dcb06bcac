// Headerless .raw volumes: layout from the name or from ReadOptions::raw.
#include <gtest/gtest.h>

#include "io/io_test_util.h"
#include "lacuna/io.h"

namespace lacuna {
namespace {

using test::ScratchDir;

TEST(RawSpecFromName, ParsesDimsAndType) {
    const auto s = raw_spec_from_name("/data/head_301x370x316_uint8.raw");
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->dims, (Vec3i{301, 370, 316}));
    EXPECT_EQ(s->type, VoxelType::UInt8);
    EXPECT_FALSE(s->big_endian);
}

TEST(RawSpecFromName, AcceptsEveryTypeAndUppercaseX) {
    EXPECT_EQ(raw_spec_from_name("a_2X3X4_int16.raw")->type, VoxelType::Int16);
    EXPECT_EQ(raw_spec_from_name("a_2x3x4_uint16.raw")->type, VoxelType::UInt16);
    EXPECT_EQ(raw_spec_from_name("a_2x3x4_float32.raw")->type, VoxelType::Float32);
    EXPECT_EQ(raw_spec_from_name("a_2x3x4_float.raw")->type, VoxelType::Float32);
    EXPECT_EQ(raw_spec_from_name("A_2X3X4_UINT8.RAW")->dims, (Vec3i{2, 3, 4}));
    EXPECT_EQ(raw_spec_from_name("64x64x64_uint8.raw")->dims, (Vec3i{64, 64, 64}));
    EXPECT_TRUE(raw_spec_from_name("ct_512x512x100_int16_be.raw")->big_endian);
    EXPECT_FALSE(raw_spec_from_name("ct_512x512x100_int16_le.raw")->big_endian);
}

TEST(RawSpecFromName, RejectsNamesWithoutALayout) {
    EXPECT_FALSE(raw_spec_from_name("head.raw"));
    EXPECT_FALSE(raw_spec_from_name("head_301x370_uint8.raw"));
    EXPECT_FALSE(raw_spec_from_name("head_301x370x316_int64.raw"));
    EXPECT_FALSE(raw_spec_from_name("head_301x370x316_uint8.nrrd"));
    EXPECT_FALSE(raw_spec_from_name("head301x370x316_uint8.raw"));
}

TEST(RawSpecFromName, HugeNumbersSaturateInsteadOfWrapping) {
    const auto s = raw_spec_from_name("x_99999999999x2x2_uint8.raw");
    ASSERT_TRUE(s.has_value());
    EXPECT_GT(s->dims.x, kMaxDim);
}

TEST(RawReader, ReadsExplicitLayoutWithSpacingAndByteSwap) {
    ScratchDir dir;
    std::vector<uint8_t> be;
    for (int i = 0; i < 2 * 3 * 4; ++i) {
        const uint16_t x = uint16_t(300 * i);
        be.push_back(uint8_t(x >> 8));
        be.push_back(uint8_t(x & 0xff));
    }
    test::write_bytes(dir.file("scan.bin.raw"), be);
    ReadOptions opts;
    opts.raw = RawSpec{{2, 3, 4}, VoxelType::UInt16, {0.5, 0.5, 2.0}, true};
    const Volume v = read_volume(dir.file("scan.bin.raw"), opts);
    EXPECT_EQ(v.dims(), (Vec3i{2, 3, 4}));
    EXPECT_EQ(v.spacing, (Vec3d{0.5, 0.5, 2.0}));
    for (int i = 0; i < 24; ++i) EXPECT_EQ(v.data_as<uint16_t>()[i], uint16_t(300 * i));
    EXPECT_EQ(v.data_range().max, 300.f * 23);
}

TEST(RawReader, ExplicitLayoutOverridesTheName) {
    ScratchDir dir;
    test::write_bytes(dir.file("v_4x4x4_uint8.raw"), std::vector<uint8_t>(64, 9));
    ReadOptions opts;
    opts.raw = RawSpec{{8, 4, 2}, VoxelType::UInt8, {1, 1, 1}, false};
    EXPECT_EQ(read_volume(dir.file("v_4x4x4_uint8.raw"), opts).dims(), (Vec3i{8, 4, 2}));
}

TEST(RawReader, RejectsBadExplicitLayout) {
    ScratchDir dir;
    test::write_bytes(dir.file("v.raw"), std::vector<uint8_t>(64, 9));
    ReadOptions opts;
    opts.raw = RawSpec{{64, 1, 1}, VoxelType::UInt8, {1, 1, 1}, false};
    const std::string msg = test::error_of([&] { read_volume(dir.file("v.raw"), opts); });
    EXPECT_NE(msg.find("dims"), std::string::npos) << msg;
    opts.raw = RawSpec{{4, 4, 4}, VoxelType::UInt8, {1, 0, 1}, false};
    const std::string msg2 = test::error_of([&] { read_volume(dir.file("v.raw"), opts); });
    EXPECT_NE(msg2.find("spacing"), std::string::npos) << msg2;
}

TEST(RawReader, NanInFloatRawReadsAsTheMinimum) {
    ScratchDir dir;
    std::vector<float> vox = {5.f, 6.f, 1.5f, 8.f, 2.f, 3.f, 4.f, 0.f};
    vox[7] = std::nanf("");
    test::write_bytes(dir.file("f_2x2x2_float32.raw"), vox.data(), vox.size() * 4);
    const Volume v = read_volume(dir.file("f_2x2x2_float32.raw"));
    EXPECT_EQ(v.nan_voxels, 1u);
    EXPECT_EQ(v.value(1, 1, 1), 1.5f);  // the smallest of the other seven
    EXPECT_EQ(v.value(0, 1, 0), 1.5f);  // (a voxel that was 1.5 all along)
    EXPECT_EQ(v.data_range().min, 1.5f);
}

TEST(IoReader, RecognisesADicomFileWithoutExtensionByContent) {
    ScratchDir dir;
    write_volume(dir.file("series") + "/", test::pattern_volume({6, 5, 3}, VoxelType::Int16));
    std::filesystem::copy(dir.path() / "series" / "slice_00000.dcm", dir.path() / "IM0001");
    // ITK's factories identify the DICOM file; a single 2D slice is then no volume.
    const std::string msg = test::error_of([&] { read_volume(dir.file("IM0001")); });
    EXPECT_NE(msg.find("6x5x1"), std::string::npos) << msg;
}

TEST(IoReader, UnknownFormatListsWhatIsSupported) {
    ScratchDir dir;
    test::write_text(dir.file("volume.dat"), "NRRD0004\n");
    const std::string msg = test::error_of([&] { read_volume(dir.file("volume.dat")); });
    EXPECT_NE(msg.find(".nrrd"), std::string::npos) << msg;
}

}  // namespace
}  // namespace lacuna
