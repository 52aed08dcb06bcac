#include "slice/occlusion_map.h"

#include <algorithm>
#include <cmath>

namespace lacuna {

void MapRect::add(const MapRect& r) {
    if (r.empty()) return;
    if (empty()) {
        *this = r;
        return;
    }
    u0 = std::min(u0, r.u0);
    v0 = std::min(v0, r.v0);
    u1 = std::max(u1, r.u1);
    v1 = std::max(v1, r.v1);
}

MapRect MapRect::intersect(const MapRect& r) const {
    if (empty() || r.empty()) return {};
    return {std::max(u0, r.u0), std::max(v0, r.v0), std::min(u1, r.u1), std::min(v1, r.v1)};
}

OcclusionMap::OcclusionMap(const Camera& cam, Vec3i dims, Vec3d spacing, int size)
    : m_n(std::max(size, 1)), m_persp(cam.projection() == Projection::Perspective) {
    const Vec3d e = Vec3d(cam.eye()), f = Vec3d(cam.forward());
    m_eye = {e.x / spacing.x, e.y / spacing.y, e.z / spacing.z};
    m_dir = {f.x / spacing.x, f.y / spacing.y, f.z / spacing.z};
    m_m = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(m_dir[a]) > std::abs(m_dir[m_m])) m_m = a;
    m_u = (m_m + 1) % 3;
    m_v = (m_m + 2) % 3;
    const double hi_m = double(dims[m_m] - 1);
    if (m_persp) {
        // The face toward the eye; the eye must be outside the volume's slab along m.
        m_valid_geometry = m_eye[m_m] < -1e-3 || m_eye[m_m] > hi_m + 1e-3;
        m_plane = m_eye[m_m] < 0 ? 0.0 : hi_m;
    } else {
        m_plane = m_dir[m_m] > 0 ? 0.0 : hi_m;
    }
    if (!m_valid_geometry) return;
    for (int c = 0; c < 8; ++c) {
        Vec3d x;
        for (int a = 0; a < 3; ++a) x[a] = (c >> a) & 1 ? double(dims[a] - 1) : 0.0;
        double u, v;
        project(x, u, v);
        m_extent.add({u, v, u, v});
    }
    m_cu = std::max((m_extent.u1 - m_extent.u0) / m_n, 1e-9);
    m_cv = std::max((m_extent.v1 - m_extent.v0) / m_n, 1e-9);
    for (int n = m_n;; n = (n + 1) / 2) {
        m_level_n.push_back(n);
        m_levels.emplace_back(size_t(n) * size_t(n), 2.f);
        if (n == 1) break;
    }
}

void OcclusionMap::project(const Vec3d& x, double& u, double& v) const {
    if (m_persp) {
        const double s = (m_plane - m_eye[m_m]) / (x[m_m] - m_eye[m_m]);
        u = m_eye[m_u] + (x[m_u] - m_eye[m_u]) * s;
        v = m_eye[m_v] + (x[m_v] - m_eye[m_v]) * s;
    } else {
        const double s = (m_plane - x[m_m]) / m_dir[m_m];
        u = x[m_u] + m_dir[m_u] * s;
        v = x[m_v] + m_dir[m_v] * s;
    }
}

MapRect OcclusionMap::project_box(const Vec3d& lo, const Vec3d& hi) const {
    MapRect r;
    for (int c = 0; c < 8; ++c) {
        Vec3d x;
        for (int a = 0; a < 3; ++a) x[a] = (c >> a) & 1 ? hi[a] : lo[a];
        double u, v;
        project(x, u, v);
        r.add({u, v, u, v});
    }
    return r;
}

void OcclusionMap::assign_pixels(const std::vector<float>& ox, const std::vector<float>& oy,
                                 const std::vector<float>& oz, const std::vector<float>& dx,
                                 const std::vector<float>& dy, const std::vector<float>& dz) {
    const size_t np = ox.size();
    m_pixel_cells.assign(np * 4, int16_t(-1));
    if (!m_valid_geometry) return;
    // A pixel whose point lies within this margin of a cell border counts for both cells.
    const double eu = 1e-3 * m_cu + 1e-6, ev = 1e-3 * m_cv + 1e-6;
    for (size_t p = 0; p < np; ++p) {
        const Vec3d o{ox[p], oy[p], oz[p]}, d{dx[p], dy[p], dz[p]};
        if (d[m_m] == 0.0) continue;
        const double s = (m_plane - o[m_m]) / d[m_m];
        const double u = o[m_u] + d[m_u] * s, v = o[m_v] + d[m_v] * s;
        const double fu0 = std::floor((u - eu - m_extent.u0) / m_cu);
        const double fu1 = std::floor((u + eu - m_extent.u0) / m_cu);
        const double fv0 = std::floor((v - ev - m_extent.v0) / m_cv);
        const double fv1 = std::floor((v + ev - m_extent.v0) / m_cv);
        if (!(fu1 >= 0 && fu0 < m_n && fv1 >= 0 && fv0 < m_n)) continue;  // off the map (or NaN)
        int16_t* c = &m_pixel_cells[p * 4];
        c[0] = int16_t(std::max(fu0, 0.0));
        c[1] = int16_t(std::min(fu1, double(m_n - 1)));
        c[2] = int16_t(std::max(fv0, 0.0));
        c[3] = int16_t(std::min(fv1, double(m_n - 1)));
    }
}

void OcclusionMap::update(const float* alpha, size_t stride) {
    if (!m_valid_geometry) return;
    std::vector<float>& l0 = m_levels[0];
    std::fill(l0.begin(), l0.end(), 2.f);
    const size_t np = m_pixel_cells.size() / 4;
    for (size_t p = 0; p < np; ++p) {
        const int16_t* c = &m_pixel_cells[p * 4];
        if (c[0] < 0) continue;
        const float a = alpha[p * stride];
        for (int j = c[2]; j <= c[3]; ++j)
            for (int i = c[0]; i <= c[1]; ++i) {
                float& cell = l0[size_t(j) * size_t(m_n) + size_t(i)];
                cell = std::min(cell, a);
            }
    }
    for (size_t l = 1; l < m_levels.size(); ++l) {
        const int n = m_level_n[l], pn = m_level_n[l - 1];
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                float m = 2.f;
                for (int dj = 0; dj < 2; ++dj)
                    for (int di = 0; di < 2; ++di) {
                        const int ci = 2 * i + di, cj = 2 * j + dj;
                        if (ci < pn && cj < pn)
                            m = std::min(m, m_levels[l - 1][size_t(cj) * size_t(pn) + size_t(ci)]);
                    }
                m_levels[l][size_t(j) * size_t(n) + size_t(i)] = m;
            }
    }
    m_valid = true;
}

MapRect OcclusionMap::cell_rect(int i, int j) const {
    return {m_extent.u0 + i * m_cu, m_extent.v0 + j * m_cv, m_extent.u0 + (i + 1) * m_cu,
            m_extent.v0 + (j + 1) * m_cv};
}

void OcclusionMap::visible_node(int level, int i, int j, int i0, int j0, int i1, int j1,
                                float threshold, MapRect& out) const {
    const int n = m_level_n[size_t(level)];
    if (i >= n || j >= n) return;
    const int lo_i = i << level, hi_i = ((i + 1) << level) - 1;
    const int lo_j = j << level, hi_j = ((j + 1) << level) - 1;
    if (hi_i < i0 || lo_i > i1 || hi_j < j0 || lo_j > j1) return;
    if (m_levels[size_t(level)][size_t(j) * size_t(n) + size_t(i)] >= threshold) return;
    if (level == 0) {
        out.add(cell_rect(i, j));
        return;
    }
    for (int dj = 0; dj < 2; ++dj)
        for (int di = 0; di < 2; ++di)
            visible_node(level - 1, 2 * i + di, 2 * j + dj, i0, j0, i1, j1, threshold, out);
}

MapRect OcclusionMap::visible(const MapRect& r, float threshold) const {
    if (!m_valid || !m_valid_geometry || r.empty()) return r;
    MapRect out;
    const MapRect& e = m_extent;
    // Parts of R_p outside the map are visible.
    if (r.u0 < e.u0) out.add({r.u0, r.v0, std::min(r.u1, e.u0), r.v1});
    if (r.u1 > e.u1) out.add({std::max(r.u0, e.u1), r.v0, r.u1, r.v1});
    if (r.v0 < e.v0) out.add({r.u0, r.v0, r.u1, std::min(r.v1, e.v0)});
    if (r.v1 > e.v1) out.add({r.u0, std::max(r.v0, e.v1), r.u1, r.v1});
    // Cells that meet R_p (closed, with a rounding margin), through the hierarchy.
    const double i0 = std::floor((r.u0 - e.u0) / m_cu - 1e-3),
                 i1 = std::floor((r.u1 - e.u0) / m_cu + 1e-3);
    const double j0 = std::floor((r.v0 - e.v0) / m_cv - 1e-3),
                 j1 = std::floor((r.v1 - e.v0) / m_cv + 1e-3);
    if (i1 >= 0 && i0 < m_n && j1 >= 0 && j0 < m_n) {
        MapRect cells;
        const int top = int(m_levels.size()) - 1;
        visible_node(top, 0, 0, int(std::max(i0, 0.0)), int(std::max(j0, 0.0)),
                     int(std::min(i1, double(m_n - 1))), int(std::min(j1, double(m_n - 1))),
                     threshold, cells);
        out.add(cells);
    }
    return out.intersect(r);
}

MapRect OcclusionMap::back_project(const MapRect& r, double depth) const {
    if (r.empty()) return r;
    double a0, a1, b0, b1;
    if (m_persp) {
        const double s = (depth - m_eye[m_m]) / (m_plane - m_eye[m_m]);
        a0 = m_eye[m_u] + (r.u0 - m_eye[m_u]) * s;
        a1 = m_eye[m_u] + (r.u1 - m_eye[m_u]) * s;
        b0 = m_eye[m_v] + (r.v0 - m_eye[m_v]) * s;
        b1 = m_eye[m_v] + (r.v1 - m_eye[m_v]) * s;
    } else {
        const double s = (m_plane - depth) / m_dir[m_m];
        a0 = r.u0 - m_dir[m_u] * s;
        a1 = r.u1 - m_dir[m_u] * s;
        b0 = r.v0 - m_dir[m_v] * s;
        b1 = r.v1 - m_dir[m_v] * s;
    }
    return {std::min(a0, a1), std::min(b0, b1), std::max(a0, a1), std::max(b0, b1)};
}

}  // namespace lacuna
