// The orthogonal opacity map of the growing-boxes paper (Section 4.1-4.3), on the CPU.
//
// The map lies on the plane x_m = P of index space, m the volume axis most parallel to the view
// direction, P the volume face toward the eye; its two axes are the other two volume axes
// (u = (m+1) % 3, v = (m+2) % 3). A point X projects onto it along the line through the eye
// (perspective: a scaling and a translation per depth) or along the view direction
// (orthographic: a translation per depth). The map covers the bounding rectangle of the volume's
// projection with N x N cells.
//
// Every framebuffer pixel's ray is one such projection line, so all samples of pixel p project
// onto the same map point q_p. A cell holds the minimum opacity of the pixels whose q_p falls in
// it (within a rounding margin, a pixel near a cell border counts for both cells); a cell no
// pixel falls in holds 2 (no ray crosses it, nothing behind it can reach the image). Pixel
// opacities only grow while a frame is composited front to back, so a cell's value stays a lower
// bound of the opacity of every pixel whose samples project into it: a region that projects only
// into cells >= T is behind pixels of opacity >= T and skipping it changes each of those pixels
// by at most 1 - T.
//
// The hierarchical map (after Zhang et al. 1997): level 0 is the map, level l+1 the minimum of
// 2x2 cells of level l; a query descends only into nodes whose minimum is below the threshold.
#pragma once
#include <cstdint>
#include <vector>

#include "lacuna/camera.h"
#include "lacuna/math.h"

namespace lacuna {

// A rectangle on the map plane (map-plane coordinates: index-space u and v), closed.
struct MapRect {
    double u0 = 1, v0 = 1, u1 = 0, v1 = 0;  // empty when u0 > u1 or v0 > v1
    bool empty() const { return u0 > u1 || v0 > v1; }
    void add(const MapRect& r);  // bounding rectangle of the union
    MapRect intersect(const MapRect& r) const;
};

class OcclusionMap {
  public:
    // Geometry for one frame: the camera (world space) and the volume (dims, spacing).
    // `valid_geometry()` is false when a perspective eye lies within the volume's slab along m
    // (projection from the eye would fold over); occlusion is then off for the frame.
    OcclusionMap(const Camera& cam, Vec3i dims, Vec3d spacing, int size);
    bool valid_geometry() const { return m_valid_geometry; }
    int axis() const { return m_m; }
    int size() const { return m_n; }

    // The cells of each pixel (once per frame): rays[p] = index-space origin and direction.
    void assign_pixels(const std::vector<float>& ox, const std::vector<float>& oy,
                       const std::vector<float>& oz, const std::vector<float>& dx,
                       const std::vector<float>& dy, const std::vector<float>& dz);
    // Map update: each cell the minimum of its pixels' opacity (alpha[p], p = y * width + x),
    // then the hierarchy.
    void update(const float* alpha, size_t stride);
    bool valid() const { return m_valid; }
    void invalidate() { m_valid = false; }

    // Projection of an index-space point onto the map plane.
    void project(const Vec3d& x, double& u, double& v) const;
    // R_p: the bounding rectangle of the projection of the index-space box [lo, hi].
    MapRect project_box(const Vec3d& lo, const Vec3d& hi) const;
    // R_v: bounding rectangle of the parts of `r` that are visible (cells < threshold, or
    // outside the map).
    MapRect visible(const MapRect& r, float threshold) const;
    // Back-projection of `r` onto the plane x_m = depth (index space), as an index-space
    // rectangle in (u, v).
    MapRect back_project(const MapRect& r, double depth) const;

    float cell(int i, int j) const { return m_levels[0][size_t(j) * size_t(m_n) + size_t(i)]; }
    MapRect extent() const { return m_extent; }

  private:
    void visible_node(int level, int i, int j, int i0, int j0, int i1, int j1, float threshold,
                      MapRect& out) const;
    MapRect cell_rect(int i, int j) const;

    int m_m = 2, m_u = 0, m_v = 1;
    int m_n = 64;
    bool m_persp = true;
    bool m_valid_geometry = true;
    bool m_valid = false;
    double m_plane = 0;      // P
    Vec3d m_eye{}, m_dir{};  // index space (eye for perspective, direction for orthographic)
    MapRect m_extent;
    double m_cu = 1, m_cv = 1;  // cell size
    // Per pixel: cells [i0, i1] x [j0, j1] packed as 4 int16 (i0 = -1: the pixel's ray misses
    // the map).
    std::vector<int16_t> m_pixel_cells;
    std::vector<std::vector<float>> m_levels;  // level l: ceil(n / 2^l)^2 minima
    std::vector<int> m_level_n;
};

}  // namespace lacuna
