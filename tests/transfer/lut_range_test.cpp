// Issue 15, class 1: the value -> LUT map is total. Ranges too narrow for float's scale are
// rejected at every boundary with one line; ranges wider than float map exactly; a map built
// from any range at all still gives an entry in range for every finite value, monotonically.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "lacuna/error.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"
#include "render/ray_march_kernel.h"

namespace lacuna {
namespace {

constexpr float kMax = std::numeric_limits<float>::max();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kTiny = std::numeric_limits<float>::denorm_min();

// Finite values from -FLT_MAX to FLT_MAX: powers of ten of both signs, zeros, denormals.
std::vector<float> sweep() {
    std::vector<float> v{-kMax, -0.f, 0.f, kTiny, -kTiny, kMax, 1e-45f, 1e-40f, 1e-37f};
    for (int e = -45; e <= 38; ++e) {
        const float x = std::pow(10.f, float(e));
        if (std::isfinite(x)) v.insert(v.end(), {x, -x, 3.4f * x, -3.4f * x});
    }
    std::sort(v.begin(), v.end());
    return v;
}

std::string text(ValueRange r) {
    return std::to_string(r.min) + ".." + std::to_string(r.max);
}

TEST(LutRange, AnyRangeGivesAnEntryInRangeMonotonically) {
    // Ranges no boundary accepts (a map built elsewhere from them must still be total).
    const ValueRange ranges[] = {{0.f, 1e-45f}, {0.f, kTiny},    {5.f, 5.f},    {1.f, 0.f},
                                 {kNaN, 1.f},   {0.f, kNaN},     {-kInf, kInf}, {0.f, kInf},
                                 {-kMax, kMax}, {-3e38f, 3e38f}, {kMax, kMax},  {0.f, 1.f}};
    const std::vector<float> values = sweep();
    for (const ValueRange& r : ranges) {
        for (int size : {1, 2, kDefaultLutSize, 4096}) {
            const ValueToLut map(r, size);
            EXPECT_TRUE(std::isfinite(map.offset()) && std::isfinite(map.scale()) &&
                        map.scale() > 0.f)
                << text(r) << " offset " << map.offset() << " scale " << map.scale();
            int prev = 0;
            for (float v : values) {
                const int e = map(v);
                ASSERT_GE(e, 0) << text(r) << " v " << v;
                ASSERT_LT(e, std::max(size, 1)) << text(r) << " v " << v;
                ASSERT_GE(e, prev) << "not monotone: " << text(r) << " v " << v;
                prev = e;
            }
        }
    }
}

TEST(LutRange, RangesWiderThanFloatMapExactlyAtTheEnds) {
    // max - min overflows float; the scale comes from the width in double.
    for (const ValueRange r : {ValueRange{-kMax, kMax}, ValueRange{-3e38f, 3e38f}}) {
        ASSERT_TRUE(std::isinf(r.max - r.min));
        EXPECT_TRUE(lut_range_ok(r));
        const ValueToLut map(r, kDefaultLutSize);
        EXPECT_EQ(map(r.min), 0);
        EXPECT_EQ(map(r.max), kDefaultLutSize - 1);
        EXPECT_NEAR(map(0.f), (kDefaultLutSize - 1) / 2.0, 1.0);
    }
}

TEST(LutRange, UsableRangesKeepTheExactFormula) {
    // What every kernel evaluates: scale = float(size-1) / (max - min), in float, unchanged.
    for (const ValueRange r : {ValueRange{0.f, 255.f}, ValueRange{-1024.f, 3071.f},
                               ValueRange{1000.f, 1000.5f}, ValueRange{0.f, 1e-30f}}) {
        for (int size : {2, kDefaultLutSize, 4096}) {
            ASSERT_TRUE(lut_range_ok(r, size)) << text(r);
            const ValueToLut map(r, size);
            EXPECT_EQ(map.scale(), float(size - 1) / (r.max - r.min)) << text(r);
            EXPECT_EQ(map.offset(), r.min);
            EXPECT_EQ(map.last(), size - 1);
        }
    }
}

TEST(LutRange, TooNarrowRangesAreRejectedWithTheNarrowestWidth) {
    EXPECT_FALSE(lut_range_ok({0.f, 1e-45f}));
    EXPECT_FALSE(lut_range_ok({0.f, 1e-37f}));
    EXPECT_TRUE(lut_range_ok({0.f, 1e-35f}));
    EXPECT_FALSE(lut_range_ok({0.f, 1.f}, 1));
    try {
        check_lut_range({0.f, 1e-45f}, kDefaultLutSize, "tf.json", "range");
        FAIL() << "accepted";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.rfind("tf.json: range: ", 0), 0u) << m;
        EXPECT_NE(m.find("at least 3.01e-36 wide"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

TEST(LutRange, TfJsonRangeTooNarrowIsRejected) {
    const std::string tf = R"({"range": [0, 1e-45], "color": [[0, 1, 1, 1]], "opacity": [[0, 1]]})";
    try {
        parse_transfer_function(tf, "narrow.json");
        FAIL() << "accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("narrow.json: range:"), std::string::npos) << e.what();
    }
    // discretise() checks the range it is given as well.
    EXPECT_THROW(discretise(preset("mr-default"), {0.f, 1e-40f}), Error);
    EXPECT_NO_THROW(discretise(preset("mr-default"), {-3e38f, 3e38f}));
}

Volume float_volume(std::vector<float> values) {
    Volume v(Vec3i{2, 2, 2}, VoxelType::Float32, "test");
    for (size_t i = 0; i < 8; ++i) v.data_as<float>()[i] = values[i % values.size()];
    return v;
}

TEST(LutRange, FloatDataWiderThanFloatIsRejected) {
    // A lerp of -3e38 and 3e38 computes b - a = inf: the volume boundary refuses the data.
    Volume v = float_volume({-3e38f, 3e38f});
    try {
        v.compute_range("wide.nii");
        FAIL() << "accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("wide.nii: voxel values:"), std::string::npos)
            << e.what();
    }
    Volume ok = float_volume({-1.5e38f, 1.5e38f});
    EXPECT_NO_THROW(ok.compute_range("ok.nii"));
}

// fuzz_value_to_lut: corners of 1.16e38 and 3.4e38 lerped at z = 1 rounded one ulp past 3.4e38,
// an inf sample. The boundary refuses non-constant float data beyond 2^127, and every sample of
// data up to it, corners at both ends, is finite.
TEST(LutRange, FloatDataWithinAnUlpOfFloatsEndIsRejected) {
    Volume v = float_volume(
        {1.1630922e38f, 1.1630922e38f, 1.1630922e38f, 1.1630922e38f, kMax, kMax, kMax, kMax});
    try {
        v.compute_range("edge.nii");
        FAIL() << "accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("edge.nii: voxel values:"), std::string::npos)
            << e.what();
    }
    const float top = 0x1p127f;
    for (const std::vector<float>& corners : std::vector<std::vector<float>>{
             {top * 0.68f, top * 0.68f, top * 0.68f, top * 0.68f, top, top, top, top},
             {-1e7f, 1e-38f, top * 0.68f, 0.f, top, 0.f, top, 0.f},
             {top, 0.f, top, 0.f, top, 0.f, top, 0.f}}) {
        Volume ok = float_volume(corners);
        ASSERT_NO_THROW(ok.compute_range("ok.nii"));
        const auto grid = kernel::make_grid(ok.data_as<float>(), ok.dims());
        for (int a = 0; a <= 64; ++a)
            for (int b = 0; b <= 64; ++b)
                for (int c = 0; c <= 64; ++c) {
                    const float s = kernel::trilinear(grid, a / 64.f, b / 64.f, c / 64.f);
                    ASSERT_TRUE(std::isfinite(s)) << a << " " << b << " " << c;
                    ASSERT_LE(s, top * (1 + 0x1p-20f));
                }
    }
}

TEST(LutRange, NarrowOrConstantDataGetsAUsableDefaultRange) {
    // scl_slope 1e-40 turns 0..255 into 0..2.6e-38: the default range widens to [min, min+1].
    for (const std::vector<float>& vals : std::vector<std::vector<float>>{
             {0.f, 2.6e-38f}, {0.f, 1e-45f}, {7.f}, {1e30f}, {kMax}, {-kMax}}) {
        Volume v = float_volume(vals);
        v.compute_range("v");
        const ValueRange r = v.vis_range();
        EXPECT_TRUE(lut_range_ok(r)) << text(r);
        EXPECT_LE(r.min, v.data_range().min);
        EXPECT_GE(r.max, v.data_range().max);
    }
}

TEST(LutRange, SetVisRangeRejectsTooNarrowRanges) {
    Volume v = float_volume({0.f, 1.f});
    v.compute_range("v");
    EXPECT_THROW(v.set_vis_range({0.f, 1e-45f}), Error);
    EXPECT_THROW(v.set_vis_range({0.f, kInf}), Error);
    EXPECT_NO_THROW(v.set_vis_range({-3e38f, 3e38f}));
}

}  // namespace
}  // namespace lacuna
