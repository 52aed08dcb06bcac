// The incremental slicing polygons (growing-boxes paper, Section 3.3) against a brute-force
// Sutherland-Hodgman clip of each plane by the box: same vertices, same cyclic order (the
// shoelace area of the incremental order equals the hull's area), on random boxes, random and
// axis-aligned normals, thin boxes, planes through vertices.
#include "slice/polygon.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/rng.h"

namespace lacuna {
namespace {

using test::Rng;

std::vector<Vec3d> dedupe(const SlicePolygon& p, double tol) {
    std::vector<Vec3d> out;
    for (int i = 0; i < p.count; ++i) {
        const Vec3d& v = p.v[size_t(i)];
        if (!out.empty() && length(out.back() - v) <= tol) continue;
        if (out.size() > 1 && length(out.front() - v) <= tol && i == p.count - 1) continue;
        out.push_back(v);
    }
    return out;
}

// Signed area of the polygon (in order) projected onto the plane with normal n.
double area(const std::vector<Vec3d>& v, Vec3d n) {
    Vec3d s{0, 0, 0};
    for (size_t i = 0; i < v.size(); ++i) s = s + cross(v[i], v[(i + 1) % v.size()]);
    return 0.5 * dot(s, normalize(n));
}

void expect_same_polygon(const SlicePolygon& inc, const SlicePolygon& ref, Vec3d n, double scale,
                         const std::string& what) {
    const double tol = 1e-7 * scale;
    const auto a = dedupe(inc, tol), b = dedupe(ref, tol);
    // Every vertex of one lies on a vertex of the other.
    for (const Vec3d& p : a) {
        double best = INFINITY;
        for (const Vec3d& q : b) best = std::min(best, length(p - q));
        ASSERT_LE(best, 10 * tol) << what << " incremental " << to_string(inc) << " ref "
                                  << to_string(ref);
    }
    for (const Vec3d& q : b) {
        double best = INFINITY;
        for (const Vec3d& p : a) best = std::min(best, length(p - q));
        ASSERT_LE(best, 10 * tol) << what << " incremental " << to_string(inc) << " ref "
                                  << to_string(ref);
    }
    // Cyclic order: a wrong order of a convex polygon's vertices has a smaller |area|.
    const double ar = std::abs(area(b, n));
    ASSERT_NEAR(std::abs(area(a, n)), ar, 1e-6 * scale * scale)
        << what << " incremental " << to_string(inc) << " ref " << to_string(ref);
}

void check_box(Vec3d lo, Vec3d hi, Vec3d n, double dc, const std::string& what,
               long long* incremental = nullptr, long long* direct = nullptr) {
    double gmin = INFINITY, gmax = -INFINITY;
    for (int c = 0; c < 8; ++c) {
        Vec3d p;
        for (int a = 0; a < 3; ++a) p[a] = (c >> a) & 1 ? hi[a] : lo[a];
        gmin = std::min(gmin, dot(n, p));
        gmax = std::max(gmax, dot(n, p));
    }
    const double c0 = gmin - 2.5 * dc;
    IncrementalSlicer s(lo, hi, n, c0, dc);
    double scale = 1;
    for (int a = 0; a < 3; ++a) scale = std::max({scale, std::abs(lo[a]), std::abs(hi[a])});
    int planes = 0, non_empty = 0;
    for (double c = c0; c <= gmax + 2.5 * dc; c = c0 + (++planes) * dc) {
        SlicePolygon inc;
        s.next(inc);
        const SlicePolygon ref = clip_plane_against_box(lo, hi, n, c);
        if (ref.count >= 3 && std::abs(area(dedupe(ref, 1e-9 * scale), n)) > 1e-6 * scale * scale) {
            ASSERT_GE(inc.count, 3)
                << what << " plane " << planes << " c " << c << " ref " << to_string(ref);
            ++non_empty;
        }
        if (inc.count == 0 && ref.count == 0) continue;
        expect_same_polygon(inc, ref, n, scale, what + " plane " + std::to_string(planes));
    }
    if (incremental) *incremental += s.incremental_updates();
    if (direct) *direct += s.direct_intersections();
}

TEST(IncrementalSlicer, MatchesBruteForceClipOnRandomBoxesAndNormals) {
    Rng rng{17};
    long long inc = 0, direct = 0;
    for (int t = 0; t < 400; ++t) {
        Vec3d lo, hi, n;
        for (int a = 0; a < 3; ++a) {
            lo[a] = double(rng.range(-20, 40)) + (rng.coin() ? 0.0 : rng.uniform_d());
            hi[a] = lo[a] + (rng.coin(6) ? 0.05 + rng.uniform_d() : 1 + 30 * rng.uniform_d());
            n[a] = rng.uniform_d() * 2 - 1;
        }
        if (rng.coin(4)) n[rng.range(0, 2)] = 0;  // planes parallel to one axis
        if (length(n) < 1e-3) n = {0.3, 0.5, 0.8};
        const double dc = (0.05 + rng.uniform_d()) * length(n);
        SCOPED_TRACE(t);
        check_box(lo, hi, n, dc, "case " + std::to_string(t), &inc, &direct);
        if (HasFatalFailure()) return;
    }
    // Incremental updates dominate: most intersections move by one addition.
    EXPECT_GT(inc, 4 * direct) << "incremental " << inc << " direct " << direct;
}

TEST(IncrementalSlicer, AxisAlignedNormalGivesRectangles) {
    check_box({0, 0, 0}, {7, 5, 3}, {0, 0, 1}, 0.5, "z");
    check_box({0, 0, 0}, {7, 5, 3}, {0, -2, 0}, 0.25, "-y");
    check_box({1, 2, 3}, {4, 9, 5}, {0.5, 0.5, 0}, 0.3, "xy diagonal");
}

TEST(IncrementalSlicer, PlanesThroughBoxVerticesAndCubeDiagonal) {
    // n = (1,1,1) on a unit-spaced cube: planes c = 0, 1, 2, 3 pass through vertices exactly;
    // the hexagon at c = 1.5.
    check_box({0, 0, 0}, {1, 1, 1}, {1, 1, 1}, 0.5, "cube diagonal");
    check_box({0, 0, 0}, {2, 2, 2}, {1, 1, 1}, 0.25, "cube diagonal fine");
    check_box({0, 0, 0}, {3, 1, 2}, {1, -1, 1}, 1.0, "box integer planes");
    IncrementalSlicer s({0, 0, 0}, {1, 1, 1}, {1, 1, 1}, 1.5, 1.0);
    SlicePolygon p;
    s.next(p);
    EXPECT_EQ(p.count, 6) << to_string(p);
}

}  // namespace
}  // namespace lacuna
