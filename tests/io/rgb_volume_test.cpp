// RGB24 / RGBA32 NIfTI files: colours kept beside the opacity scalar (Rec. 709 luminance or a
// chosen channel), computed from the bytes as written here; malformed RGB headers are one line.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "io/io_test_util.h"
#include "io/nifti_test_file.h"
#include "lacuna/io.h"
#include "lacuna/rgb.h"

namespace lacuna {
namespace {

using test::error_of;
using test::NiftiSpec;
using test::ScratchDir;

// Interleaved r, g, b[, a] bytes of a dims volume: a different colour at every voxel.
std::vector<uint8_t> colours(Vec3i d, int channels) {
    std::vector<uint8_t> out;
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                out.push_back(uint8_t(40 * i + 3));
                out.push_back(uint8_t(70 * j + 11));
                out.push_back(uint8_t(90 * k + 5));
                if (channels == 4) out.push_back(uint8_t(255 - 30 * (i + j + k)));
            }
    return out;
}

std::string write_rgb(const ScratchDir& dir, const std::string& name, int channels,
                      Vec3i d = {3, 4, 2}, NiftiSpec s = {}) {
    s.dims = d;
    s.datatype = channels == 3 ? 128 : 2304;
    const std::vector<uint8_t> v = colours(d, channels);
    test::write_bytes(dir.file(name), test::nifti_bytes(s, v.data(), v.size()));
    return dir.file(name);
}

TEST(RgbVolume, Rgb24KeepsColoursAndLuminanceIsRec709) {
    ScratchDir dir;
    const Vec3i d{3, 4, 2};
    const Volume v = read_volume(write_rgb(dir, "c.nii", 3, d));
    const RgbColours* rgb = rgb_colours(v);
    ASSERT_TRUE(rgb);
    EXPECT_EQ(rgb->channels, 3);
    EXPECT_EQ(v.type(), VoxelType::Float32);
    const std::vector<uint8_t> c = colours(d, 3);
    for (size_t n = 0; n < v.voxel_count(); ++n) {
        const uint8_t* p = &rgb->rgba[4 * n];
        EXPECT_EQ(p[0], c[3 * n]);
        EXPECT_EQ(p[1], c[3 * n + 1]);
        EXPECT_EQ(p[2], c[3 * n + 2]);
        EXPECT_EQ(p[3], 255);  // no alpha in the file: opaque colour
        const double lum = 0.2126 * c[3 * n] + 0.7152 * c[3 * n + 1] + 0.0722 * c[3 * n + 2];
        EXPECT_NEAR(v.data_as<float>()[n], lum, 1e-3) << n;
    }
    EXPECT_GT(v.data_range().max, v.data_range().min);
}

TEST(RgbVolume, ChannelChoiceStoresThatChannel) {
    ScratchDir dir;
    const Vec3i d{3, 4, 2};
    const std::string path = write_rgb(dir, "c.nii.gz", 4, d);
    const std::vector<uint8_t> c = colours(d, 4);
    const RgbOpacity picks[] = {RgbOpacity::R, RgbOpacity::G, RgbOpacity::B, RgbOpacity::A};
    for (int ch = 0; ch < 4; ++ch) {
        const Volume v = read_volume(path, {}, picks[ch]);
        const RgbColours* rgb = rgb_colours(v);
        ASSERT_TRUE(rgb);
        EXPECT_EQ(rgb->channels, 4);
        EXPECT_EQ(rgb->opacity, picks[ch]);
        ASSERT_EQ(v.type(), VoxelType::UInt8);
        for (size_t n = 0; n < v.voxel_count(); ++n)
            EXPECT_EQ(v.data_as<uint8_t>()[n], c[4 * n + size_t(ch)]) << to_string(picks[ch]);
    }
}

TEST(RgbVolume, MalformedRgbHeadersAreOneLine) {
    ScratchDir dir;
    NiftiSpec bad_bitpix;
    bad_bitpix.bitpix = 8;
    EXPECT_EQ(error_of([&] {
                  read_volume(write_rgb(dir, "b.nii", 3, {3, 4, 2}, bad_bitpix));
              }),
              dir.file("b.nii") + ": bitpix: expected 24 for RGB24 (datatype 128), got 8");
    EXPECT_EQ(error_of([&] { read_volume(write_rgb(dir, "a.nii", 3), {}, RgbOpacity::A); }),
              dir.file("a.nii") +
                  ": rgb opacity: expected luminance, r, g or b: the file has no alpha channel "
                  "(RGB24), got a");
    // Truncated voxels, plain and compressed.
    NiftiSpec s;
    s.dims = {3, 4, 2};
    s.datatype = 2304;
    const std::vector<uint8_t> c = colours(s.dims, 4);
    std::vector<uint8_t> bytes = test::nifti_bytes(s, c.data(), c.size());
    bytes.resize(bytes.size() - 5);
    test::write_bytes(dir.file("t.nii"), bytes);
    const std::string t = error_of([&] { read_volume(dir.file("t.nii")); });
    EXPECT_NE(t.find("voxel data: truncated"), std::string::npos) << t;
    test::write_bytes(dir.file("t.nii.gz"), test::gzip(bytes));
    const std::string tz = error_of([&] { read_volume(dir.file("t.nii.gz")); });
    EXPECT_NE(tz.find("truncated: expected 96 bytes of RGBA32 voxels"), std::string::npos) << tz;
    // A vector dimension beside RGB is not a volume.
    NiftiSpec vec;
    vec.ndim = 5;
    vec.dim5 = 3;
    const std::string ve = error_of([&] {
        read_volume(write_rgb(dir, "v.nii", 3, {3, 4, 2}, vec));
    });
    EXPECT_NE(ve.find("dims: expected a scalar image, got 3 components"), std::string::npos) << ve;
    for (const std::string& e : {t, tz, ve}) EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_EQ(error_of([] { parse_rgb_opacity("luma"); }),
              "--rgb-opacity: rgb opacity: expected one of: luminance, r, g, b, a; got 'luma'");
}

TEST(RgbVolume, FramesOfA4dRgbFile) {
    ScratchDir dir;
    NiftiSpec s;
    s.ndim = 4;
    s.dim4 = 2;
    s.dims = {2, 2, 2};
    s.datatype = 128;
    std::vector<uint8_t> bytes(2 * 8 * 3);
    for (size_t n = 0; n < bytes.size(); ++n) bytes[n] = uint8_t(n < 24 ? 10 : 200);
    test::write_bytes(dir.file("f.nii"), test::nifti_bytes(s, bytes.data(), bytes.size()));
    ReadOptions ro;
    ro.frame = 1;
    const Volume v = read_volume(dir.file("f.nii"), ro, RgbOpacity::G);
    ASSERT_TRUE(rgb_colours(v));
    EXPECT_EQ(v.data_as<uint8_t>()[0], 200);
    EXPECT_EQ(rgb_colours(v)->rgba[0], 200);
}

// The colours die with the buffer: a later volume at any address is scalar, a copy shares them.
TEST(RgbVolume, ColoursFollowTheBuffer) {
    ScratchDir dir;
    const std::string path = write_rgb(dir, "c.nii", 3);
    const void* old = nullptr;
    {
        const Volume v = read_volume(path);
        const Volume copy = v;
        EXPECT_EQ(rgb_colours(copy), rgb_colours(v));
        old = v.data();
    }
    for (int n = 0; n < 8; ++n) {
        const Volume s(Vec3i{3, 4, 2}, VoxelType::Float32);
        if (s.data() == old) SUCCEED() << "the old address was reused";
        EXPECT_EQ(rgb_colours(s), nullptr);
    }
}

}  // namespace
}  // namespace lacuna
