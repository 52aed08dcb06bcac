#include "lacuna/mpr.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/parallel.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "render/ray_march_kernel.h"

namespace lacuna {

namespace {

constexpr int kTile = 64;  // pixels per tile side for parallel_for_tiles

// Screen right and screen up of each plane in RAS, and its normal (mpr.h's table).
struct PlaneAxes {
    Vec3d right, up, normal;
};
PlaneAxes plane_axes(SlicePlane p) {
    switch (p) {
        case SlicePlane::Axial:
            return {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        case SlicePlane::Coronal:
            return {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}};
        case SlicePlane::Sagittal:
            return {{0, -1, 0}, {0, 0, 1}, {1, 0, 0}};
    }
    return {};
}

// index = m * (world - t): the inverse of the volume's index-to-world affine (any invertible
// matrix: the cofactor formula, in double).
struct WorldToIndex {
    double m[3][3];
    Vec3d t;
    Vec3d point(Vec3d w) const {
        const Vec3d d = w - t;
        return {m[0][0] * d.x + m[0][1] * d.y + m[0][2] * d.z,
                m[1][0] * d.x + m[1][1] * d.y + m[1][2] * d.z,
                m[2][0] * d.x + m[2][1] * d.y + m[2][2] * d.z};
    }
    Vec3d vector(Vec3d d) const { return point(d + t); }
};
WorldToIndex world_to_index(const Volume& v) {
    const Affine a = index_to_world(v);
    const auto& m = a.m;
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    WorldToIndex w;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            // inverse[r][c] = cofactor[c][r] / det
            const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            w.m[r][c] = (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det;
        }
    w.t = {a.t[0], a.t[1], a.t[2]};
    return w;
}

bool inside_box(Vec3d p, Vec3i dims) {
    const double e = kInsideTolerance;
    return p.x >= -e && p.y >= -e && p.z >= -e && p.x <= dims.x - 1 + e && p.y <= dims.y - 1 + e &&
           p.z <= dims.z - 1 + e;
}

// Calls f(c, r, index) for every pixel of g, in tiles on the project's threads; index is the
// pixel's continuous index in `v`'s grid.
template <class F>
void for_each_pixel(const Volume& v, const SliceGeometry& g, int threads, F&& f) {
    const WorldToIndex w = world_to_index(v);
    const Vec3d i0 = w.point(g.origin), di = w.vector(g.u), dj = w.vector(g.v);
    parallel_for_tiles(g.width, g.height, kTile, threads, [&](int x0, int y0, int x1, int y1) {
        for (int r = y0; r < y1; ++r)
            for (int c = x0; c < x1; ++c) f(c, r, i0 + di * double(c) + dj * double(r));
    });
}

}  // namespace

std::string to_string(SlicePlane p) {
    switch (p) {
        case SlicePlane::Axial:
            return "axial";
        case SlicePlane::Coronal:
            return "coronal";
        case SlicePlane::Sagittal:
            return "sagittal";
    }
    return "?";
}

SlicePlane parse_slice_plane(const std::string& name, const std::string& where) {
    for (SlicePlane p : {SlicePlane::Axial, SlicePlane::Coronal, SlicePlane::Sagittal})
        if (name == to_string(p)) return p;
    throw Error(where, "plane",
                "unknown '" + name.substr(0, 40) + "'; expected axial, coronal or sagittal");
}

std::string to_string(const SliceGeometry& g) {
    return to_string(g.plane) + " " + std::to_string(g.width) + "x" + std::to_string(g.height) +
           " origin " + to_string(g.origin) + " u " + to_string(g.u) + " v " + to_string(g.v);
}

SliceGeometry slice_geometry(const Volume& v, SlicePlane plane, Vec3d point, const SliceOptions& o,
                             const std::string& where) {
    if (!std::isfinite(point.x) || !std::isfinite(point.y) || !std::isfinite(point.z))
        throw Error(where, "point", "expected finite RAS mm, got " + to_string(point));
    double p = o.pixel_mm;
    if (p == 0) p = std::min({v.spacing.x, v.spacing.y, v.spacing.z});
    if (!std::isfinite(p) || p <= 0)
        throw Error(where, "pixel_mm", "expected a finite positive size, got " + std::to_string(p));
    if (o.max_size < 0) throw Error(where, "max_size", "expected 0 (no cap) or a positive size");
    const PlaneAxes ax = plane_axes(plane);
    // 1. The sampled box's 8 world corners projected on screen right and screen up.
    const Affine a = index_to_world(v);
    const Vec3i d = v.dims();
    double u0 = INFINITY, u1 = -INFINITY, w0 = INFINITY, w1 = -INFINITY;
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3d idx{corner & 1 ? d.x - 1.0 : 0.0, corner & 2 ? d.y - 1.0 : 0.0,
                        corner & 4 ? d.z - 1.0 : 0.0};
        const Vec3d wc = a.apply(idx);
        u0 = std::min(u0, dot(wc, ax.right));
        u1 = std::max(u1, dot(wc, ax.right));
        w0 = std::min(w0, dot(wc, ax.up));
        w1 = std::max(w1, dot(wc, ax.up));
    }
    // 2. Pixels: one per p mm from the low edge (the tolerance keeps an exact multiple exact).
    auto count = [](double extent, double px) { return int(std::floor(extent / px + 1e-9)) + 1; };
    double cw = double(count(u1 - u0, p)), ch = double(count(w1 - w0, p));
    if (o.max_size > 0 && std::max(cw, ch) > o.max_size) {
        // Coarser pixels over the same extent: the longer side gets max_size pixels.
        p = std::max(u1 - u0, w1 - w0) / std::max(1, o.max_size - 1);
        cw = double(count(u1 - u0, p));
        ch = double(count(w1 - w0, p));
        cw = std::min(cw, double(o.max_size));
        ch = std::min(ch, double(o.max_size));
    }
    if (cw > kMaxSliceSide || ch > kMaxSliceSide)
        throw Error(where, "pixel_mm",
                    std::to_string(p) + " mm makes a " + std::to_string(int64_t(cw)) + "x" +
                        std::to_string(int64_t(ch)) + " slice; expected at most " +
                        std::to_string(kMaxSliceSide) + " per side");
    // 3. Column 0 at u0 (screen left), row 0 at w1 (screen top), on the plane through the point.
    SliceGeometry g;
    g.plane = plane;
    g.width = int(cw);
    g.height = int(ch);
    g.pixel_mm = p;
    g.origin = ax.normal * dot(point, ax.normal) + ax.right * u0 + ax.up * w1;
    g.u = ax.right * p;
    g.v = ax.up * -p;
    return g;
}

Slice sample_slice(const Volume& v, const SliceGeometry& g, Interpolation interp, int threads) {
    Slice s;
    s.geometry = g;
    s.values.assign(size_t(g.width) * size_t(g.height), std::numeric_limits<float>::quiet_NaN());
    const Vec3i dims = v.dims();
    visit_voxels(v, [&](const auto* data) {
        const auto grid = kernel::make_grid<int64_t>(data, dims);
        float* out = s.values.data();
        const size_t w = size_t(g.width);
        auto run = [&]<bool kNearest>() {
            for_each_pixel(v, g, threads, [&](int c, int r, Vec3d p) {
                if (!inside_box(p, dims)) return;  // stays NaN
                out[size_t(r) * w + size_t(c)] =
                    kernel::sample<kNearest>(grid, float(p.x), float(p.y), float(p.z));
            });
        };
        if (interp == Interpolation::Nearest)
            run.template operator()<true>();
        else
            run.template operator()<false>();
    });
    return s;
}

Slice sample_slice(const Volume& v, SlicePlane plane, Vec3d point, const SliceOptions& o) {
    return sample_slice(v, slice_geometry(v, plane, point, o), o.interpolation, o.threads);
}

std::vector<int32_t> sample_labels(const Volume& labels, const SliceGeometry& g, int threads) {
    std::vector<int32_t> out(size_t(g.width) * size_t(g.height), -1);
    const Vec3i dims = labels.dims();
    visit_voxels(labels, [&](const auto* data) {
        const auto grid = kernel::make_grid<int64_t>(data, dims);
        for_each_pixel(labels, g, threads, [&](int c, int r, Vec3d p) {
            if (!inside_box(p, dims)) return;
            const float l = kernel::nearest(grid, float(p.x), float(p.y), float(p.z));
            out[size_t(r) * size_t(g.width) + size_t(c)] = l >= 0 ? int32_t(l) : -1;
        });
    });
    return out;
}

Image window_level(const Slice& s, double window, double level, const std::string& where) {
    if (!std::isfinite(window) || window <= 0)
        throw Error(where, "window",
                    "expected a finite positive width, got " + std::to_string(window));
    if (!std::isfinite(level))
        throw Error(where, "level", "expected a finite number, got " + std::to_string(level));
    Image img(s.geometry.width, s.geometry.height);
    const double lo = level - window / 2;
    for (size_t i = 0; i < s.values.size(); ++i) {
        const float x = s.values[i];
        uint8_t grey = 0;
        if (!std::isnan(x))
            grey = uint8_t(std::lround(std::clamp((x - lo) / window, 0.0, 1.0) * 255));
        uint8_t* px = &img.rgba[i * 4];
        px[0] = px[1] = px[2] = grey;
        px[3] = 255;
    }
    return img;
}

void overlay_labels(Image& img, const std::vector<int32_t>& labels, const LabelTable& table,
                    float opacity) {
    const double a = std::clamp(std::isnan(opacity) ? 0.f : opacity, 0.f, 1.f);
    const size_t n = std::min(labels.size(), img.rgba.size() / 4);
    for (size_t i = 0; i < n; ++i) {
        const int32_t l = labels[i];
        if (l <= 0 || l >= table.size() || !table.styles[size_t(l)].visible) continue;
        const LabelStyle& st = table.styles[size_t(l)];
        const float col[3] = {st.r, st.g, st.b};
        uint8_t* px = &img.rgba[i * 4];
        for (int ch = 0; ch < 3; ++ch) {
            const double grey = double(px[ch]);
            const double target = double(std::clamp(col[ch], 0.f, 1.f)) * 255.0;
            px[ch] = uint8_t(std::lround(grey + a * (target - grey)));
        }
    }
}

ProbeResult probe(const Volume& v, Vec3d world, Interpolation interp, const Volume* labels,
                  const LabelTable* table) {
    ProbeResult out;
    out.world = world;
    out.index = world_to_index(v).point(world);
    out.inside = inside_box(out.index, v.dims());
    out.value = std::numeric_limits<float>::quiet_NaN();
    out.voxel_value = out.value;
    if (out.inside) {
        const Vec3i d = v.dims();
        auto round_in = [](double x, int n) {
            return std::clamp(int(std::floor(x + 0.5)), 0, n - 1);
        };
        out.voxel = {round_in(out.index.x, d.x), round_in(out.index.y, d.y),
                     round_in(out.index.z, d.z)};
        out.voxel_value = v.value(out.voxel.x, out.voxel.y, out.voxel.z);
        out.value = visit_voxels(v, [&](const auto* data) {
            const auto grid = kernel::make_grid<int64_t>(data, d);
            const float x = float(out.index.x), y = float(out.index.y), z = float(out.index.z);
            return interp == Interpolation::Nearest ? kernel::nearest(grid, x, y, z)
                                                    : kernel::trilinear(grid, x, y, z);
        });
    }
    if (labels) {
        const Vec3d li = world_to_index(*labels).point(world);
        const Vec3i ld = labels->dims();
        if (inside_box(li, ld)) {
            const float l = visit_voxels(*labels, [&](const auto* data) {
                return kernel::nearest(kernel::make_grid<int64_t>(data, ld), float(li.x),
                                       float(li.y), float(li.z));
            });
            out.label = int(l);
            if (table && *out.label >= 0 && *out.label < table->size())
                out.label_name = table->styles[size_t(*out.label)].name;
        }
    }
    return out;
}

}  // namespace lacuna
