#include "lacuna/orientation.h"

#include <cmath>
#include <cstdio>

#include "lacuna/error.h"

namespace lacuna {
namespace {

// ITK's LPS+ world to RAS+: negate x and y.
constexpr double kLpsToRas[3] = {-1.0, -1.0, 1.0};

// The direction in RAS, column c = the world direction of index axis c.
void ras_direction(const Volume& v, double r[3][3]) {
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col)
            r[row][col] = kLpsToRas[row] * v.direction[row * 3 + col] + 0.0;  // + 0.0: no -0
}

std::string num(double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", x);
    return b;
}

}  // namespace

Vec3d Affine::apply(Vec3d p) const {
    Vec3d w;
    for (int r = 0; r < 3; ++r) w[r] = m[r][0] * p.x + m[r][1] * p.y + m[r][2] * p.z + t[r];
    return w;
}

double Affine::column_length(int c) const {
    return std::sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]);
}

std::string to_string(const Affine& a) {
    std::string s;
    for (int r = 0; r < 3; ++r) {
        s += r ? " [" : "[";
        for (int c = 0; c < 3; ++c) s += num(a.m[r][c] + 0.0) + " ";
        s += num(a.t[r] + 0.0) + "]";
    }
    return s;
}

Affine index_to_world(const Volume& v) {
    double r[3][3];
    ras_direction(v, r);
    Affine a;
    for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) a.m[row][col] = r[row][col] * v.spacing[col] + 0.0;
        a.t[row] = kLpsToRas[row] * v.origin[row] + 0.0;
    }
    return a;
}

std::string orientation_code(const Volume& v) {
    double r[3][3];
    ras_direction(v, r);
    static const char pos[3] = {'R', 'A', 'S'}, neg[3] = {'L', 'P', 'I'};
    std::string code;
    for (int col = 0; col < 3; ++col) {
        int best = 0;
        for (int row = 1; row < 3; ++row)
            if (std::fabs(r[row][col]) > std::fabs(r[best][col])) best = row;
        code += r[best][col] >= 0 ? pos[best] : neg[best];
    }
    return code;
}

Box3f world_bounds(const Volume& v) {
    const Affine a = index_to_world(v);
    const Vec3i d = v.dims();
    Vec3d lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int c = 0; c < 8; ++c) {
        const Vec3d p = a.apply({c & 1 ? double(d.x - 1) : 0.0, c & 2 ? double(d.y - 1) : 0.0,
                                 c & 4 ? double(d.z - 1) : 0.0});
        lo = vmin(lo, p);
        hi = vmax(hi, p);
    }
    return {Vec3f(lo), Vec3f(hi)};
}

void check_geometry(const Volume& v, const std::string& where) {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(v.spacing[a]) || !(v.spacing[a] > 0))
            throw Error(where, "spacing",
                        "expected finite positive voxel spacing, got " + num(v.spacing.x) + " " +
                            num(v.spacing.y) + " " + num(v.spacing.z));
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(v.origin[a]))
            throw Error(where, "origin",
                        "expected a finite position of the first voxel, got " + num(v.origin.x) +
                            " " + num(v.origin.y) + " " + num(v.origin.z));
    std::string dir;
    for (int i = 0; i < 9; ++i) dir += (i ? " " : "") + num(v.direction[i]);
    for (int i = 0; i < 9; ++i)
        if (!std::isfinite(v.direction[i]))
            throw Error(where, "direction", "expected finite direction cosines, got " + dir);
    // Columns of unit length and mutually perpendicular: a rotation, possibly with a flip.
    const double* m = v.direction;
    auto col_dot = [m](int a, int b) {
        return m[a] * m[b] + m[3 + a] * m[3 + b] + m[6 + a] * m[6 + b];
    };
    for (int a = 0; a < 3; ++a)
        if (!(std::fabs(col_dot(a, a) - 1.0) < 1e-4))
            throw Error(
                where, "direction",
                "axis " + std::to_string(a) + " has length " + num(std::sqrt(col_dot(a, a))) +
                    ", expected unit direction cosines (a zero or singular matrix?): " + dir);
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b)
            if (!(std::fabs(col_dot(a, b)) < 1e-4))
                throw Error(
                    where, "direction",
                    "axes " + std::to_string(a) + " and " + std::to_string(b) +
                        " are not perpendicular (cos " + num(col_dot(a, b)) +
                        "): a sheared or singular grid, which lacuna does not render: " + dir);
    // Renderable in float: the camera, the world bounds and the volume frame are float. Measured
    // on an 8^3 file (docs/reliability.md), pictures are the bytes of spacing 1 for any spacing
    // from 1e-20 to 1e18 mm and empty (0 samples per ray, no error) below 1e-40 or above 1e19,
    // where squared lengths leave float: so spacing and every world coordinate stay within
    // 1e-15 .. 1e15 mm. Far from the world origin, float resolves positions only to |x| * 2^-24,
    // which the camera's eye adds to the rounding of the volume's own size: a volume further
    // out than twice its size and 2^19 of its finest spacing (a 32nd of a voxel) is refused
    // (spacing 1 at 1e5 mm renders within 1 of 255 per channel; at 1e6 mm up to 32 off; at
    // 1e9 mm nothing).
    const Vec3i d = v.dims();
    const double finest = std::fmin(v.spacing.x, std::fmin(v.spacing.y, v.spacing.z));
    if (!(finest >= 1e-15))
        throw Error(where, "spacing",
                    "voxel spacing " + num(finest) +
                        " mm is below 1e-15 mm, too fine for the float positions of the renderers");
    double size = 0;  // the largest side of the voxel box, mm
    for (int a = 0; a < 3; ++a) size = std::fmax(size, double(d[a]) * v.spacing[a]);
    if (!(size <= 1e15))
        throw Error(where, "spacing",
                    "the volume spans " + num(size) +
                        " mm, more than the 1e15 mm the float positions of the renderers reach");
    const Affine w = index_to_world(v);
    double far = 0;  // the largest world coordinate of a corner, mm
    for (int c = 0; c < 8; ++c) {
        const Vec3d p = w.apply({c & 1 ? double(d.x - 1) : 0.0, c & 2 ? double(d.y - 1) : 0.0,
                                 c & 4 ? double(d.z - 1) : 0.0});
        far = std::fmax(far, std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z))));
    }
    if (!(far <= 1e15) || (far > 2 * size && far > 0x1p19 * finest))
        throw Error(where, "origin",
                    "the volume (" + num(size) + " mm across, voxels of " + num(finest) +
                        " mm) lies " + num(far) +
                        " mm from the world origin, too far for float positions to resolve its "
                        "voxels (at most 2^19 voxels or twice its size, and 1e15 mm)");
}

Vec3f VolumeFrame::point(Vec3f p) const {
    const Vec3d d{double(p.x) - from.x, double(p.y) - from.y, double(p.z) - from.z};
    Vec3f q;
    for (int r = 0; r < 3; ++r) q[r] = float(rot[r][0] * d.x + rot[r][1] * d.y + rot[r][2] * d.z);
    return q;
}

Vec3f VolumeFrame::vector(Vec3f p) const {
    Vec3f q;
    for (int r = 0; r < 3; ++r)
        q[r] = float(rot[r][0] * double(p.x) + rot[r][1] * double(p.y) + rot[r][2] * double(p.z));
    return q;
}

bool VolumeFrame::axis_aligned() const {
    for (int r = 0; r < 3; ++r) {
        int nonzero = 0;
        for (int c = 0; c < 3; ++c) {
            if (rot[r][c] == 0.0) continue;
            if (std::fabs(rot[r][c]) != 1.0) return false;
            ++nonzero;
        }
        if (nonzero != 1) return false;
    }
    return true;
}

VolumeFrame volume_frame(const Volume& v) {
    double r[3][3];
    ras_direction(v, r);
    // Gram-Schmidt on the columns (check_geometry allows 1e-4 of slack; the renderers need an
    // exact rigid map so that t stays in millimetres). A signed permutation passes unchanged.
    double c[3][3];
    for (int a = 0; a < 3; ++a) {
        for (int k = 0; k < 3; ++k) c[a][k] = r[k][a];
        for (int b = 0; b < a; ++b) {
            const double d = c[a][0] * c[b][0] + c[a][1] * c[b][1] + c[a][2] * c[b][2];
            if (d != 0.0)
                for (int k = 0; k < 3; ++k) c[a][k] -= d * c[b][k];
        }
        const double n2 = c[a][0] * c[a][0] + c[a][1] * c[a][1] + c[a][2] * c[a][2];
        if (n2 != 1.0) {
            const double n = std::sqrt(n2);
            for (int k = 0; k < 3; ++k) c[a][k] /= n;
        }
    }
    VolumeFrame f;
    f.identity = true;
    for (int a = 0; a < 3; ++a) {
        for (int k = 0; k < 3; ++k) {
            f.rot[a][k] = c[a][k] + 0.0;  // row a of R^T = column a of R
            if (f.rot[a][k] != (a == k ? 1.0 : 0.0)) f.identity = false;
        }
        f.from[a] = kLpsToRas[a] * v.origin[a] + 0.0;
        if (f.from[a] != 0.0) f.identity = false;
    }
    return f;
}

Camera to_volume_frame(const VolumeFrame& f, const Camera& c) {
    if (f.identity) return c;
    return Camera::from_basis(f.point(c.eye()), f.vector(c.forward()), f.vector(c.right()),
                              f.vector(c.up()), c.half_height(), c.width(), c.height(),
                              c.projection());
}

}  // namespace lacuna
