// ValueToLut: the one value -> LUT entry map shared by renderers and skipping structures.
#include <gtest/gtest.h>

#include <cmath>

#include "lacuna/transfer_function.h"

namespace lacuna {
namespace {

const ValueRange kRanges[] = {
    {0.f, 255.f}, {-1024.f, 3071.f}, {-1.f, 1.f}, {0.f, 65535.f}, {1000.f, 1000.5f}};

TEST(LutMapping, MapsVisRangeEndsToFirstAndLastEntry) {
    for (const ValueRange& vis : kRanges) {
        for (int size : {2, 256, kDefaultLutSize, 4096}) {
            const ValueToLut map(vis, size);
            EXPECT_EQ(map.size(), size);
            EXPECT_EQ(map(vis.min), 0) << vis.min << ".." << vis.max << " size " << size;
            EXPECT_EQ(map(vis.max), size - 1) << vis.min << ".." << vis.max << " size " << size;
        }
    }
}

TEST(LutMapping, ClampsValuesOutsideVisRange) {
    const ValueToLut map({0.f, 255.f}, kDefaultLutSize);
    EXPECT_EQ(map(-1e30f), 0);
    EXPECT_EQ(map(-1.f), 0);
    EXPECT_EQ(map(256.f), kDefaultLutSize - 1);
    EXPECT_EQ(map(1e30f), kDefaultLutSize - 1);
}

TEST(LutMapping, IsMonotoneInValue) {
    for (const ValueRange& vis : kRanges) {
        const ValueToLut map(vis, kDefaultLutSize);
        const float lo = vis.min - 0.1f * vis.width(), hi = vis.max + 0.1f * vis.width();
        const int steps = 100000;
        int prev = map(lo);
        for (int i = 1; i <= steps; ++i) {
            const float v = lo + (hi - lo) * float(i) / float(steps);
            const int idx = map(v);
            ASSERT_GE(idx, prev) << "v " << v << " range " << vis.min << ".." << vis.max;
            prev = idx;
        }
        // And on consecutive floats around an entry boundary.
        float v = vis.min + 0.5f * vis.width();
        prev = map(v);
        for (int i = 0; i < 1000; ++i) {
            v = std::nextafter(v, hi);
            ASSERT_GE(map(v), prev);
            prev = map(v);
        }
    }
}

TEST(LutMapping, EntryPositionsMapToTheirOwnEntry) {
    // discretise() evaluates entry e at vis.min + e*(vis.max-vis.min)/(size-1); a sample with
    // exactly that value must read entry e.
    for (const ValueRange& vis : {ValueRange{0.f, 255.f}, ValueRange{-1024.f, 3071.f}}) {
        const ValueToLut map(vis, kDefaultLutSize);
        for (int e = 0; e < kDefaultLutSize; ++e) {
            const float v = float(vis.min + double(e) * vis.width() / (kDefaultLutSize - 1));
            EXPECT_EQ(map(v), e) << "v " << v;
        }
    }
}

TEST(LutMapping, TransferLutMapUsesItsOwnRange) {
    TransferFunction tf;
    tf.color = {{0.0, 1.f, 1.f, 1.f}};
    tf.opacity = {{0.0, 0.5f}};
    tf.range = ValueRange{10.f, 20.f};
    const TransferLut lut = discretise(tf, {0.f, 1000.f}, 11);
    const ValueToLut map = lut.map();
    EXPECT_EQ(map.size(), 11);
    EXPECT_EQ(map(10.f), 0);
    EXPECT_EQ(map(15.f), 5);
    EXPECT_EQ(map(20.f), 10);
}

}  // namespace
}  // namespace lacuna
