// DICOM series geometry (issue 14): a series written by lacuna reads back to the same world, and
// a slice whose ImagePositionPatient leaves the line of the slice normal (a sheared or tilted
// stack: no rigid index-to-world map) is one line naming the folder and the slice.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "io/io_test_util.h"
#include "lacuna/io.h"
#include "lacuna/orientation.h"

namespace lacuna {
namespace {

// Offset of the value of element (0020,0032) ImagePositionPatient in a little-endian file
// (explicit VR "DS" + 2-byte length, or implicit VR: a 4-byte length), or npos.
size_t ipp_value(const std::vector<uint8_t>& f, uint32_t& length) {
    const uint8_t tag[4] = {0x20, 0x00, 0x32, 0x00};
    for (size_t i = 132; i + 8 < f.size(); ++i) {
        if (std::memcmp(&f[i], tag, 4) != 0) continue;
        if (f[i + 4] == 'D' && f[i + 5] == 'S') {
            length = uint32_t(f[i + 6] | (f[i + 7] << 8));
        } else {
            length = uint32_t(f[i + 4] | (f[i + 5] << 8) | (f[i + 6] << 16) |
                              (uint32_t(f[i + 7]) << 24));
        }
        if (length < 5 || i + 8 + length > f.size()) continue;
        return i + 8;
    }
    return std::string::npos;
}

TEST(DicomOrientation, AWrittenSeriesKeepsItsWorldFrame) {
    test::ScratchDir dir;
    Volume v = test::pattern_volume({8, 7, 5}, VoxelType::Int16);
    v.spacing = {0.5, 0.75, 2};
    // LPI storage: i toward the left, j posterior, k inferior; origin somewhere else.
    const double lpi[9] = {1, 0, 0, 0, 1, 0, 0, 0, -1};
    for (int i = 0; i < 9; ++i) v.direction[i] = lpi[i];
    v.origin = {12, -30, 40};
    write_volume(dir.file("s") + "/", v);
    const Volume r = read_volume(dir.file("s"));
    EXPECT_NE(r.geometry_source.find("DICOM"), std::string::npos) << r.geometry_source;
    const Box3f a = world_bounds(r), b = world_bounds(v);
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(a.lo[i], b.lo[i], 1e-4) << i;
        EXPECT_NEAR(a.hi[i], b.hi[i], 1e-4) << i;
    }
    // The voxel at a world position holds the same value (GDCM may have reversed the slices).
    const Affine ra = index_to_world(r), va = index_to_world(v);
    const Vec3d w = va.apply({2, 3, 1});
    const int k = int(std::lround((w.z - ra.t[2]) / ra.m[2][2]));
    EXPECT_EQ(r.value(2, 3, k), v.value(2, 3, 1));
}

TEST(DicomOrientation, ASliceOffTheNormalIsContradictorySlicePositions) {
    test::ScratchDir dir;
    const Volume v = test::pattern_volume({8, 8, 5}, VoxelType::Int16);
    write_volume(dir.file("s") + "/", v);
    ASSERT_NO_THROW(read_volume(dir.file("s")));
    // Move slice 3 sideways: the leading digit of its x position changes (same length, so the
    // file stays well formed), its position along the normal (z) is unchanged.
    const std::string victim = dir.file("s/slice_00003.dcm");
    std::vector<uint8_t> f = test::file_bytes(victim);
    uint32_t len = 0;
    const size_t at = ipp_value(f, len);
    ASSERT_NE(at, std::string::npos) << "no ImagePositionPatient in the written slice";
    size_t digit = at;
    while (digit < at + len && !(f[digit] >= '0' && f[digit] <= '9')) ++digit;
    ASSERT_LT(digit, at + len) << std::string(f.begin() + long(at), f.begin() + long(at + len));
    f[digit] = f[digit] == '9' ? '1' : '9';
    test::write_bytes(victim, f);
    try {
        read_volume(dir.file("s"));
        ADD_FAILURE() << "a sheared stack was accepted";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("slice_00003.dcm: ImagePositionPatient is "), std::string::npos) << m;
        EXPECT_NE(m.find("mm off the slice normal through slice_00000.dcm"), std::string::npos)
            << m;
        EXPECT_NE(m.find("contradictory slice positions"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

}  // namespace
}  // namespace lacuna
