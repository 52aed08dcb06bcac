#include "accel/brick_grid.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <type_traits>

#include "accel/cell_ranges.h"
#include "core/parallel.h"

namespace lacuna {

BrickGrid::BrickGrid(const Volume& v, const AccelOptions& o) : OctreeBase(AccelKind::Grid, v, o) {
    m_interpolation = o.interpolation;
    m_log2 = m_pyr.leaf_log2;  // Pyramid::init validated the edge (power of two, 2..64)
    for (int a = 0; a < 3; ++a) {
        m_nb[a] = (m_pyr.cells[a] + (1 << m_log2) - 1) >> m_log2;
        m_nw[a] = (m_nb[a] + 3) >> 2;
    }
    build();
}

void BrickGrid::build() {
    const auto t0 = std::chrono::steady_clock::now();
    m_fine_lo.clear(), m_fine_hi.clear();  // made again, with this map, on the next refine()
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
    m_block_lo.assign(words, 1);
    m_block_hi.assign(words, 0);
    for (size_t w = 0; w < words; ++w)
        for (int b = 0; b < 64; ++b)
            if (m_lo[w * 64 + b] <= m_hi[w * 64 + b]) {
                m_block_lo[w] = std::min(m_block_lo[w], m_lo[w * 64 + b]);
                m_block_hi[w] = std::max(m_block_hi[w], m_hi[w * 64 + b]);
            }
    if (m_interpolation == Interpolation::Nearest) build_nearest_bins();
    m_stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_stats.nodes = size_t(m_nb[0]) * m_nb[1] * m_nb[2];
    m_stats.bytes = m_lo.size() * 4 + m_words.size() * 8 + m_bins.size() * 8;
}

// Per brick the bins of its apron voxels [B*b - 1, B*b + B + 1] (clipped), each voxel mapped as a
// nearest sample maps it (ValueToLut of the value itself). The union over a box is separable: per
// layer of bricks (bz), every voxel row of its apron slices is reduced once along x into per-brick
// masks, then those are ORed over each brick's apron rows in y and z. Integer voxels look their
// bin bit up in a table per value. In parallel over brick layers.
void BrickGrid::build_nearest_bins() {
    const Vec3i d = m_volume.dims();
    const int B = 1 << m_log2, size = m_map.size(), nbx = m_nb[0];
    m_bins.assign(m_lo.size(), 0);
    auto bit_of = [&](float v) { return uint64_t(1) << (int64_t(m_map(v)) * 64 / size); };
    visit_voxels(m_volume, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        constexpr bool kTable = sizeof(T) <= 2;
        constexpr int kBias = std::is_signed_v<T> ? 32768 : 0;
        std::vector<uint64_t> table;
        if constexpr (kTable) {
            table.resize(sizeof(T) == 1 ? 256 : 65536);
            for (size_t i = 0; i < table.size(); ++i) table[i] = bit_of(float(int(i) - kBias));
        }
        parallel_for(size_t(m_nb[2]), m_opts.threads, [&](size_t z0, size_t z1) {
            std::vector<uint64_t> row(size_t(d.x)), xmask;
            for (int bz = int(z0); bz < int(z1); ++bz) {
                const int k0 = std::max(B * bz - 1, 0), k1 = std::min(B * bz + B + 1, d.z - 1);
                // xmask[(k - k0) * d.y + j][bx]: the bins of row (j, k) within brick bx's apron.
                xmask.assign(size_t(k1 - k0 + 1) * size_t(d.y) * size_t(nbx), 0);
                for (int k = k0; k <= k1; ++k)
                    for (int j = 0; j < d.y; ++j) {
                        const T* v = data + (size_t(k) * size_t(d.y) + size_t(j)) * size_t(d.x);
                        for (int i = 0; i < d.x; ++i) {
                            if constexpr (kTable)
                                row[size_t(i)] = table[size_t(int(v[i]) + kBias)];
                            else
                                row[size_t(i)] = bit_of(float(v[i]));
                        }
                        uint64_t* out =
                            &xmask[(size_t(k - k0) * size_t(d.y) + size_t(j)) * size_t(nbx)];
                        for (int bx = 0; bx < nbx; ++bx) {
                            const int i0 = std::max(B * bx - 1, 0),
                                      i1 = std::min(B * bx + B + 1, d.x - 1);
                            uint64_t m = 0;
                            for (int i = i0; i <= i1; ++i) m |= row[size_t(i)];
                            out[bx] = m;
                        }
                    }
                for (int by = 0; by < m_nb[1]; ++by) {
                    const int j0 = std::max(B * by - 1, 0), j1 = std::min(B * by + B + 1, d.y - 1);
                    for (int bx = 0; bx < nbx; ++bx) {
                        uint64_t m = 0;
                        for (int k = k0; k <= k1; ++k)
                            for (int j = j0; j <= j1; ++j)
                                m |=
                                    xmask[(size_t(k - k0) * size_t(d.y) + size_t(j)) * size_t(nbx) +
                                          size_t(bx)];
                        m_bins[slot(bx, by, bz)] = m;
                    }
                }
            }
        });
    });
}

// Chebyshev distance transform of an n[0] x n[1] x n[2] grid (x fastest), separable: per x row
// the distance to the nearest occupied entry (two sweeps), then along y and z the min over q of
// max(|i - q|, f(q)) (brute force per line, outward from i until the distance cannot improve).
// f[i] is 0 where occupied(i); capped at kCap, which only shrinks leaps (a grid with nothing
// occupied gets kCap everywhere).
namespace {
constexpr int kCap = 255;
template <class Occupied>
std::vector<int> chebyshev_distances(const int n[3], Occupied&& occupied) {
    const int nx = n[0], ny = n[1], nz = n[2];
    std::vector<int> f(size_t(nx) * ny * nz);
    auto at = [&](int x, int y, int z) -> int& { return f[(size_t(z) * ny + y) * nx + x]; };
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y) {
            int d = kCap;
            for (int x = 0; x < nx; ++x) {
                d = occupied((size_t(z) * ny + y) * nx + x) ? 0 : std::min(kCap, d + 1);
                at(x, y, z) = d;
            }
            d = kCap;
            for (int x = nx - 1; x >= 0; --x) {
                d = at(x, y, z) == 0 ? 0 : std::min(kCap, d + 1);
                at(x, y, z) = std::min(at(x, y, z), d);
            }
        }
    std::vector<int> line, out;
    auto pass = [&](int len, auto&& cell) {
        line.resize(size_t(len));
        out.resize(size_t(len));
        for (int i = 0; i < len; ++i) line[size_t(i)] = cell(i);
        for (int i = 0; i < len; ++i) {
            int best = line[size_t(i)];
            for (int d = 1; d < best; ++d) {
                if (i - d >= 0) best = std::min(best, std::max(d, line[size_t(i - d)]));
                if (i + d < len) best = std::min(best, std::max(d, line[size_t(i + d)]));
                if (i - d < 0 && i + d >= len) break;
            }
            out[size_t(i)] = best;
        }
        for (int i = 0; i < len; ++i) cell(i) = out[size_t(i)];
    };
    for (int z = 0; z < nz; ++z)
        for (int x = 0; x < nx; ++x) pass(ny, [&](int y) -> int& { return at(x, y, z); });
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) pass(nz, [&](int z) -> int& { return at(x, y, z); });
    return f;
}
}  // namespace

// The leap map's eight octant maps (see leap_map): octant o (bit a set: the ray's dir_a < 0)
// gives brick b the largest d such that every brick of the box reaching d - 1 bricks from b
// toward the octant, prod_a (bit a ? [b_a - d + 1, b_a] : [b_a, b_a + d - 1]), is empty
// (bricks past the grid are empty; capped at kCap). The largest-empty-cube recurrence: the box
// of side d at b is b itself and the seven boxes of side d - 1 at b + s delta, delta in
// {0, 1}^3 minus 0, s the octant's step per axis (any brick p of the box other than b lies in
// the one with delta_a = [p_a != b_a]), so
//     S(b) = occupied(b) ? 0 : min(kCap, 1 + min_delta S(b + s delta)),
// swept against s, in a copy of the grid flipped to s = +1 with one plane of kCap past its
// far faces. `near` holds octant 0's layout: low byte 0 where occupied, high byte the
// sub-bricks (copied into every octant). The inside distances of the fully visible bricks
// (high byte 0xff) follow the same recurrence with "fully visible" for "empty", swept in a
// second copy whose plane past the far faces is 0. One octant per task.
static void octant_distances(const int nf[3], const uint16_t* near, int threads, uint16_t* leap) {
    const int nx = nf[0], ny = nf[1], nz = nf[2];
    const size_t n = size_t(nx) * size_t(ny) * size_t(nz);
    const size_t px = size_t(nx) + 1, pxy = px * (size_t(ny) + 1);
    parallel_for(8, threads, [&](size_t o0, size_t o1) {
        std::vector<uint8_t> s(pxy * (size_t(nz) + 1), uint8_t(kCap));
        std::vector<uint8_t> f(pxy * (size_t(nz) + 1), uint8_t(0));  // inside distances
        for (size_t o = o0; o < o1; ++o) {
            const bool neg[3] = {bool(o & 1), bool(o & 2), bool(o & 4)};
            for (int z = nz - 1; z >= 0; --z)
                for (int y = ny - 1; y >= 0; --y) {
                    // (x, y, z) in the flipped copy is brick (fx, fy, fz) of the grid
                    const int fy = neg[1] ? ny - 1 - y : y, fz = neg[2] ? nz - 1 - z : z;
                    const size_t row = (size_t(fz) * size_t(ny) + size_t(fy)) * size_t(nx);
                    const size_t at = size_t(z) * pxy + size_t(y) * px;
                    uint8_t* c = s.data() + at;
                    const uint8_t* cy = c + px;
                    const uint8_t* cz = c + pxy;
                    const uint8_t* cyz = cz + px;
                    uint8_t* g = f.data() + at;
                    const uint8_t* gy = g + px;
                    const uint8_t* gz = g + pxy;
                    const uint8_t* gyz = gz + px;
                    uint16_t* out = leap + o * n + row;
                    for (int x = nx - 1; x >= 0; --x) {
                        const int fx = neg[0] ? nx - 1 - x : x;
                        const uint16_t e = near[row + size_t(fx)];
                        int d = 0, in = 0;
                        if (e & 0xff) {
                            int m = std::min(
                                {c[x + 1], cy[x], cy[x + 1], cz[x], cz[x + 1], cyz[x], cyz[x + 1]});
                            d = std::min(kCap, m + 1);
                        } else if ((e & 0xff00) == 0xff00) {
                            int m = std::min(
                                {g[x + 1], gy[x], gy[x + 1], gz[x], gz[x + 1], gyz[x], gyz[x + 1]});
                            in = std::min(kCap, m + 1);
                        }
                        c[x] = uint8_t(d);
                        g[x] = uint8_t(in);
                        out[fx] = uint16_t((e & 0xff00) | unsigned(d | in));
                    }
                }
        }
    });
}

// The block grid's distances (the DDA's leaps out of empty blocks), at least 1.
void BrickGrid::compute_distances() {
    const std::vector<int> f = chebyshev_distances(m_nw, [&](size_t i) { return m_words[i] != 0; });
    for (size_t i = 0; i < f.size(); ++i) m_dist[i] = uint8_t(std::clamp(f[i], 1, kCap));
}

void BrickGrid::brick_range(int x, int y, int z, int& lo, int& hi) const {
    const size_t i = slot(x, y, z);
    lo = m_lo[i];
    hi = m_hi[i];
}

// The leap map's high bytes (see leap_map): for every fine brick at distance 0, the sub-bricks
// of 2^3 cells whose apron-inclusive cells hold a bit of the visible-cell mask. Per brick, the
// mask's bits of the 6 x 6 x 6 cells 4b - 1 .. 4b + 4 (clipped to the grid; cells past it are
// never sampled), one row of six along x at a time: row position p = 0..5 is cell 4b - 1 + p,
// sub-brick half 0 covers p = 0..3, half 1 covers p = 2..5 (on every axis).
// A brick whose apron range holds only visible entries (`all_visible(i)`) has every sub-brick
// set without looking.
template <class AllVisible>
static void leap_sub_bricks(const Volume& v, const uint32_t* mask, const int nf[3], int threads,
                            AllVisible&& all_visible, std::vector<uint16_t>& leap) {
    const Vec3i d = v.dims();
    const int cells[3] = {d.x - 1, d.y - 1, d.z - 1};
    const size_t sy = size_t(d.x), sz = size_t(d.x) * size_t(d.y);
    // Bits off .. off + n - 1 of the mask (n <= 6; the mask has two words of padding).
    auto bits = [&](size_t off, int n) {
        const size_t w = off >> 5;
        const uint64_t x = uint64_t(mask[w]) | uint64_t(mask[w + 1]) << 32;
        return unsigned(x >> (off & 31)) & ((1u << n) - 1u);
    };
    auto halves = [](int p) { return (p <= 3 ? 1 : 0) | (p >= 2 ? 2 : 0); };
    parallel_for(size_t(nf[2]), threads, [&](size_t z0, size_t z1) {
        for (int bz = int(z0); bz < int(z1); ++bz)
            for (int by = 0; by < nf[1]; ++by)
                for (int bx = 0; bx < nf[0]; ++bx) {
                    const size_t i =
                        (size_t(bz) * size_t(nf[1]) + size_t(by)) * size_t(nf[0]) + size_t(bx);
                    uint16_t& e = leap[i];
                    if (e != 0) continue;
                    if (all_visible(i)) {
                        e = 0xff00;
                        continue;
                    }
                    const int x0 = std::max(4 * bx - 1, 0), x1 = std::min(4 * bx + 4, cells[0] - 1);
                    unsigned sub = 0;
                    for (int pk = 0; pk < 6; ++pk) {
                        const int k = 4 * bz - 1 + pk;
                        if (k < 0 || k >= cells[2]) continue;
                        for (int pj = 0; pj < 6; ++pj) {
                            const int j = 4 * by - 1 + pj;
                            if (j < 0 || j >= cells[1]) continue;
                            const unsigned row =
                                bits(size_t(k) * sz + size_t(j) * sy + size_t(x0), x1 - x0 + 1)
                                << (x0 - (4 * bx - 1));
                            const unsigned m = (row & 0x0fu ? 1u : 0u) | (row & 0x3cu ? 2u : 0u);
                            if (!m) continue;
                            const int hy = halves(pj), hz = halves(pk);
                            for (int qz = 0; qz < 2; ++qz)
                                for (int qy = 0; qy < 2; ++qy)
                                    if ((hz >> qz & 1) && (hy >> qy & 1))
                                        sub |= m << (2 * qy + 4 * qz);
                        }
                    }
                    e = uint16_t(sub << 8);
                }
    });
}

void BrickGrid::refine() {
    // Built for Nearest, a brick's occupancy also tests voxel bins, so an unoccupied brick may
    // hold cells whose range is visible: the mask (a trilinear notion) would be wrong there, and
    // nearest frames do not read it.
    if (m_interpolation == Interpolation::Nearest || m_mask_ready) return;
    const auto t0 = std::chrono::steady_clock::now();
    // A brick is 0 (empty), 2 when every entry of its apron range is visible (so is every
    // cell's range, which it contains), else 1.
    visible_cell_mask(
        m_volume, m_map, m_next_visible.data(), 1 << m_log2,
        [&](int x, int y, int z) {
            if (!occupied(x, y, z)) return 0;
            const size_t i = slot(x, y, z);
            return m_next_invisible[m_lo[i]] > m_hi[i] ? 2 : 1;
        },
        m_opts.threads, m_mask);
    m_mask_ready = true;
    // The leap map: fine bricks' apron ranges (TF-independent, made on the first refine), their
    // occupancy under this TF, and its Chebyshev distances.
    if (m_fine_lo.empty()) {
        apron_brick_ranges(m_volume, m_map, 1 << kLeapLog2, m_opts.threads, m_fine_lo, m_fine_hi);
        for (int a = 0; a < 3; ++a) m_nf[a] = (m_pyr.cells[a] + (1 << kLeapLog2) - 1) >> kLeapLog2;
    }
    const uint16_t* next = m_next_visible.data();
    const size_t n = size_t(m_nf[0]) * size_t(m_nf[1]) * size_t(m_nf[2]);
    // Octant 0's layout first: occupancy (0 occupied, 1 empty) and the sub-bricks' high bytes.
    std::vector<uint16_t> near(n + 1, 0);
    for (size_t i = 0; i < n; ++i) near[i] = next[m_fine_lo[i]] <= m_fine_hi[i] ? 0 : 1;
    const uint16_t* next_invisible = m_next_invisible.data();
    leap_sub_bricks(
        m_volume, m_mask.data(), m_nf, m_opts.threads,
        [&](size_t i) { return next_invisible[m_fine_lo[i]] > m_fine_hi[i]; }, near);
    m_leap.assign(8 * n + 1, 0);  // padding: kernels read 32-bit words
    octant_distances(m_nf, near.data(), m_opts.threads, m_leap.data());
    find_surface();
    m_stats.refine_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The surface runs (surface_runs()): an occupied brick is on the surface unless all 26
// neighbours are occupied; bricks past the grid count as unoccupied. Zero words are skipped whole.
void BrickGrid::find_surface() {
    m_surface.clear();
    auto occ = [&](int x, int y, int z) {
        return x >= 0 && y >= 0 && z >= 0 && x < m_nb[0] && y < m_nb[1] && z < m_nb[2] &&
               occupied(x, y, z);
    };
    auto surface = [&](int x, int y, int z) {
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if (!occ(x + dx, y + dy, z + dz)) return true;
        return false;
    };
    for (int z = 0; z < m_nb[2]; ++z)
        for (int y = 0; y < m_nb[1]; ++y) {
            int run = -1;  // first brick of the open run
            for (int x = 0; x <= m_nb[0]; ++x) {
                if (x < m_nb[0] && (x & 3) == 0 && word(x, y, z) == 0 && run < 0) {
                    x += 3;  // a block without an occupied brick
                    continue;
                }
                const bool on = x < m_nb[0] && occupied(x, y, z) && surface(x, y, z);
                if (on && run < 0) run = x;
                if (!on && run >= 0) {
                    m_surface.push_back({uint16_t(run), uint16_t(x - 1), uint16_t(y), uint16_t(z)});
                    run = -1;
                }
            }
        }
}

void BrickGrid::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    m_mask_ready = false;
    if (needs_rebuild(lut)) build();
    // The prefix count as one lookup: a range [lo, hi] holds a visible entry iff the first
    // visible entry at or after lo is <= hi. (Empty bricks past the grid: lo = 1 > hi = 0.)
    const int size = lut.size();
    m_next_visible.resize(size_t(size) + 1);
    m_next_visible[size_t(size)] = uint16_t(0xffff);
    m_next_invisible.resize(size_t(size) + 1);
    m_next_invisible[size_t(size)] = uint16_t(0xffff);
    for (int e = size - 1; e >= 0; --e) {
        const bool vis = lut.entries[size_t(e)].a > 0.f;
        m_next_visible[size_t(e)] = vis ? uint16_t(e) : m_next_visible[size_t(e) + 1];
        m_next_invisible[size_t(e)] = vis ? m_next_invisible[size_t(e) + 1] : uint16_t(e);
    }
    m_tf_bins = 0;
    for (int e = 0; e < size; ++e)
        if (lut.entries[size_t(e)].a > 0.f) m_tf_bins |= uint64_t(1) << (int64_t(e) * 64 / size);
    // One word per block, 64 branch-free tests; two threads on big grids.
    const size_t n = m_words.size();
    const uint16_t* lo = m_lo.data();
    const uint16_t* hi = m_hi.data();
    const uint16_t* next = m_next_visible.data();
    auto words = [&](size_t w0, size_t w1) {
        for (size_t w = w0; w < w1; ++w) {
            // Most blocks of sparse data are decided by their union range alone.
            if (next[m_block_lo[w]] > m_block_hi[w]) {
                m_words[w] = 0;
                continue;
            }
            uint64_t bits = 0;
            const uint16_t* l = lo + w * 64;
            const uint16_t* h = hi + w * 64;
            for (int b = 0; b < 64; ++b) bits |= uint64_t(next[l[b]] <= h[b]) << b;
            if (bits && !m_bins.empty()) {
                const uint64_t* bins = m_bins.data() + w * 64;
                for (int b = 0; b < 64; ++b) bits &= ~(uint64_t((bins[b] & m_tf_bins) == 0) << b);
            }
            m_words[w] = bits;
        }
    };
    if (n >= 2048)
        parallel_for(n, m_opts.threads, words, 512);
    else
        words(0, n);
    compute_distances();
    m_stats.tf_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lacuna
