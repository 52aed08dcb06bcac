#include "accel/brick_grid.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>

#include "core/parallel.h"

namespace lacuna {

BrickGrid::BrickGrid(const Volume& v, const AccelOptions& o) : OctreeBase(AccelKind::Grid, v, o) {
    m_log2 = m_pyr.leaf_log2;  // Pyramid::init validated the edge (power of two, 2..64)
    for (int a = 0; a < 3; ++a) {
        m_nb[a] = (m_pyr.cells[a] + (1 << m_log2) - 1) >> m_log2;
        m_nw[a] = (m_nb[a] + 3) >> 2;
    }
    build();
}

void BrickGrid::build() {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<uint16_t> lo, hi;
    apron_brick_ranges(m_volume, m_map, 1 << m_log2, m_opts.threads, lo, hi);
    const size_t words = size_t(m_nw[0]) * m_nw[1] * m_nw[2];
    m_lo.assign(words * 64, 1);
    m_hi.assign(words * 64, 0);
    for (int z = 0; z < m_nb[2]; ++z)
        for (int y = 0; y < m_nb[1]; ++y)
            for (int x = 0; x < m_nb[0]; ++x) {
                const size_t src = (size_t(z) * m_nb[1] + y) * m_nb[0] + x, dst = slot(x, y, z);
                m_lo[dst] = lo[src];
                m_hi[dst] = hi[src];
            }
    m_words.assign(words, 0);
    m_dist.assign(words, 1);
    m_stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_stats.nodes = size_t(m_nb[0]) * m_nb[1] * m_nb[2];
    m_stats.bytes = m_lo.size() * 4 + m_words.size() * 8;
}

// Chebyshev distance transform of the block grid, separable: per x row the distance to the
// nearest occupied block (two sweeps), then along y and z the min over q of max(|i - q|, f(q))
// (brute force per line: a block grid has tens of blocks per axis). Capped at 255, which only
// shrinks leaps. An all-empty grid gets 255 everywhere.
void BrickGrid::compute_distances() {
    const int nx = m_nw[0], ny = m_nw[1], nz = m_nw[2];
    constexpr int kCap = 255;
    std::vector<int> f(m_words.size());
    auto at = [&](int x, int y, int z) -> int& { return f[(size_t(z) * ny + y) * nx + x]; };
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y) {
            int d = kCap;
            for (int x = 0; x < nx; ++x) {
                d = m_words[(size_t(z) * ny + y) * nx + x] ? 0 : std::min(kCap, d + 1);
                at(x, y, z) = d;
            }
            d = kCap;
            for (int x = nx - 1; x >= 0; --x) {
                d = at(x, y, z) == 0 ? 0 : std::min(kCap, d + 1);
                at(x, y, z) = std::min(at(x, y, z), d);
            }
        }
    std::vector<int> line, out;
    auto pass = [&](int n, auto&& cell) {
        line.resize(size_t(n));
        out.resize(size_t(n));
        for (int i = 0; i < n; ++i) line[size_t(i)] = cell(i);
        for (int i = 0; i < n; ++i) {
            int best = line[size_t(i)];
            for (int q = 0; q < n && best > 0; ++q)
                best = std::min(best, std::max(std::abs(i - q), line[size_t(q)]));
            out[size_t(i)] = best;
        }
        for (int i = 0; i < n; ++i) cell(i) = out[size_t(i)];
    };
    for (int z = 0; z < nz; ++z)
        for (int x = 0; x < nx; ++x) pass(ny, [&](int y) -> int& { return at(x, y, z); });
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) pass(nz, [&](int z) -> int& { return at(x, y, z); });
    for (size_t i = 0; i < f.size(); ++i) m_dist[i] = uint8_t(std::clamp(f[i], 1, kCap));
}

void BrickGrid::brick_range(int x, int y, int z, int& lo, int& hi) const {
    const size_t i = slot(x, y, z);
    lo = m_lo[i];
    hi = m_hi[i];
}

void BrickGrid::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    if (needs_rebuild(lut)) build();
    m_prefix.build(lut);
    // One word per block: 64 prefix-count tests, no branches.
    const size_t n = m_words.size();
    const uint16_t* lo = m_lo.data();
    const uint16_t* hi = m_hi.data();
    for (size_t w = 0; w < n; ++w) {
        uint64_t bits = 0;
        for (int b = 0; b < 64; ++b)
            bits |= uint64_t(m_prefix.visible(lo[w * 64 + b], hi[w * 64 + b])) << b;
        m_words[w] = bits;
    }
    compute_distances();
    m_stats.tf_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lacuna
