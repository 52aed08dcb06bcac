// Discretisation and interpolation of transfer functions against hand-computed values.
#include "lacuna/transfer_function.h"

#include <gtest/gtest.h>

#include <cmath>

#include "lacuna/error.h"

namespace lacuna {
namespace {

TransferFunction opacity_only(std::vector<OpacityPoint> opacity,
                              TfDomain domain = TfDomain::Normalized) {
    TransferFunction tf;
    tf.name = "test";
    tf.domain = domain;
    tf.color = {{0.0, 1.f, 1.f, 1.f}};
    tf.opacity = std::move(opacity);
    return tf;
}

// Entry e of a `size`-entry LUT sits at t = e/(size-1) across the visualization range.
double entry_t(int e, int size) {
    return double(e) / double(size - 1);
}

TEST(TransferFunction, DiscretisesLinearRampExactly) {
    TransferFunction tf;
    tf.color = {{0.0, 0.f, 0.f, 0.f}, {1.0, 1.f, 0.5f, 0.25f}};
    tf.opacity = {{0.0, 0.f}, {1.0, 1.f}};
    // Five entries at t = 0, 1/4, 1/2, 3/4, 1: every product below is exact in binary.
    const TransferLut lut = discretise(tf, {0.f, 4.f}, 5);
    ASSERT_EQ(lut.size(), 5);
    for (int e = 0; e < 5; ++e) {
        const float t = float(e) / 4.f;
        EXPECT_EQ(lut.entries[e], (Rgba{t, 0.5f * t, 0.25f * t, t})) << "entry " << e;
    }
    EXPECT_EQ(lut.vis.min, 0.f);
    EXPECT_EQ(lut.vis.max, 4.f);
}

TEST(TransferFunction, MatchesControlPointsAndMidpoints) {
    const TransferFunction tf = opacity_only({{0.25, 0.2f}, {0.5, 0.8f}, {0.75, 0.4f}});
    // size 9: entry e at t = e/8, so entries 2, 4, 6 sit on the points and 3, 5 halfway.
    const TransferLut lut = discretise(tf, {0.f, 1.f}, 9);
    EXPECT_EQ(lut.entries[2].a, 0.2f);
    EXPECT_FLOAT_EQ(lut.entries[3].a, 0.5f);
    EXPECT_EQ(lut.entries[4].a, 0.8f);
    EXPECT_FLOAT_EQ(lut.entries[5].a, 0.6f);
    EXPECT_EQ(lut.entries[6].a, 0.4f);
}

TEST(TransferFunction, ClampsToEndValuesOutsideFirstAndLastPoint) {
    TransferFunction tf = opacity_only({{0.25, 0.2f}, {0.75, 0.4f}});
    tf.color = {{0.25, 0.1f, 0.2f, 0.3f}, {0.75, 0.7f, 0.8f, 0.9f}};
    const TransferLut lut = discretise(tf, {0.f, 1.f}, 9);
    for (int e : {0, 1, 2}) {
        EXPECT_EQ(lut.entries[e], (Rgba{0.1f, 0.2f, 0.3f, 0.2f})) << "entry " << e;
    }
    for (int e : {6, 7, 8}) {
        EXPECT_EQ(lut.entries[e], (Rgba{0.7f, 0.8f, 0.9f, 0.4f})) << "entry " << e;
    }
}

TEST(TransferFunction, SinglePointIsConstant) {
    const TransferLut lut = discretise(opacity_only({{0.3, 0.25f}}), {0.f, 1.f}, 16);
    for (const Rgba& c : lut.entries) EXPECT_EQ(c, (Rgba{1.f, 1.f, 1.f, 0.25f}));
}

TEST(TransferFunction, ZeroOpacityBetweenZeroPointsIsExactlyZero) {
    const TransferFunction tf =
        opacity_only({{0.0, 0.f}, {0.3, 0.f}, {0.45, 0.7f}, {0.6, 0.f}, {1.0, 0.f}});
    const int size = kDefaultLutSize;
    const TransferLut lut = discretise(tf, {-3.7f, 1234.5f}, size);
    for (int e = 0; e < size; ++e) {
        const double t = entry_t(e, size);
        if (t <= 0.3 || t >= 0.6)
            EXPECT_EQ(lut.entries[e].a, 0.0f) << "entry " << e << " t " << t;
        else
            EXPECT_GT(lut.entries[e].a, 0.0f) << "entry " << e << " t " << t;
    }
}

TEST(TransferFunction, SinglePeakIsNonzeroOnlyNearIt) {
    const TransferFunction tf =
        opacity_only({{0.0, 0.f}, {0.49, 0.f}, {0.5, 1.f}, {0.51, 0.f}, {1.0, 0.f}});
    const int size = kDefaultLutSize;
    const TransferLut lut = discretise(tf, {0.f, 255.f}, size);
    int nonzero = 0;
    for (int e = 0; e < size; ++e) {
        if (lut.entries[e].a == 0.0f) continue;
        ++nonzero;
        EXPECT_LT(std::abs(entry_t(e, size) - 0.5), 0.01) << "entry " << e;
    }
    // 0.02 of 1023 entries is ~20 wide.
    EXPECT_GE(nonzero, 18);
    EXPECT_LE(nonzero, 21);
}

TEST(TransferFunction, StepIsRightContinuous) {
    const TransferFunction tf = opacity_only({{0.0, 0.f}, {0.5, 0.f}, {0.5, 0.6f}, {1.0, 0.6f}});
    const TransferLut lut = discretise(tf, {0.f, 1.f}, 5);
    EXPECT_EQ(lut.entries[0].a, 0.f);
    EXPECT_EQ(lut.entries[1].a, 0.f);
    EXPECT_EQ(lut.entries[2].a, 0.6f);  // t = 0.5 exactly: the step's right-hand value
    EXPECT_EQ(lut.entries[3].a, 0.6f);
    EXPECT_EQ(lut.entries[4].a, 0.6f);
}

TEST(TransferFunction, ValueDomainMatchesNormalizedDomainOverSameRange) {
    const ValueRange vis{100.f, 1100.f};
    TransferFunction norm = opacity_only({{0.0, 0.f},
                                          {0.125, 0.f},
                                          {0.25, 0.5f},
                                          {0.4, 0.1f},
                                          {0.5, 0.f},
                                          {0.75, 0.f},
                                          {1.0, 0.9f}});
    norm.color = {{0.1, 0.2f, 0.4f, 0.6f}, {0.8, 1.f, 0.5f, 0.f}};
    TransferFunction value = norm;
    value.domain = TfDomain::Value;
    for (auto& p : value.opacity) p.x = vis.min + p.x * vis.width();
    for (auto& p : value.color) p.x = vis.min + p.x * vis.width();

    const TransferLut a = discretise(norm, vis, kDefaultLutSize);
    const TransferLut b = discretise(value, vis, kDefaultLutSize);
    ASSERT_EQ(a.size(), b.size());
    for (int e = 0; e < a.size(); ++e) {
        EXPECT_NEAR(a.entries[e].a, b.entries[e].a, 1e-6) << "entry " << e;
        EXPECT_NEAR(a.entries[e].r, b.entries[e].r, 1e-6) << "entry " << e;
        EXPECT_NEAR(a.entries[e].g, b.entries[e].g, 1e-6) << "entry " << e;
        EXPECT_NEAR(a.entries[e].b, b.entries[e].b, 1e-6) << "entry " << e;
        // Which entries are empty must agree exactly: skipping depends on it.
        EXPECT_EQ(a.entries[e].a == 0.f, b.entries[e].a == 0.f) << "entry " << e;
    }
}

TEST(TransferFunction, RangeCarriedByTfOverridesVolumeRange) {
    TransferFunction tf = opacity_only({{0.0, 0.f}, {10.0, 1.f}}, TfDomain::Value);
    tf.range = ValueRange{0.f, 10.f};
    const TransferLut lut = discretise(tf, {-500.f, 500.f}, 11);
    EXPECT_EQ(lut.vis.min, 0.f);
    EXPECT_EQ(lut.vis.max, 10.f);
    for (int e = 0; e <= 10; ++e) EXPECT_FLOAT_EQ(lut.entries[e].a, float(e) / 10.f);
}

TEST(TransferFunction, ValueDomainSamplesAtValuesAcrossVisRange) {
    // Values 0..255 over 256 entries: entry e sits at value e.
    const TransferFunction tf =
        opacity_only({{0.0, 0.f}, {64.0, 0.f}, {128.0, 0.5f}, {255.0, 0.5f}}, TfDomain::Value);
    const TransferLut lut = discretise(tf, {0.f, 255.f}, 256);
    EXPECT_EQ(lut.entries[64].a, 0.f);
    EXPECT_FLOAT_EQ(lut.entries[96].a, 0.25f);
    EXPECT_EQ(lut.entries[128].a, 0.5f);
    EXPECT_EQ(lut.entries[255].a, 0.5f);
}

TEST(TransferFunction, RejectsLutSizeBelowTwo) {
    const TransferFunction tf = opacity_only({{0.0, 0.5f}});
    EXPECT_THROW(discretise(tf, {0.f, 1.f}, 1), Error);
    EXPECT_THROW(discretise(tf, {0.f, 1.f}, 0), Error);
    EXPECT_NO_THROW(discretise(tf, {0.f, 1.f}, 2));
}

TEST(TransferFunction, RejectsEmptyVisRange) {
    const TransferFunction tf = opacity_only({{0.0, 0.5f}});
    EXPECT_THROW(discretise(tf, {1.f, 1.f}, 16), Error);
    EXPECT_THROW(discretise(tf, {2.f, 1.f}, 16), Error);
    EXPECT_THROW(discretise(tf, {0.f, NAN}, 16), Error);
}

TEST(TransferFunction, RejectsMalformedInMemoryTf) {
    EXPECT_THROW(discretise(opacity_only({}), {0.f, 1.f}, 16), Error);
    EXPECT_THROW(discretise(opacity_only({{0.5, 0.f}, {0.2, 0.f}}), {0.f, 1.f}, 16), Error);
    EXPECT_THROW(discretise(opacity_only({{0.5, 1.5f}}), {0.f, 1.f}, 16), Error);
    EXPECT_THROW(discretise(opacity_only({{1.5, 0.5f}}), {0.f, 1.f}, 16), Error);
    EXPECT_THROW(discretise(opacity_only({{0.5, 0.f}, {0.5, 0.f}, {0.5, 1.f}}), {0.f, 1.f}, 16),
                 Error);
    TransferFunction no_color = opacity_only({{0.5, 0.5f}});
    no_color.color.clear();
    EXPECT_THROW(discretise(no_color, {0.f, 1.f}, 16), Error);
}

TEST(TransferFunction, ToStringNamesEveryField) {
    TransferFunction tf = opacity_only({{0.0, 0.f}, {1.0, 0.5f}});
    tf.range = ValueRange{-1.f, 2.5f};
    const std::string s = to_string(tf);
    EXPECT_NE(s.find("test"), std::string::npos) << s;
    EXPECT_NE(s.find("normalized"), std::string::npos) << s;
    EXPECT_NE(s.find("[-1, 2.5]"), std::string::npos) << s;
    EXPECT_NE(s.find("[1, 0.5]"), std::string::npos) << s;
    EXPECT_EQ(s.find('\n'), std::string::npos) << s;
    EXPECT_EQ(to_string(TfDomain::Value), "value");
    EXPECT_EQ(to_string(Rgba{0.f, 0.25f, 0.5f, 1.f}), "Rgba{0, 0.25, 0.5, 1}");
}

// --- lerp (bitfield paper, Section 4.5) -------------------------------------------------------

void expect_luts_near(const TransferLut& a, const TransferLut& b, double tol) {
    ASSERT_EQ(a.size(), b.size());
    for (int e = 0; e < a.size(); ++e) {
        EXPECT_NEAR(a.entries[e].r, b.entries[e].r, tol) << "entry " << e;
        EXPECT_NEAR(a.entries[e].g, b.entries[e].g, tol) << "entry " << e;
        EXPECT_NEAR(a.entries[e].b, b.entries[e].b, tol) << "entry " << e;
        EXPECT_NEAR(a.entries[e].a, b.entries[e].a, tol) << "entry " << e;
        EXPECT_EQ(a.entries[e].a == 0.f, b.entries[e].a == 0.f) << "entry " << e;
    }
}

TEST(TransferLerp, EndpointsEqualInputs) {
    const TransferFunction a = preset("mr-gap");
    const TransferFunction b = preset("mr-brain");
    const ValueRange vis{0.f, 255.f};
    expect_luts_near(discretise(lerp(a, b, 0.f), vis), discretise(a, vis), 1e-6);
    expect_luts_near(discretise(lerp(a, b, 1.f), vis), discretise(b, vis), 1e-6);
    // On a's own breakpoints the w=0 blend reproduces a's values bit for bit.
    const TransferFunction l0 = lerp(a, b, 0.f);
    for (const OpacityPoint& p : a.opacity) {
        bool found = false;
        for (const OpacityPoint& q : l0.opacity) found |= (q == p);
        EXPECT_TRUE(found) << "point x=" << p.x << " a=" << p.a;
    }
    EXPECT_EQ(l0.name, a.name);
}

TEST(TransferLerp, MidpointIsAverage) {
    const TransferFunction a = preset("ct-bone");
    const TransferFunction b = preset("ct-soft-tissue");
    const ValueRange vis{-1024.f, 3071.f};
    const TransferLut la = discretise(a, vis), lb = discretise(b, vis);
    const TransferLut mid = discretise(lerp(a, b, 0.5f), vis);
    for (int e = 0; e < mid.size(); ++e) {
        EXPECT_NEAR(mid.entries[e].a, 0.5f * (la.entries[e].a + lb.entries[e].a), 1e-6);
        EXPECT_NEAR(mid.entries[e].r, 0.5f * (la.entries[e].r + lb.entries[e].r), 1e-6);
        EXPECT_NEAR(mid.entries[e].g, 0.5f * (la.entries[e].g + lb.entries[e].g), 1e-6);
        EXPECT_NEAR(mid.entries[e].b, 0.5f * (la.entries[e].b + lb.entries[e].b), 1e-6);
    }
}

TEST(TransferLerp, KeepsZeroWhereBothInputsAreZero) {
    const TransferFunction a = opacity_only({{0.0, 0.f}, {0.4, 0.f}, {0.5, 1.f}, {1.0, 1.f}});
    const TransferFunction b = opacity_only({{0.0, 0.f}, {0.6, 0.f}, {0.7, 0.5f}, {1.0, 0.f}});
    const int size = kDefaultLutSize;
    const TransferLut la = discretise(a, {0.f, 1.f}, size), lb = discretise(b, {0.f, 1.f}, size);
    const TransferLut mid = discretise(lerp(a, b, 0.3f), {0.f, 1.f}, size);
    for (int e = 0; e < size; ++e) {
        const bool both_zero = la.entries[e].a == 0.f && lb.entries[e].a == 0.f;
        EXPECT_EQ(mid.entries[e].a == 0.f, both_zero) << "entry " << e;
    }
}

TEST(TransferLerp, KeepsStepsOfEitherInput) {
    const TransferFunction a = opacity_only({{0.0, 0.f}, {0.5, 0.f}, {0.5, 0.8f}, {1.0, 0.8f}});
    const TransferFunction b = opacity_only({{0.0, 0.4f}});
    const TransferLut lut = discretise(lerp(a, b, 0.5f), {0.f, 1.f}, 5);
    EXPECT_FLOAT_EQ(lut.entries[1].a, 0.2f);  // left of the step: (0 + 0.4)/2
    EXPECT_FLOAT_EQ(lut.entries[2].a, 0.6f);  // at and right of it: (0.8 + 0.4)/2
    EXPECT_FLOAT_EQ(lut.entries[4].a, 0.6f);
}

TEST(TransferLerp, BlendsRangesWhenBothCarryOne) {
    TransferFunction a = opacity_only({{0.0, 0.5f}}), b = a;
    a.range = ValueRange{0.f, 100.f};
    b.range = ValueRange{100.f, 300.f};
    const TransferFunction m = lerp(a, b, 0.5f);
    ASSERT_TRUE(m.range.has_value());
    EXPECT_EQ(m.range->min, 50.f);
    EXPECT_EQ(m.range->max, 200.f);
    b.range.reset();
    EXPECT_THROW(lerp(a, b, 0.5f), Error);
}

TEST(TransferLerp, RejectsMismatchedDomains) {
    const TransferFunction a = opacity_only({{0.0, 0.5f}});
    const TransferFunction b = opacity_only({{0.0, 0.5f}}, TfDomain::Value);
    EXPECT_THROW(lerp(a, b, 0.5f), Error);
}

TEST(TransferLerp, RejectsWeightOutsideUnitInterval) {
    const TransferFunction a = opacity_only({{0.0, 0.5f}});
    EXPECT_THROW(lerp(a, a, -0.1f), Error);
    EXPECT_THROW(lerp(a, a, 1.5f), Error);
    EXPECT_THROW(lerp(a, a, NAN), Error);
}

}  // namespace
}  // namespace lacuna
