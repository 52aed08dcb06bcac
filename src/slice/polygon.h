// Slicing polygons of an axis-aligned box, computed incrementally (growing-boxes paper, Section
// 3.3: the ActiveIntersectionList).
//
// Planes are g(p) = dot(n, p) = c for a fixed normal n (index space) and c = c0, c0 + dc, ...
// (front to back: dc > 0 along n). The first plane that cuts the box is intersected with all 12
// edges "in the traditional way" and its intersections are sorted around their centroid. For
// every next plane:
//   - each active intersection moves along its edge by deltaPos = dc / n[axis] (only the edge's
//     own coordinate changes: axis-aligned edges meet at 90 degrees);
//   - an intersection that leaves its edge is removed, and the edges met behind the end vertex it
//     crossed are searched breadth first (the connection list: the three edges of each box
//     vertex); every edge the new plane cuts that is not active yet is intersected directly;
//   - only the new intersections are ordered, in place of the removed one: the first shares a
//     box face with its predecessor in the list, the last with its successor (consecutive
//     vertices of a slicing polygon always lie on one common face).
// Texture coordinates need no separate increments here: the polygon is in index space, which is
// the texture space of the CPU renderer.
//
// Edge e in 0..11: axis a = e / 4 (the coordinate that varies along it); bit 0 of e % 4 selects
// lo/hi on axis (a+1) % 3, bit 1 on axis (a+2) % 3. Vertex v in 0..7: bit i set = hi on axis i.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "lacuna/math.h"

namespace lacuna {

inline constexpr int kMaxPolygonVertices = 12;  // 6 for a proper cut; duplicates at vertices

struct SlicePolygon {
    int count = 0;
    std::array<Vec3d, kMaxPolygonVertices> v{};  // index space, in cyclic order
};
std::string to_string(const SlicePolygon& p);

class IncrementalSlicer {
  public:
    // The box [lo, hi] (index space, lo <= hi), the plane normal n (index space, non-zero),
    // the first plane value c0 and the spacing dc > 0 of the planes.
    IncrementalSlicer(Vec3d lo, Vec3d hi, Vec3d n, double c0, double dc);
    // The polygon of the current plane (count 0 when it misses the box), then moves to the next.
    void next(SlicePolygon& out);
    double plane() const { return m_c; }
    // Intersections recomputed from scratch (initialisations and edges met by the search) and
    // moved incrementally, since construction.
    long long direct_intersections() const { return m_direct; }
    long long incremental_updates() const { return m_incremental; }

  private:
    struct Active {
        int edge;
        double pos;  // coordinate on the edge's axis
        bool updated;
    };
    double vertex_g(int v) const;
    bool cuts(int edge, double c) const;  // the plane c meets the closed edge
    double intersect(int edge, double c);
    void initialise();
    void advance();
    void emit(SlicePolygon& out) const;

    double m_lo[3], m_hi[3], m_n[3];
    double m_c, m_dc;
    double m_gmin, m_gmax;
    double m_delta[3];           // deltaPos per edge axis (0 for an edge parallel to the planes)
    std::vector<Active> m_list;  // the ActiveIntersectionList, cyclic order
    bool m_started = false;
    long long m_direct = 0, m_incremental = 0;
};

// Reference for tests: the plane dot(n, p) = c clipped against the box by Sutherland-Hodgman
// (a large quad in the plane cut by the six half-spaces), in cyclic order.
SlicePolygon clip_plane_against_box(Vec3d lo, Vec3d hi, Vec3d n, double c);

}  // namespace lacuna
