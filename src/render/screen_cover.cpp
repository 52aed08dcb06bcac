#include "render/screen_cover.h"

#include <algorithm>
#include <cmath>

namespace lacuna {

namespace {

// Screen coordinates as affine forms of an index-space point p: with the camera basis as the
// columns of M = [forward right up] (not necessarily orthonormal) and v = p * spacing - eye,
// (s, a, b) = M^-1 v. A perspective ray through screen point (sx, sy) is the set s > 0 with
// a = s sx, b = s sy (Camera::generate); an orthographic one has a = sx, b = sy.
struct Forms {
    double c[3][4];  // row k: coefficients of p.x, p.y, p.z and the constant
    double at(int k, const double p[3]) const {
        return c[k][0] * p[0] + c[k][1] * p[1] + c[k][2] * p[2] + c[k][3];
    }
};

bool screen_forms(const Camera& cam, const Vec3d& spacing, Forms& f) {
    const Vec3f col[3] = {cam.forward(), cam.right(), cam.up()};
    double m[3][3];
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) m[r][k] = double(col[k][r]);
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(std::fabs(det) > 1e-12)) return false;
    double inv[3][3];
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
            // cofactor of m[k][r] over det
            const int r1 = (k + 1) % 3, r2 = (k + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            inv[r][k] = (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det;
        }
    const Vec3f e = cam.eye();
    const double sp[3] = {spacing.x, spacing.y, spacing.z}, eye[3] = {e.x, e.y, e.z};
    for (int k = 0; k < 3; ++k) {
        f.c[k][3] = 0;
        for (int a = 0; a < 3; ++a) {
            f.c[k][a] = inv[k][a] * sp[a];
            f.c[k][3] -= inv[k][a] * eye[a];
        }
    }
    return true;
}

}  // namespace

std::optional<ScreenCover> ScreenCover::build(const BrickGrid& grid, const Volume& vol,
                                              const Camera& cam) {
    const std::vector<BrickGrid::BrickRun>* runs = grid.surface_runs();
    if (!runs) return std::nullopt;
    Forms f;
    if (!screen_forms(cam, vol.spacing, f)) return std::nullopt;
    const Vec3i dims = vol.dims();
    const double hi[3] = {double(dims.x - 1), double(dims.y - 1), double(dims.z - 1)};
    const bool ortho = cam.projection() == Projection::Orthographic;
    // The eye (and, orthographic, the eye plane) clear of the grid's box grown by 2 voxels.
    {
        const Vec3f e = cam.eye();
        const Vec3d sp = vol.spacing;
        const double p[3] = {e.x / sp.x, e.y / sp.y, e.z / sp.z};
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside = inside && p[a] > -2.0 && p[a] < hi[a] + 2.0;
        if (inside) return std::nullopt;
    }
    const double W = cam.width(), H = cam.height(), hh = cam.half_height();
    const double ax = W / (2.0 * (W / H) * hh), ay = H / (2.0 * hh);
    // The smallest s a corner may have: well in front of the eye plane, so 1/s stays tame.
    const double s_min =
        1e-3 * std::max({hi[0] * vol.spacing.x, hi[1] * vol.spacing.y, hi[2] * vol.spacing.z, 1.0});
    ScreenCover c;
    c.m_width = cam.width(), c.m_height = cam.height();
    c.m_words = (size_t(c.m_width) + 63) / 64;
    c.m_bits.assign(c.m_words * size_t(c.m_height), 0);
    c.m_bw = (c.m_width + 7) / 8;
    const size_t blocks = size_t(c.m_bw) * size_t((c.m_height + 7) / 8);
    c.m_t0.assign(blocks, INFINITY);
    c.m_t1.assign(blocks, -INFINITY);
    const Vec3f eye_f = cam.eye();
    const double eye[3] = {eye_f.x, eye_f.y, eye_f.z};
    const double sp[3] = {vol.spacing.x, vol.spacing.y, vol.spacing.z};
    auto box = [&](const double lo[3], const double up[3]) {
        // Each form at a corner is its constant plus one term per axis, lo or up: 18 products.
        double t[3][3][2];
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a)
                t[k][a][0] = f.c[k][a] * lo[a], t[k][a][1] = f.c[k][a] * up[a];
        double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
        double s0 = INFINITY, s1 = -INFINITY;
        for (int i = 0; i < 8; ++i) {
            const int u = i & 1, v = i >> 1 & 1, w = i >> 2;
            const double s = f.c[0][3] + t[0][0][u] + t[0][1][v] + t[0][2][w];
            if (!(s > s_min)) return false;
            s0 = std::min(s0, s), s1 = std::max(s1, s);
            const double q = ortho ? 1.0 : 1.0 / s;
            const double sx = (f.c[1][3] + t[1][0][u] + t[1][1][v] + t[1][2][w]) * q;
            const double sy = (f.c[2][3] + t[2][0][u] + t[2][1][v] + t[2][2][w]) * q;
            // Camera::generate inverted: sx = (2 (px + 0.5) / W - 1) aspect hh, likewise y.
            const double px = (sx * ax + W / 2) - 0.5, py = (H / 2 - sy * ay) - 0.5;
            x0 = std::min(x0, px), x1 = std::max(x1, px);
            y0 = std::min(y0, py), y1 = std::max(y1, py);
        }
        // The box's t range: orthographic t is the depth s (a unit forward); perspective t is the
        // distance from the eye, between the box's nearest point and its farthest corner.
        double t0 = s0, t1 = s1;
        if (!ortho) {
            double n2 = 0, f2 = 0;
            for (int a = 0; a < 3; ++a) {
                const double l = lo[a] * sp[a] - eye[a], h = up[a] * sp[a] - eye[a];
                const double near = l > 0 ? l : (h < 0 ? -h : 0);
                const double far = std::max(std::fabs(l), std::fabs(h));
                n2 += near * near, f2 += far * far;
            }
            t0 = std::sqrt(n2), t1 = std::sqrt(f2);
        }
        // Clamped before the int conversion (a box far off screen projects anywhere); mark()
        // clips to the image.
        auto px_lo = [](double v) { return int(std::floor(std::clamp(v, -1e9, 1e9))) - 1; };
        auto px_hi = [](double v) { return int(std::ceil(std::clamp(v, -1e9, 1e9))) + 1; };
        c.mark(px_lo(x0), px_lo(y0), px_hi(x1), px_hi(y1), float(t0 * (1 - 1e-6)),
               float(t1 * (1 + 1e-6)));
        return true;
    };
    // Orthographic rays start on the eye plane: the whole grown grid in front of it.
    if (ortho) {
        const double lo[3] = {-2, -2, -2}, up[3] = {hi[0] + 2, hi[1] + 2, hi[2] + 2};
        for (int i = 0; i < 8; ++i) {
            const double p[3] = {i & 1 ? up[0] : lo[0], i & 2 ? up[1] : lo[1],
                                 i & 4 ? up[2] : lo[2]};
            if (!(f.at(0, p) > 0)) return std::nullopt;
        }
    }
    const int B = 1 << grid.brick_log2();
    constexpr double m = 1.0;  // the growth of every box (the argument's m)
    for (const BrickGrid::BrickRun& r : *runs) {
        const int b0[3] = {r.x0, r.y, r.z}, b1[3] = {r.x1, r.y, r.z};
        double lo[3], up[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = double(b0[a] * B) - m;
            up[a] = std::min(double((b1[a] + 1) * B), hi[a]) + m;
        }
        if (!box(lo, up)) return std::nullopt;
    }
    return c;
}

void ScreenCover::mark(int x0, int y0, int x1, int y1, float t0, float t1) {
    x0 = std::max(x0, 0), y0 = std::max(y0, 0);
    x1 = std::min(x1, m_width - 1), y1 = std::min(y1, m_height - 1);
    if (x0 > x1 || y0 > y1) return;
    for (int by = y0 >> 3; by <= y1 >> 3; ++by)
        for (int bx = x0 >> 3; bx <= x1 >> 3; ++bx) {
            const size_t b = size_t(by) * size_t(m_bw) + size_t(bx);
            m_t0[b] = std::min(m_t0[b], t0), m_t1[b] = std::max(m_t1[b], t1);
        }
    const int w0 = x0 >> 6, w1 = x1 >> 6;
    for (int y = y0; y <= y1; ++y) {
        uint64_t* row = &m_bits[size_t(y) * m_words];
        for (int w = w0; w <= w1; ++w) {
            uint64_t bits = ~uint64_t(0);
            if (w == w0) bits &= ~uint64_t(0) << (x0 & 63);
            if (w == w1) bits &= ~uint64_t(0) >> (63 - (x1 & 63));
            row[w] |= bits;
        }
    }
}

bool ScreenCover::any(int x0, int y0, int x1, int y1) const {
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            if (covered(x, y)) return true;
    return false;
}

double ScreenCover::fraction() const {
    size_t n = 0;
    for (uint64_t w : m_bits) n += size_t(__builtin_popcountll(w));
    return double(n) / (double(m_width) * double(m_height));
}

}  // namespace lacuna
