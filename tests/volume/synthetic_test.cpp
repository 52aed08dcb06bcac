#include "lacuna/synthetic.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <set>
#include <string>
#include <utility>

#include "lacuna/error.h"

namespace lacuna {
namespace {

const SyntheticKind kAllKinds[] = {
    SyntheticKind::SphereShells,  SyntheticKind::MarschnerLobb, SyntheticKind::Tree,
    SyntheticKind::NoiseBlobs,    SyntheticKind::ThinSheets,    SyntheticKind::Checkerboard,
    SyntheticKind::BinBoundaries, SyntheticKind::Slab,          SyntheticKind::Sphere,
};
const VoxelType kAllTypes[] = {VoxelType::UInt8, VoxelType::Int16, VoxelType::UInt16,
                               VoxelType::Float32};

Volume make(SyntheticKind kind, Vec3i dims, VoxelType type = VoxelType::UInt8, uint32_t seed = 1,
            int threads = 0) {
    SyntheticOptions o;
    o.dims = dims;
    o.type = type;
    o.seed = seed;
    o.threads = threads;
    return generate(kind, o);
}

bool same_bytes(const Volume& a, const Volume& b) {
    return a.bytes() == b.bytes() && std::memcmp(a.data(), b.data(), a.bytes()) == 0;
}

std::string label(SyntheticKind k, VoxelType t, Vec3i d) {
    return to_string(k) + " " + to_string(t) + " " + to_string(d);
}

TEST(Synthetic, EveryKindAndTypeStaysInTheTypeRangeAtOddDims) {
    for (Vec3i dims : {Vec3i{33, 17, 25}, Vec3i{2, 2, 2}, Vec3i{3, 5, 2}}) {
        for (SyntheticKind k : kAllKinds) {
            for (VoxelType t : kAllTypes) {
                SCOPED_TRACE(label(k, t, dims));
                const Volume v = make(k, dims, t);
                const ValueRange want = synthetic_value_range(t);
                EXPECT_EQ(v.dims(), dims);
                EXPECT_EQ(v.type(), t);
                EXPECT_GE(v.data_range().min, want.min);
                EXPECT_LE(v.data_range().max, want.max);
                EXPECT_LE(v.data_range().min, v.data_range().max);
            }
        }
    }
}

TEST(Synthetic, EveryKindButMarschnerLobbSpansTheFullRangeAt33x17x25) {
    for (SyntheticKind k : kAllKinds) {
        if (k == SyntheticKind::MarschnerLobb) continue;  // sampled signal misses 0 and 1
        for (VoxelType t : kAllTypes) {
            SCOPED_TRACE(label(k, t, {33, 17, 25}));
            const Volume v = make(k, {33, 17, 25}, t);
            const ValueRange want = synthetic_value_range(t);
            EXPECT_EQ(v.data_range().min, want.min);
            EXPECT_EQ(v.data_range().max, want.max);
        }
    }
}

TEST(Synthetic, MarschnerLobbStaysWithinZeroToOneAndReachesOneOnTheAxisAtZMinusOne) {
    const Volume v = make(SyntheticKind::MarschnerLobb, {33, 17, 25}, VoxelType::Float32);
    EXPECT_GE(v.data_range().min, 0.f);
    EXPECT_LE(v.data_range().max, 1.f);
    // x = y = 0 at the middle voxel of odd axes, z = -1 at k = 0: rho = 1.
    EXPECT_NEAR(v.value(16, 8, 0), 1.f, 1e-6f);
}

TEST(Synthetic, RangeIsComputedBeforeReturning) {
    const Volume v = make(SyntheticKind::Sphere, {20, 20, 20}, VoxelType::Int16);
    EXPECT_EQ(v.data_range().min, -1024.f);
    EXPECT_EQ(v.data_range().max, 3071.f);
    EXPECT_EQ(v.vis_range().min, -1024.f);
    EXPECT_EQ(v.vis_range().max, 3071.f);
}

TEST(Synthetic, SameOptionsGiveIdenticalBytes) {
    for (SyntheticKind k : kAllKinds) {
        for (VoxelType t : {VoxelType::UInt8, VoxelType::Float32}) {
            SCOPED_TRACE(label(k, t, {37, 29, 41}));
            EXPECT_TRUE(same_bytes(make(k, {37, 29, 41}, t, 7), make(k, {37, 29, 41}, t, 7)));
        }
    }
}

TEST(Synthetic, BytesDoNotDependOnThreadCount) {
    for (SyntheticKind k : kAllKinds) {
        SCOPED_TRACE(to_string(k));
        const Volume one = make(k, {40, 31, 47}, VoxelType::UInt16, 3, 1);
        const Volume many = make(k, {40, 31, 47}, VoxelType::UInt16, 3, 2);
        EXPECT_TRUE(same_bytes(one, many));
    }
}

TEST(Synthetic, DifferentSeedsGiveDifferentTrees) {
    const Volume a = make(SyntheticKind::Tree, {48, 48, 48}, VoxelType::UInt8, 1);
    const Volume b = make(SyntheticKind::Tree, {48, 48, 48}, VoxelType::UInt8, 2);
    EXPECT_FALSE(same_bytes(a, b));
}

TEST(Synthetic, DifferentSeedsGiveDifferentNoiseBlobs) {
    const Volume a = make(SyntheticKind::NoiseBlobs, {48, 48, 48}, VoxelType::UInt8, 1);
    const Volume b = make(SyntheticKind::NoiseBlobs, {48, 48, 48}, VoxelType::UInt8, 2);
    EXPECT_FALSE(same_bytes(a, b));
}

TEST(Synthetic, MarschnerLobbMatchesTheAnalyticFunction) {
    // Hand-evaluated: at (0,0,0) rho_r(0) = cos(12 pi) = 1, so rho = (1 + 0.25 * 2) / 2.5.
    EXPECT_NEAR(marschner_lobb(0, 0, 0), 0.6f, 1e-6f);
    EXPECT_NEAR(marschner_lobb(0, 0, 1), 0.2f, 1e-6f);
    EXPECT_NEAR(marschner_lobb(0, 0, -1), 1.0f, 1e-6f);
    // r = 1: cos(pi/2) = 0, rho_r = cos(0) = 1 as well.
    EXPECT_NEAR(marschner_lobb(1, 0, 0), 0.6f, 1e-6f);
    // r = 2/3: cos(pi/3) = 1/2, rho_r = cos(6 pi) = 1; r with cos(pi r/2) = 1/12: rho_r = -1.
    EXPECT_NEAR(marschner_lobb(0, 2.f / 3.f, 0), 0.6f, 1e-5f);
    const float r_min = float(2.0 / std::numbers::pi * std::acos(1.0 / 12.0));
    EXPECT_NEAR(marschner_lobb(r_min, 0, 0), 0.4f, 1e-5f);

    const Vec3i d{33, 17, 25};
    const Volume f = make(SyntheticKind::MarschnerLobb, d, VoxelType::Float32);
    const Volume u = make(SyntheticKind::MarschnerLobb, d, VoxelType::UInt16);
    auto coord = [](int i, int n) { return -1.f + 2.f * float(i) / float(n - 1); };
    for (int k = 0; k < d.z; k += 3)
        for (int j = 0; j < d.y; j += 2)
            for (int i = 0; i < d.x; i += 5) {
                const float want = marschner_lobb(coord(i, d.x), coord(j, d.y), coord(k, d.z));
                ASSERT_EQ(f.value(i, j, k), want) << i << "," << j << "," << k;
                ASSERT_NEAR(u.value(i, j, k), want * 65535.f, 0.5f + 1e-2f);
            }
}

TEST(Synthetic, SphereVoxelsAreInsideExactlyWhenWithinTheDocumentedRadius) {
    const Vec3i d{33, 17, 25};
    const Volume v = make(SyntheticKind::Sphere, d, VoxelType::UInt8);
    const double cx = (d.x - 1) / 2.0, cy = (d.y - 1) / 2.0, cz = (d.z - 1) / 2.0;
    const double r = 0.35 * (std::min({d.x, d.y, d.z}) - 1);
    int inside = 0;
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const double d2 = (i - cx) * (i - cx) + (j - cy) * (j - cy) + (k - cz) * (k - cz);
                const bool in = d2 <= r * r;
                inside += in;
                ASSERT_EQ(v.value(i, j, k), in ? 255.f : 0.f) << i << "," << j << "," << k;
            }
    // r = 5.6 voxels: roughly 4/3 pi r^3 = 735 voxels.
    EXPECT_NEAR(inside, 735, 60);
}

TEST(Synthetic, SlabCoversExactlyTheDocumentedSlices) {
    const Vec3i d{9, 6, 30};  // z0 = 7, z1 = 22
    const Volume v = make(SyntheticKind::Slab, d, VoxelType::Float32);
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i)
                ASSERT_EQ(v.value(i, j, k), (k >= 7 && k <= 22) ? 1.f : 0.f) << k;
    const Volume w = make(SyntheticKind::Slab, {64, 64, 64}, VoxelType::UInt8);
    EXPECT_EQ(w.value(0, 0, 15), 0.f);
    EXPECT_EQ(w.value(63, 63, 16), 255.f);
    EXPECT_EQ(w.value(5, 9, 48), 255.f);
    EXPECT_EQ(w.value(5, 9, 49), 0.f);
}

TEST(Synthetic, TreeLeavesMoreThanNinetyPercentOfVoxelsEmpty) {
    const std::pair<int, uint32_t> cases[] = {{64, 1}, {64, 2}, {64, 3},  {64, 4},
                                              {64, 5}, {64, 6}, {128, 7}, {128, 8}};
    for (auto [n, seed] : cases) {
        SCOPED_TRACE(std::to_string(n) + "^3 seed " + std::to_string(seed));
        const Volume v = make(SyntheticKind::Tree, {n, n, n}, VoxelType::UInt8, seed);
        const uint8_t* p = v.data_as<uint8_t>();
        size_t zeros = 0;
        for (size_t i = 0; i < v.voxel_count(); ++i) zeros += p[i] == 0;
        const double frac = double(zeros) / double(v.voxel_count());
        EXPECT_GT(frac, 0.90);
        EXPECT_LT(frac, 0.995);  // and it is not empty either
        EXPECT_EQ(v.data_range().max, 255.f);
    }
}

TEST(Synthetic, TreeTrunkStandsOnTheBottomCentre) {
    const Volume v = make(SyntheticKind::Tree, {64, 64, 64}, VoxelType::Float32, 9);
    EXPECT_EQ(v.value(31, 31, 0), 1.f);
    EXPECT_EQ(v.value(0, 0, 0), 0.f);
    EXPECT_EQ(v.value(63, 63, 0), 0.f);
}

TEST(Synthetic, NoiseBlobsAreExactlyZeroAtTheCorners) {
    const Vec3i d{40, 30, 50};
    const Volume v = make(SyntheticKind::NoiseBlobs, d, VoxelType::Float32, 11);
    for (int c = 0; c < 8; ++c)
        EXPECT_EQ(v.value(c & 1 ? d.x - 1 : 0, c & 2 ? d.y - 1 : 0, c & 4 ? d.z - 1 : 0), 0.f);
    EXPECT_EQ(v.data_range().max, 1.f);
}

TEST(Synthetic, CheckerboardNeighboursDiffer) {
    const Vec3i d{7, 6, 5};
    const Volume v = make(SyntheticKind::Checkerboard, d, VoxelType::Int16);
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const float x = v.value(i, j, k);
                ASSERT_TRUE(x == -1024.f || x == 3071.f);
                if (i + 1 < d.x) {
                    ASSERT_NE(x, v.value(i + 1, j, k));
                }
                if (j + 1 < d.y) {
                    ASSERT_NE(x, v.value(i, j + 1, k));
                }
                if (k + 1 < d.z) {
                    ASSERT_NE(x, v.value(i, j, k + 1));
                }
            }
    EXPECT_EQ(v.value(0, 0, 0), -1024.f);
}

TEST(Synthetic, ThinSheetsAreOneVoxelThin) {
    const Vec3i d{30, 20, 24};  // planes i = 10, j = 10, k = 16, i = j, i + j + k = 35
    const Volume v = make(SyntheticKind::ThinSheets, d, VoxelType::UInt8);
    EXPECT_EQ(v.value(10, 3, 2), 255.f);
    EXPECT_EQ(v.value(3, 10, 2), 255.f);
    EXPECT_EQ(v.value(25, 3, 16), 255.f);
    EXPECT_EQ(v.value(4, 4, 1), 255.f);
    EXPECT_EQ(v.value(20, 12, 3), 255.f);
    EXPECT_EQ(v.value(20, 12, 4), 0.f);
    EXPECT_EQ(v.value(11, 3, 2), 0.f);
    EXPECT_EQ(v.value(25, 3, 15), 0.f);
}

TEST(Synthetic, BinBoundariesPlacesValuesAroundEveryEighthOfTheRange) {
    const Volume v = make(SyntheticKind::BinBoundaries, {128, 128, 64}, VoxelType::UInt16);
    std::set<int> values;
    const uint16_t* p = v.data_as<uint16_t>();
    for (size_t i = 0; i < v.voxel_count(); ++i) values.insert(p[i]);
    EXPECT_TRUE(values.count(0));
    EXPECT_TRUE(values.count(65535));
    for (int k = 1; k < 8; ++k) {
        const int b = int(std::lround(k * 65535.0 / 8));
        EXPECT_TRUE(values.count(b - 1) && values.count(b) && values.count(b + 1)) << k;
    }
    // LUT entry boundary between entries 511 and 512: (511.5 / 1023) * 65535.
    const int lut = int(std::lround(511.5 * 65535.0 / 1023));
    EXPECT_TRUE(values.count(lut - 1) && values.count(lut) && values.count(lut + 1));

    const Volume f = make(SyntheticKind::BinBoundaries, {128, 128, 64}, VoxelType::Float32);
    std::set<float> fv(f.data_as<float>(), f.data_as<float>() + f.voxel_count());
    EXPECT_TRUE(fv.count(0.5f) && fv.count(std::nextafter(0.5f, 0.f)) &&
                fv.count(std::nextafter(0.5f, 1.f)));
    EXPECT_TRUE(fv.count(3.f / 128.f));
}

TEST(Synthetic, KindNamesRoundTrip) {
    const auto names = synthetic_kind_names();
    EXPECT_EQ(names.size(), std::size(kAllKinds));
    for (SyntheticKind k : kAllKinds) EXPECT_EQ(parse_synthetic_kind(to_string(k)), k);
    EXPECT_EQ(parse_synthetic_kind("marschner-lobb"), SyntheticKind::MarschnerLobb);
}

TEST(Synthetic, UnknownKindThrowsWithTheValidNames) {
    try {
        parse_synthetic_kind("spheres");
        FAIL() << "expected lacuna::Error";
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("generate: kind: unknown 'spheres'"), std::string::npos) << msg;
        EXPECT_NE(msg.find("expected one of: sphere-shells,"), std::string::npos) << msg;
        EXPECT_NE(msg.find("sphere"), std::string::npos) << msg;
    }
    EXPECT_THROW(parse_synthetic_kind(""), Error);
    EXPECT_THROW(parse_synthetic_kind("Tree"), Error);
}

TEST(Synthetic, RejectsDimsBelowTwo) {
    EXPECT_THROW(make(SyntheticKind::Sphere, {1, 8, 8}), Error);
}

}  // namespace
}  // namespace lacuna
