#include "slice/polygon.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace lacuna {

namespace {

constexpr int edge_axis(int e) {
    return e / 4;
}
// The endpoint of edge e on its axis' lo (end = 0) or hi (end = 1) side.
constexpr int edge_vertex(int e, int end) {
    const int a = e / 4, b = e % 4, a1 = (a + 1) % 3, a2 = (a + 2) % 3;
    return ((b & 1) << a1) | ((b >> 1) << a2) | (end << a);
}
// The edge along axis a through vertex v.
constexpr int vertex_edge(int v, int a) {
    const int a1 = (a + 1) % 3, a2 = (a + 2) % 3;
    return a * 4 + (((v >> a1) & 1) | (((v >> a2) & 1) << 1));
}
// The two faces (axis * 2 + side) an edge lies on.
constexpr int edge_face(int e, int which) {
    const int a = e / 4, b = e % 4;
    return which == 0 ? ((a + 1) % 3) * 2 + (b & 1) : ((a + 2) % 3) * 2 + (b >> 1);
}
constexpr bool share_face(int e, int f) {
    return edge_face(e, 0) == edge_face(f, 0) || edge_face(e, 0) == edge_face(f, 1) ||
           edge_face(e, 1) == edge_face(f, 0) || edge_face(e, 1) == edge_face(f, 1);
}

Vec3d any_perpendicular(Vec3d n) {
    const Vec3d ax = std::abs(n.x) <= std::abs(n.y) && std::abs(n.x) <= std::abs(n.z)
                         ? Vec3d{1, 0, 0}
                         : (std::abs(n.y) <= std::abs(n.z) ? Vec3d{0, 1, 0} : Vec3d{0, 0, 1});
    return normalize(cross(n, ax));
}

}  // namespace

std::string to_string(const SlicePolygon& p) {
    std::string s = "polygon[" + std::to_string(p.count) + "]";
    for (int i = 0; i < p.count; ++i) s += " " + to_string(p.v[size_t(i)]);
    return s;
}

IncrementalSlicer::IncrementalSlicer(Vec3d lo, Vec3d hi, Vec3d n, double c0, double dc)
    : m_lo{lo.x, lo.y, lo.z}, m_hi{hi.x, hi.y, hi.z}, m_n{n.x, n.y, n.z}, m_c(c0), m_dc(dc) {
    m_gmin = INFINITY;
    m_gmax = -INFINITY;
    for (int v = 0; v < 8; ++v) {
        m_gmin = std::min(m_gmin, vertex_g(v));
        m_gmax = std::max(m_gmax, vertex_g(v));
    }
    for (int a = 0; a < 3; ++a) m_delta[a] = m_n[a] != 0.0 ? dc / m_n[a] : 0.0;
    m_list.reserve(kMaxPolygonVertices);
}

double IncrementalSlicer::vertex_g(int v) const {
    double g = 0;
    for (int a = 0; a < 3; ++a) g += m_n[a] * ((v >> a) & 1 ? m_hi[a] : m_lo[a]);
    return g;
}

bool IncrementalSlicer::cuts(int e, double c) const {
    if (m_n[edge_axis(e)] == 0.0) return false;  // parallel: its endpoints' edges carry it
    const double g0 = vertex_g(edge_vertex(e, 0)), g1 = vertex_g(edge_vertex(e, 1));
    return std::min(g0, g1) <= c && c <= std::max(g0, g1);
}

double IncrementalSlicer::intersect(int e, double c) {
    ++m_direct;
    const int a = edge_axis(e);
    const double pos = m_lo[a] + (c - vertex_g(edge_vertex(e, 0))) / m_n[a];
    return std::clamp(pos, m_lo[a], m_hi[a]);
}

// The first plane that meets the box: all 12 edges, sorted by angle around the centroid.
void IncrementalSlicer::initialise() {
    m_list.clear();
    for (int e = 0; e < 12; ++e)
        if (cuts(e, m_c)) m_list.push_back({e, intersect(e, m_c), true});
    SlicePolygon tmp;
    emit(tmp);
    Vec3d cen{0, 0, 0};
    for (int i = 0; i < tmp.count; ++i) cen = cen + tmp.v[size_t(i)];
    cen = cen / double(std::max(tmp.count, 1));
    const Vec3d n{m_n[0], m_n[1], m_n[2]};
    const Vec3d u = any_perpendicular(n), w = normalize(cross(n, u));
    std::vector<std::pair<double, Active>> keyed;
    for (int i = 0; i < tmp.count; ++i) {
        const Vec3d d = tmp.v[size_t(i)] - cen;
        keyed.push_back({std::atan2(dot(d, w), dot(d, u)), m_list[size_t(i)]});
    }
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    for (size_t i = 0; i < keyed.size(); ++i) m_list[i] = keyed[i].second;
}

// One plane further: the loop of Section 3.3.
void IncrementalSlicer::advance() {
    m_c += m_dc;
    if (!m_started || m_list.empty()) return;
    unsigned in_list = 0;
    for (Active& it : m_list) {
        it.updated = false;
        in_list |= 1u << it.edge;
    }
    for (size_t i = 0; i < m_list.size();) {
        Active& it = m_list[i];
        if (it.updated) {
            ++i;
            continue;
        }
        it.updated = true;
        const int a = edge_axis(it.edge);
        const double new_pos = it.pos + m_delta[a];
        if (new_pos >= m_lo[a] && new_pos <= m_hi[a]) {
            it.pos = new_pos;  // still on its edge: one addition
            ++m_incremental;
            ++i;
            continue;
        }
        // Left its edge beyond the end vertex the plane passed: remove it and search the
        // neighbour edges breadth first from that vertex.
        const int removed = it.edge;
        const int start = edge_vertex(removed, m_delta[a] > 0 ? 1 : 0);
        m_list.erase(m_list.begin() + std::ptrdiff_t(i));
        in_list &= ~(1u << removed);
        int found[kMaxPolygonVertices];
        int nfound = 0;
        int queue[8], head = 0, tail = 0;
        unsigned seen = 1u << start;
        queue[tail++] = start;
        while (head < tail) {
            const int v = queue[head++];
            const double gv = vertex_g(v);
            for (int b = 0; b < 3; ++b) {
                const int e = vertex_edge(v, b);
                const int w = v ^ (1 << b);
                const double gw = vertex_g(w);
                if (gw < gv || (gw == gv && m_n[b] != 0.0)) continue;  // behind: not this way
                if (gw >= m_c && m_n[b] != 0.0) {
                    // The new plane cuts e (the vertex v is passed, w is not).
                    if (!(in_list & (1u << e)) && nfound < kMaxPolygonVertices) {
                        found[nfound++] = e;
                        in_list |= 1u << e;
                    }
                } else if (!(seen & (1u << w))) {
                    // w passed as well (or e is parallel to the planes): search on from w.
                    seen |= 1u << w;
                    queue[tail++] = w;
                }
            }
        }
        if (nfound == 0) continue;  // i now points at the next intersection
        // Only the new intersections are ordered: the permutation whose chain predecessor ->
        // new ... -> successor shares faces most often (all links, in a proper cut).
        int order[kMaxPolygonVertices];
        for (int k = 0; k < nfound; ++k) order[k] = k;
        int best[kMaxPolygonVertices];
        int best_score = -1;
        const bool has_nb = !m_list.empty();
        const int pred = has_nb ? m_list[(i + m_list.size() - 1) % m_list.size()].edge : -1;
        const int succ = has_nb ? m_list[i % m_list.size()].edge : -1;
        do {
            int score = 0;
            if (has_nb) score += share_face(pred, found[order[0]]);
            for (int k = 0; k + 1 < nfound; ++k)
                score += share_face(found[order[k]], found[order[k + 1]]);
            if (has_nb) score += share_face(found[order[nfound - 1]], succ);
            if (score > best_score) {
                best_score = score;
                std::copy(order, order + nfound, best);
            }
        } while (std::next_permutation(order, order + nfound));
        for (int k = 0; k < nfound; ++k) {
            const int e = found[best[k]];
            m_list.insert(m_list.begin() + std::ptrdiff_t(i) + k,
                          Active{e, intersect(e, m_c), true});
        }
        i += size_t(nfound);
    }
}

void IncrementalSlicer::emit(SlicePolygon& out) const {
    out.count = 0;
    for (const Active& it : m_list) {
        if (out.count == kMaxPolygonVertices) break;
        const int a = edge_axis(it.edge), v = edge_vertex(it.edge, 0);
        Vec3d p;
        for (int b = 0; b < 3; ++b) p[b] = (v >> b) & 1 ? m_hi[b] : m_lo[b];
        p[a] = it.pos;
        out.v[size_t(out.count++)] = p;
    }
}

void IncrementalSlicer::next(SlicePolygon& out) {
    if (!m_started && m_c >= m_gmin) {
        m_started = true;
        if (m_c <= m_gmax) initialise();
    }
    emit(out);
    advance();  // m_c is now the plane whose polygon the next call returns
}

SlicePolygon clip_plane_against_box(Vec3d lo, Vec3d hi, Vec3d n, double c) {
    const double nn = dot(n, n);
    const Vec3d p0 = n * (c / nn);
    const Vec3d u = any_perpendicular(n), w = normalize(cross(n, u));
    double big = 1;
    for (int a = 0; a < 3; ++a) big = std::max({big, std::abs(lo[a]), std::abs(hi[a])});
    big = 8 * big + 8 * length(p0);
    std::vector<Vec3d> poly = {p0 + u * big + w * big, p0 - u * big + w * big,
                               p0 - u * big - w * big, p0 + u * big - w * big};
    for (int a = 0; a < 3; ++a) {
        for (int side = 0; side < 2; ++side) {
            // Keep p[a] >= lo[a] (side 0) or p[a] <= hi[a] (side 1).
            auto inside = [&](const Vec3d& p) { return side == 0 ? p[a] >= lo[a] : p[a] <= hi[a]; };
            const double bound = side == 0 ? lo[a] : hi[a];
            std::vector<Vec3d> out;
            for (size_t i = 0; i < poly.size(); ++i) {
                const Vec3d& p = poly[i];
                const Vec3d& q = poly[(i + 1) % poly.size()];
                const bool ip = inside(p), iq = inside(q);
                if (ip) out.push_back(p);
                if (ip != iq) {
                    const double t = (bound - p[a]) / (q[a] - p[a]);
                    Vec3d x = p + (q - p) * t;
                    x[a] = bound;
                    out.push_back(x);
                }
            }
            poly.swap(out);
            if (poly.empty()) return {};
        }
    }
    SlicePolygon r;
    for (const Vec3d& p : poly)
        if (r.count < kMaxPolygonVertices) r.v[size_t(r.count++)] = p;
    return r;
}

}  // namespace lacuna
