// Evaluation of piecewise-linear control-point lists (ColorPoint / OpacityPoint), shared by
// discretise() and lerp().
//
// Semantics (docs/transfer-functions.md):
//   - between two points the value is linear in x;
//   - left of the first point and right of the last one the end values hold (VTK clamping);
//   - two points with the same x form a step; the function is right-continuous there: at x
//     itself and to its right it has the second point's value, just left of x the first's.
//
// Exactness: mix() returns an endpoint bit-for-bit when the two endpoints are equal or when
// t is 0 or 1, so a segment between two a=0 points evaluates to exactly 0.0f. Empty-space
// skipping relies on this: "opacity is zero" must be a property of the LUT, with no float dust.
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "lacuna/transfer_function.h"

namespace lacuna::tf_detail {

template <size_t N>
using Values = std::array<float, N>;

inline Values<3> values_of(const ColorPoint& p) {
    return {p.r, p.g, p.b};
}
inline Values<1> values_of(const OpacityPoint& p) {
    return {p.a};
}
inline ColorPoint make_point(double x, const Values<3>& v, const ColorPoint*) {
    return {x, v[0], v[1], v[2]};
}
inline OpacityPoint make_point(double x, const Values<1>& v, const OpacityPoint*) {
    return {x, v[0]};
}

// (1-t)*a + t*b per component, in double, rounded once to float. Equal components are copied,
// so constant (in particular all-zero) stretches stay exact.
template <size_t N>
Values<N> mix(const Values<N>& a, const Values<N>& b, double t) {
    Values<N> r;
    for (size_t i = 0; i < N; ++i)
        r[i] = a[i] == b[i] ? a[i] : float((1.0 - t) * double(a[i]) + t * double(b[i]));
    return r;
}

// Value at x, right-continuous at steps. pts: sorted by x, non-empty.
template <class P>
auto evaluate(const std::vector<P>& pts, double x) {
    // First point strictly right of x; the segment is [hi-1, hi).
    auto hi =
        std::upper_bound(pts.begin(), pts.end(), x, [](double v, const P& p) { return v < p.x; });
    if (hi == pts.begin()) return values_of(pts.front());
    if (hi == pts.end()) return values_of(pts.back());
    const P& lo = *(hi - 1);
    // lo.x <= x < hi->x, so the division is by a positive width.
    return mix(values_of(lo), values_of(*hi), (x - lo.x) / (hi->x - lo.x));
}

// Limit of the value as x is approached from the left (differs from evaluate() only at steps).
template <class P>
auto evaluate_left(const std::vector<P>& pts, double x) {
    // First point at or right of x; the segment is (lo-1, lo].
    auto lo =
        std::lower_bound(pts.begin(), pts.end(), x, [](const P& p, double v) { return p.x < v; });
    if (lo == pts.begin()) return values_of(pts.front());
    if (lo == pts.end()) return values_of(pts.back());
    if (lo->x == x) return values_of(*lo);
    const P& prev = *(lo - 1);
    return mix(values_of(prev), values_of(*lo), (x - prev.x) / (lo->x - prev.x));
}

// (1-w)*a + w*b as a control-point list: the blend of two piecewise-linear functions is
// piecewise linear with breakpoints at the union of theirs, so evaluating both there is exact.
// A step in either input (or a left/right difference after blending) becomes a two-point step.
template <class P>
std::vector<P> blend(const std::vector<P>& a, const std::vector<P>& b, double w) {
    std::vector<double> xs;
    xs.reserve(a.size() + b.size());
    for (const P& p : a) xs.push_back(p.x);
    for (const P& p : b) xs.push_back(p.x);
    std::sort(xs.begin(), xs.end());
    xs.erase(std::unique(xs.begin(), xs.end()), xs.end());

    std::vector<P> out;
    out.reserve(xs.size());
    for (double x : xs) {
        auto left = mix(evaluate_left(a, x), evaluate_left(b, x), w);
        auto right = mix(evaluate(a, x), evaluate(b, x), w);
        out.push_back(make_point(x, left, static_cast<const P*>(nullptr)));
        if (right != left) out.push_back(make_point(x, right, static_cast<const P*>(nullptr)));
    }
    return out;
}

}  // namespace lacuna::tf_detail
