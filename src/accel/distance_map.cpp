#include "accel/distance_map.h"

#include <chrono>
#include <cmath>
#include <limits>

#include "core/parallel.h"
#include "lacuna/error.h"

namespace lacuna {

namespace {

// Felzenszwalb-Huttenlocher 1D squared distance transform of f (length n) into d.
void edt_1d(const float* f, float* d, int n, int* v, float* z) {
    int k = 0;
    v[0] = 0;
    z[0] = -INFINITY;
    z[1] = INFINITY;
    for (int q = 1; q < n; ++q) {
        float s;
        for (;;) {
            const int p = v[k];
            s = ((f[q] + float(q) * q) - (f[p] + float(p) * p)) / (2.f * float(q - p));
            if (s <= z[k] && k > 0) {
                --k;
                continue;
            }
            if (s <= z[k]) {  // k == 0 and the new parabola dominates everywhere
                v[0] = q;
                z[1] = INFINITY;
                goto next;
            }
            break;
        }
        ++k;
        v[k] = q;
        z[k] = s;
        z[k + 1] = INFINITY;
    next:;
    }
    k = 0;
    for (int q = 0; q < n; ++q) {
        while (z[k + 1] < float(q)) ++k;
        const float dq = float(q - v[k]);
        d[q] = dq * dq + f[v[k]];
    }
}

}  // namespace

DistanceMap::DistanceMap(AccelKind kind, const Volume& v, const AccelOptions& o)
    : Accel(kind), m_volume(v), m_opts(o), m_block(o.distance_block) {
    if (m_block < 1 || m_block > 64) throw FrameError("structure.block", "expected 1..64 cells");
    cell_counts(v, m_cells);
    for (int a = 0; a < 3; ++a) m_nb[a] = (m_cells[a] + m_block - 1) / m_block;
    m_radius.assign(size_t(m_nb[0]) * m_nb[1] * m_nb[2], 0);
    m_stats.nodes = m_radius.size();
    m_stats.bytes = m_radius.size() * sizeof(uint16_t);
}

void DistanceMap::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    OpacityPrefix prefix;
    prefix.build(lut);
    const size_t nx = size_t(m_nb[0]), ny = size_t(m_nb[1]), nz = size_t(m_nb[2]);
    const size_t n = nx * ny * nz;
    // 1. Occupancy per block, conservative: any visible cell.
    std::vector<uint8_t> occ(n, 0);
    for_each_cell_row(m_volume, lut.map(), m_block, m_opts.threads, [&](const CellRow& r) {
        uint8_t* blk = &occ[(size_t(r.k / m_block) * ny + size_t(r.j / m_block)) * nx];
        for (int i0 = 0; i0 < r.n; i0 += m_block, ++blk) {
            if (*blk) continue;
            const int i1 = std::min(r.n, i0 + m_block);
            uint8_t o = 0;
            for (int i = i0; i < i1 && !o; ++i) o = prefix.visible(r.lo[i], r.hi[i]);
            *blk = o;
        }
    });
    const uint16_t kFar = 0xfffe;
    if (kind() == AccelKind::Chebyshev) {
        // 2a. Exact Chebyshev distance: a wavefront over the 26-neighbourhood.
        std::vector<uint16_t> dist(n, kFar);
        std::vector<uint32_t> front, next;
        for (size_t i = 0; i < n; ++i)
            if (occ[i]) dist[i] = 0, front.push_back(uint32_t(i));
        uint16_t level = 0;
        while (!front.empty()) {
            ++level;
            next.clear();
            for (uint32_t i : front) {
                const int x = int(i % nx), y = int((i / nx) % ny), z = int(i / (nx * ny));
                for (int dz = -1; dz <= 1; ++dz)
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            const int X = x + dx, Y = y + dy, Z = z + dz;
                            if (X < 0 || Y < 0 || Z < 0 || X >= int(nx) || Y >= int(ny) ||
                                Z >= int(nz))
                                continue;
                            const size_t j = (size_t(Z) * ny + Y) * nx + X;
                            if (dist[j] == kFar) dist[j] = level, next.push_back(uint32_t(j));
                        }
            }
            front.swap(next);
        }
        // r = D - 1, stored as r + 1 = D; no occupied block at all: the whole grid.
        for (size_t i = 0; i < n; ++i) m_radius[i] = dist[i];
    } else {
        // 2b. Exact squared Euclidean distance, separable (x, then y, then z).
        const float inf = 1e20f;
        std::vector<float> f(n);
        for (size_t i = 0; i < n; ++i) f[i] = occ[i] ? 0.f : inf;
        const size_t dims[3] = {nx, ny, nz};
        const size_t stride[3] = {1, nx, nx * ny};
        for (int ax = 0; ax < 3; ++ax) {
            const int len = int(dims[ax]);
            const int o1 = (ax + 1) % 3, o2 = (ax + 2) % 3;
            const size_t lines = dims[o1] * dims[o2];
            parallel_for(lines, m_opts.threads, [&](size_t l0, size_t l1) {
                std::vector<float> in(static_cast<size_t>(len)), out(static_cast<size_t>(len)),
                    z(static_cast<size_t>(len) + 1);
                std::vector<int> v(static_cast<size_t>(len));
                for (size_t l = l0; l < l1; ++l) {
                    const size_t a = l % dims[o1], b = l / dims[o1];
                    const size_t base = a * stride[o1] + b * stride[o2];
                    for (int q = 0; q < len; ++q) in[size_t(q)] = f[base + size_t(q) * stride[ax]];
                    edt_1d(in.data(), out.data(), len, v.data(), z.data());
                    for (int q = 0; q < len; ++q)
                        f[base + size_t(q) * stride[ax]] = std::min(out[size_t(q)], inf);
                }
            });
        }
        for (size_t i = 0; i < n; ++i) {
            if (occ[i]) {
                m_radius[i] = 0;
                continue;
            }
            if (f[i] >= inf) {  // nothing visible anywhere
                m_radius[i] = kFar;
                continue;
            }
            // Largest integer r with r * sqrt(3) < D, D = sqrt(f): r^2 * 3 < f.
            int r = int(std::sqrt(f[i] / 3.f));
            while (r > 0 && 3.f * float(r) * float(r) >= f[i]) --r;
            while (3.f * float(r + 1) * float(r + 1) < f[i]) ++r;
            m_radius[i] = uint16_t(std::min(r + 1, int(kFar)));
        }
    }
    m_stats.tf_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_stats.build_seconds = m_stats.tf_update_seconds;
}

}  // namespace lacuna
