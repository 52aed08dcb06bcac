// Slice views (lacuna/mpr.h) against answers computed here: a double-precision trilinear at the
// index this file computes from the geometry by its own route (R^T (w - t) / spacing), the
// display convention on an unrotated volume voxel by voxel, linear ramps, one phantom in three
// voxel orders, and the probe against brute force.
#include "lacuna/mpr.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/rng.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "render/orientation_test_util.h"

namespace lacuna {
namespace {

using test::Rng;
using namespace test::orientation;

// index = R^T (world - t) / spacing, R the RAS direction (orthonormal): not the library's
// cofactor inverse.
Vec3d index_of(const Volume& v, Vec3d w) {
    const Mat3 r = ras_direction(v);
    const Affine a = index_to_world(v);
    const Vec3d d{w.x - a.t[0], w.y - a.t[1], w.z - a.t[2]};
    Vec3d out;
    for (int c = 0; c < 3; ++c)
        out[c] = (r[0][c] * d.x + r[1][c] * d.y + r[2][c] * d.z) / v.spacing[c];
    return out;
}

bool clearly_inside(const Volume& v, Vec3d p, double margin) {
    for (int a = 0; a < 3; ++a)
        if (p[a] < margin || p[a] > v.dims()[a] - 1 - margin) return false;
    return true;
}
bool clearly_outside(const Volume& v, Vec3d p, double margin) {
    for (int a = 0; a < 3; ++a)
        if (p[a] < -margin || p[a] > v.dims()[a] - 1 + margin) return true;
    return false;
}

double trilinear_d(const Volume& v, Vec3d p) {
    const Vec3i d = v.dims();
    int i0[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        const double x = std::clamp(p[a], 0.0, double(d[a] - 1));
        i0[a] = std::min(int(std::floor(x)), d[a] - 2);
        f[a] = x - i0[a];
    }
    double s = 0;
    for (int c = 0; c < 8; ++c) {
        const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
        const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
        s += w * v.value(i0[0] + dx, i0[1] + dy, i0[2] + dz);
    }
    return s;
}

Volume random_volume(Vec3i dims, uint64_t seed) {
    Volume v(dims, VoxelType::Int16);
    Rng rng{seed};
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            for (int i = 0; i < dims.x; ++i) v.set_value(i, j, k, float(rng.range(-500, 1500)));
    v.compute_range();
    return v;
}

// A rotation about a tilted axis (no axis of the patient), spacing anisotropic, origin offset.
void make_oblique(Volume& v) {
    const double ax[3] = {0.48, -0.6, 0.64};  // unit
    const double th = 0.43, c = std::cos(th), s = std::sin(th);
    Mat3 r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            r[i][j] = (i == j ? c : 0) + (1 - c) * ax[i] * ax[j];
        }
    r[0][1] -= s * ax[2];
    r[0][2] += s * ax[1];
    r[1][0] += s * ax[2];
    r[1][2] -= s * ax[0];
    r[2][0] -= s * ax[1];
    r[2][1] += s * ax[0];
    set_ras_direction(v, r);
    v.spacing = {0.9, 1.3, 1.1};
    set_ras_origin(v, {-17.5, 4.25, -9});
}

const SlicePlane kPlanes[] = {SlicePlane::Axial, SlicePlane::Coronal, SlicePlane::Sagittal};

// Every pixel: inside -> the kernel's float sample within `tol` of the test's double answer;
// outside -> NaN. Pixels within 1e-3 voxels of a face are not judged (either is right).
template <class Want>
void expect_slice(const Volume& v, const Slice& s, Want want, double tol, const std::string& what) {
    const SliceGeometry& g = s.geometry;
    size_t inside = 0, outside = 0;
    for (int r = 0; r < g.height; ++r)
        for (int c = 0; c < g.width; ++c) {
            const Vec3d w = g.pixel_world(c, r);
            const Vec3d p = index_of(v, w);
            const float got = s.values[size_t(r) * size_t(g.width) + size_t(c)];
            if (clearly_inside(v, p, 1e-3)) {
                ++inside;
                ASSERT_NEAR(got, want(p), tol) << what << " pixel " << c << "," << r << " index "
                                               << to_string(p) << " " << to_string(g);
            } else if (clearly_outside(v, p, 1e-3)) {
                ++outside;
                ASSERT_TRUE(std::isnan(got)) << what << " pixel " << c << "," << r;
            }
        }
    EXPECT_GT(inside, size_t(g.width) * size_t(g.height) / 10) << what;
    (void)outside;
}

TEST(Mpr, TrilinearMatchesDoublePrecisionOnAnObliqueVolume) {
    Volume v = random_volume({23, 19, 17}, 7);
    make_oblique(v);
    Rng rng{3};
    for (SlicePlane pl : kPlanes)
        for (int trial = 0; trial < 3; ++trial) {
            const Vec3d centre = Vec3d(world_bounds(v).center());
            const Vec3d pt = centre + Vec3d{rng.uniform_d() * 8 - 4, rng.uniform_d() * 8 - 4,
                                            rng.uniform_d() * 8 - 4};
            SliceOptions o;
            o.pixel_mm = 0.37;  // off the lattice on purpose
            const Slice s = sample_slice(v, pl, pt, o);
            // Tolerance, from the kernel's float arithmetic (the index is exact in double, then
            // rounded to float). Indices below 32 round by <= 2^-20 ~ 9.5e-7 voxels per axis;
            // neighbouring voxels differ by <= 2000, so the cell's trilinear moves by <= 3 axes
            // x 2000 x 9.5e-7 = 5.7e-3. The 7 lerps on values <= 1500 round by <= 2 x 2^-14 ~
            // 1.2e-4 each: < 1e-3 in all. Bound 6.7e-3; 0.01 leaves a margin, a wrong corner or
            // weight is off by tens.
            expect_slice(
                v, s, [&](Vec3d p) { return trilinear_d(v, p); }, 0.01, to_string(pl));
        }
}

TEST(Mpr, LinearRampComesOutLinearStraightAndOblique) {
    for (bool oblique : {false, true}) {
        Volume v({31, 27, 22}, VoxelType::Float32);
        for (int k = 0; k < 22; ++k)
            for (int j = 0; j < 27; ++j)
                for (int i = 0; i < 31; ++i) v.set_value(i, j, k, float(2 * i - 3 * j + 5 * k + 7));
        v.compute_range();
        if (oblique) make_oblique(v);
        for (SlicePlane pl : kPlanes) {
            SliceOptions o;
            o.pixel_mm = 0.61;
            const Vec3d pt = Vec3d(world_bounds(v).center()) + Vec3d{0.3, -0.7, 0.45};
            const Slice s = sample_slice(v, pl, pt, o);
            // Trilinear reproduces a linear function exactly, up to float: the index rounds by
            // <= 9.5e-7 voxels per axis (indices < 32), moving the ramp by <= (2 + 3 + 5) x
            // 9.5e-7 ~ 1e-5, and 7 lerps on values <= 256 round by <= 7 x 2^-16 ~ 1.1e-4.
            expect_slice(
                v, s, [](Vec3d p) { return 2 * p.x - 3 * p.y + 5 * p.z + 7; }, 1e-3,
                std::string(oblique ? "oblique " : "straight ") + to_string(pl));
        }
    }
}

// Unrotated volume (RAS identity): each pixel is one voxel, in Slicer's screen orientation.
TEST(Mpr, DisplayConventionIsSlicersOnePixelPerVoxel) {
    Volume v = random_volume({13, 11, 9}, 11);
    v.spacing = {1.5, 1.5, 1.5};
    set_ras_origin(v, {-9, 2, 5});
    const Affine a = index_to_world(v);
    const int ci = 4, cj = 6, ck = 3;
    const Vec3d pt = a.apply({double(ci), double(cj), double(ck)});
    const Vec3i d = v.dims();
    for (SlicePlane pl : kPlanes)
        for (Interpolation in : {Interpolation::Trilinear, Interpolation::Nearest}) {
            SliceOptions o;
            o.interpolation = in;
            const Slice s = sample_slice(v, pl, pt, o);
            const SliceGeometry& g = s.geometry;
            // screen right / down per plane, as voxel index steps (RAS identity: +i = right)
            const int want_w = pl == SlicePlane::Sagittal ? d.y : d.x;
            const int want_h = pl == SlicePlane::Axial ? d.y : d.z;
            ASSERT_EQ(g.width, want_w) << to_string(g);
            ASSERT_EQ(g.height, want_h) << to_string(g);
            for (int r = 0; r < g.height; ++r)
                for (int c = 0; c < g.width; ++c) {
                    int i = 0, j = 0, k = 0;
                    if (pl == SlicePlane::Axial) {
                        i = d.x - 1 - c;  // screen right = patient left (-x)
                        j = d.y - 1 - r;  // screen up = anterior (+y)
                        k = ck;
                    } else if (pl == SlicePlane::Coronal) {
                        i = d.x - 1 - c;
                        j = cj;
                        k = d.z - 1 - r;  // screen up = superior
                    } else {
                        i = ci;
                        j = d.y - 1 - c;  // screen right = posterior (-y): nose left
                        k = d.z - 1 - r;
                    }
                    ASSERT_EQ(s.values[size_t(r) * size_t(g.width) + size_t(c)], v.value(i, j, k))
                        << to_string(pl) << " " << to_string(in) << " pixel " << c << "," << r;
                }
        }
}

TEST(Mpr, PhantomInThreeVoxelOrdersGivesTheSameSlices) {
    const Volume ras = phantom();
    const Volume lps = reorder(ras, {0, 1, 2}, {true, true, false});
    const Volume perm = reorder(ras, {2, 0, 1}, {false, true, true});
    ASSERT_EQ(orientation_code(ras), "RAS");
    ASSERT_EQ(orientation_code(lps), "LPS");
    const Vec3d pts[] = {{0, 0, 0}, {11, -2, 0.3}, {-3, 4.5, 15.5}};
    for (SlicePlane pl : kPlanes)
        for (Vec3d pt : pts)
            for (Interpolation in : {Interpolation::Trilinear, Interpolation::Nearest}) {
                SliceOptions o;
                o.interpolation = in;
                const Slice a = sample_slice(ras, pl, pt, o);
                for (const Volume* other : {&lps, &perm}) {
                    const Slice b = sample_slice(*other, pl, pt, o);
                    ASSERT_EQ(a.geometry.width, b.geometry.width);
                    ASSERT_EQ(a.geometry.height, b.geometry.height);
                    size_t shown = 0;
                    for (size_t p = 0; p < a.values.size(); ++p) {
                        const float x = a.values[p], y = b.values[p];
                        if (std::isnan(x) || std::isnan(y)) {
                            // a face pixel may fall either side by rounding; far ones may not
                            continue;
                        }
                        ++shown;
                        // Trilinear: the two copies reach the same world point through different
                        // affines, so each index is the exact one rounded to float: <= 2^-19 ~
                        // 1.9e-6 voxels per axis (indices < 64). The phantom's neighbouring
                        // voxels differ by <= 133 (220 over 2.5 mm, spacing <= 1.5 mm, rounded),
                        // so each copy's sample moves by <= 3 x 133 x 1.9e-6 = 7.6e-4, plus
                        // <= 7 x 2 x 2^-16 ~ 2e-4 of lerp rounding on values <= 255: the two
                        // differ by <= 2 x 9.6e-4 ~ 1.9e-3 (so 1e-3 was too tight). 5e-3; a
                        // wrong voxel order is off by whole grey steps. Nearest: the same voxel.
                        ASSERT_NEAR(x, y, in == Interpolation::Nearest ? 0.0 : 5e-3)
                            << to_string(pl) << " " << to_string(in) << " "
                            << orientation_code(*other) << " pixel " << p;
                    }
                    EXPECT_GT(shown, a.values.size() / 2);
                    size_t nan_a = 0, nan_b = 0;
                    for (size_t p = 0; p < a.values.size(); ++p) {
                        nan_a += std::isnan(a.values[p]);
                        nan_b += std::isnan(b.values[p]);
                    }
                    EXPECT_EQ(nan_a, nan_b) << to_string(pl);
                }
            }
}

TEST(Mpr, OutsideTheVolumeIsNaNAndShownBlack) {
    Volume v = random_volume({10, 12, 8}, 5);
    make_oblique(v);
    const Vec3d c = Vec3d(world_bounds(v).center());
    // A plane beyond the box: all NaN.
    const Slice far = sample_slice(v, SlicePlane::Axial, c + Vec3d{0, 0, 1000});
    for (float x : far.values) ASSERT_TRUE(std::isnan(x));
    // The oblique box's corners on a central plane are outside.
    const Slice s = sample_slice(v, SlicePlane::Coronal, c);
    // 0.01: the bound of TrilinearMatchesDoublePrecisionOnAnObliqueVolume (same values).
    expect_slice(
        v, s, [&](Vec3d p) { return trilinear_d(v, p); }, 0.01, "coronal");
    const Image img = window_level(s, 400, 500);
    size_t nan = 0;
    for (size_t p = 0; p < s.values.size(); ++p)
        if (std::isnan(s.values[p])) {
            ++nan;
            ASSERT_EQ(img.rgba[p * 4], 0);
            ASSERT_EQ(img.rgba[p * 4 + 3], 255);
        }
    EXPECT_GT(nan, size_t(0));
}

TEST(Mpr, WindowLevelIsTheLinearRampClamped) {
    Volume v = random_volume({9, 9, 9}, 9);
    const Slice s = sample_slice(v, SlicePlane::Axial, {4, 4, 4});
    const double window = 700, level = 300;
    const Image img = window_level(s, window, level);
    for (size_t p = 0; p < s.values.size(); ++p) {
        const double t = std::clamp((s.values[p] - (level - window / 2)) / window, 0.0, 1.0);
        ASSERT_EQ(int(img.rgba[p * 4]), int(std::lround(t * 255))) << p;
        ASSERT_EQ(img.rgba[p * 4], img.rgba[p * 4 + 2]);
    }
    EXPECT_THROW(window_level(s, 0, 1), Error);
    EXPECT_THROW(window_level(s, NAN, 1), Error);
}

TEST(Mpr, LabelOverlayUsesNearestLabelsAndTheirColours) {
    const Volume img = phantom();
    Volume labels(img.dims(), VoxelType::UInt8);
    labels.spacing = img.spacing;
    labels.origin = img.origin;
    for (int k = 0; k < img.dims().z; ++k)
        for (int j = 0; j < img.dims().y; ++j)
            for (int i = 0; i < img.dims().x; ++i)
                labels.set_value(i, j, k, float((i / 7 + j / 5 + k / 3) % 4));
    labels.compute_range();
    const LabelTable table = default_label_table(labels);
    const Slice s = sample_slice(img, SlicePlane::Coronal, {1.3, 2.2, -3.1});
    const std::vector<int32_t> ls = sample_labels(labels, s.geometry);
    Image out = window_level(s, 255, 127.5);
    const Image grey = out;
    overlay_labels(out, ls, table, 0.4f);
    size_t coloured = 0;
    for (int r = 0; r < s.geometry.height; ++r)
        for (int c = 0; c < s.geometry.width; ++c) {
            const size_t p = size_t(r) * size_t(s.geometry.width) + size_t(c);
            const Vec3d li = index_of(labels, s.geometry.pixel_world(c, r));
            int want = -1;
            if (clearly_inside(labels, li, 1e-3)) {
                want = int(labels.value(int(std::floor(li.x + 0.5)), int(std::floor(li.y + 0.5)),
                                        int(std::floor(li.z + 0.5))));
                // away from a rounding tie, nearest is unambiguous
                bool tie = false;
                for (int a = 0; a < 3; ++a) tie |= std::abs(li[a] - std::floor(li[a]) - 0.5) < 1e-4;
                if (!tie) {
                    ASSERT_EQ(ls[p], want) << c << "," << r;
                }
            } else if (clearly_outside(labels, li, 1e-3)) {
                ASSERT_EQ(ls[p], -1);
            }
            if (ls[p] > 0) {
                ++coloured;
                const LabelStyle& st = table.styles[size_t(ls[p])];
                const float col[3] = {st.r, st.g, st.b};
                for (int ch = 0; ch < 3; ++ch) {
                    const double g = grey.rgba[p * 4 + size_t(ch)];
                    ASSERT_EQ(int(out.rgba[p * 4 + size_t(ch)]),
                              int(std::lround(g + double(0.4f) * (col[ch] * 255.0 - g))));
                }
            } else {
                for (int ch = 0; ch < 4; ++ch)
                    ASSERT_EQ(out.rgba[p * 4 + size_t(ch)], grey.rgba[p * 4 + size_t(ch)]);
            }
        }
    EXPECT_GT(coloured, size_t(100));
}

TEST(Mpr, ProbeMatchesBruteForce) {
    Volume v = random_volume({14, 16, 12}, 21);
    make_oblique(v);
    Volume labels = random_volume({14, 16, 12}, 22);
    for (int k = 0; k < 12; ++k)
        for (int j = 0; j < 16; ++j)
            for (int i = 0; i < 14; ++i) labels.set_value(i, j, k, float((i + 2 * j + 3 * k) % 5));
    labels.compute_range();
    labels.spacing = v.spacing;
    labels.origin = v.origin;
    std::copy(std::begin(v.direction), std::end(v.direction), std::begin(labels.direction));
    LabelTable table = default_label_table(labels);
    for (int l = 0; l < table.size(); ++l)
        table.styles[size_t(l)].name = "label" + std::to_string(l);
    Rng rng{99};
    const Box3f b = world_bounds(v);
    size_t in = 0, out = 0;
    for (int t = 0; t < 400; ++t) {
        const Vec3d w{b.lo.x - 3 + rng.uniform_d() * (b.hi.x - b.lo.x + 6),
                      b.lo.y - 3 + rng.uniform_d() * (b.hi.y - b.lo.y + 6),
                      b.lo.z - 3 + rng.uniform_d() * (b.hi.z - b.lo.z + 6)};
        const ProbeResult pr = probe(v, w, Interpolation::Trilinear, &labels, &table);
        const Vec3d p = index_of(v, w);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(pr.index[a], p[a], 1e-9);
        if (clearly_inside(v, p, 1e-3)) {
            ++in;
            ASSERT_TRUE(pr.inside);
            // 0.01: the bound of TrilinearMatchesDoublePrecisionOnAnObliqueVolume (same values).
            ASSERT_NEAR(pr.value, trilinear_d(v, p), 0.01);
            const Vec3i nv{int(std::lround(p.x)), int(std::lround(p.y)), int(std::lround(p.z))};
            ASSERT_EQ(pr.voxel, nv);
            ASSERT_EQ(pr.voxel_value, v.value(nv.x, nv.y, nv.z));
            ASSERT_TRUE(pr.label.has_value());
            ASSERT_EQ(*pr.label, int(labels.value(nv.x, nv.y, nv.z)));
            ASSERT_EQ(pr.label_name, "label" + std::to_string(*pr.label));
        } else if (clearly_outside(v, p, 1e-3)) {
            ++out;
            ASSERT_FALSE(pr.inside);
            ASSERT_TRUE(std::isnan(pr.value));
            ASSERT_FALSE(pr.label.has_value());
        }
    }
    EXPECT_GT(in, size_t(50));
    EXPECT_GT(out, size_t(50));
}

TEST(Mpr, BadInputIsAOneLineErrorNamingTheField) {
    const Volume v = random_volume({5, 5, 5}, 1);
    auto message = [&](auto f) {
        try {
            f();
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message([&] {
                  slice_geometry(v, SlicePlane::Axial, {NAN, 0, 0});
              }).find("point"),
              std::string::npos);
    SliceOptions o;
    o.pixel_mm = -1;
    EXPECT_NE(message([&] {
                  slice_geometry(v, SlicePlane::Axial, {0, 0, 0}, o);
              }).find("pixel_mm"),
              std::string::npos);
    o.pixel_mm = 1e-6;
    EXPECT_NE(message([&] {
                  slice_geometry(v, SlicePlane::Axial, {0, 0, 0}, o);
              }).find("pixel_mm"),
              std::string::npos);
    EXPECT_NE(message([&] { parse_slice_plane("oblique"); }).find("plane"), std::string::npos);
    // max_size coarsens the pixel, keeping the extent.
    Volume big = random_volume({40, 30, 20}, 2);
    SliceOptions capped;
    capped.max_size = 16;
    const SliceGeometry g = slice_geometry(big, SlicePlane::Axial, {0, 0, 0}, capped);
    EXPECT_LE(std::max(g.width, g.height), 16);
    EXPECT_NEAR(g.pixel_mm * (g.width - 1), 39.0, 1e-9);
}

}  // namespace
}  // namespace lacuna
