#include "accel/cell_ranges.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <limits>
#include <type_traits>

#include "core/parallel.h"

namespace lacuna {

namespace {

// LUT-entry bounds of one voxel value, widened on both sides. Float trilinear arithmetic (even on
// integer corners, once fractions enter) can land a few ulps outside the corner range, and those
// ulps are ulps of the *largest* corner of the cell, not of this voxel: a far-face sample
// a + (b - a) * 1 beside a huge corner a misses a small b by ulp(a). So the widening is relative
// to the largest magnitude in the data and the visualization range (2e-6, about 16 ulps), plus
// 1e-6 of the value itself for volumes whose data range was never scanned. Integer voxels: two
// tables over every possible value.
template <class T>
struct VoxelLut {
    static constexpr bool kTable = sizeof(T) <= 2 && std::is_integral_v<T>;
    std::vector<uint16_t> lo_table, hi_table;
    ValueToLut map;
    float widen = 0;
    VoxelLut(ValueToLut m, ValueRange vis, ValueRange data)
        : map(m),
          widen(2e-6f * std::max({std::abs(vis.min), std::abs(vis.max), std::abs(data.min),
                                  std::abs(data.max)})) {
        if constexpr (kTable) {
            const int lo = std::numeric_limits<T>::min(), hi = std::numeric_limits<T>::max();
            lo_table.resize(size_t(hi - lo + 1));
            hi_table.resize(size_t(hi - lo + 1));
            for (int x = lo; x <= hi; ++x) {
                uint16_t a, b;
                compute(float(x), a, b);
                lo_table[size_t(x - lo)] = a;
                hi_table[size_t(x - lo)] = b;
            }
        }
    }
    void compute(float x, uint16_t& lo, uint16_t& hi) const {
        const float w = widen + 1e-6f * std::abs(x);
        lo = uint16_t(map(x - w));
        hi = uint16_t(map(x + w));
    }
    // Integer voxels only: the table bounds of one value.
    uint16_t lower(T x) const {
        return lo_table[size_t(int(x) - int(std::numeric_limits<T>::min()))];
    }
    uint16_t upper(T x) const {
        return hi_table[size_t(int(x) - int(std::numeric_limits<T>::min()))];
    }
    void bounds(T x, uint16_t& lo, uint16_t& hi) const {
        if constexpr (kTable) {
            const size_t e = size_t(int(x) - int(std::numeric_limits<T>::min()));
            lo = lo_table[e];
            hi = hi_table[e];
        } else {
            compute(float(x), lo, hi);
        }
    }
};

template <class T>
void blocks_typed(const Volume& v, const T* data, ValueToLut map, int edge, int threads,
                  const std::function<void(const BlockCells&)>& fn) {
    int cells[3];
    cell_counts(v, cells);
    int nb[3];
    for (int a = 0; a < 3; ++a) nb[a] = (cells[a] + edge - 1) / edge;
    const VoxelLut<T> vl(map, v.vis_range(), v.data_range());
    const Vec3i d = v.dims();
    const size_t sy = size_t(d.x), sz = size_t(d.x) * size_t(d.y);
    parallel_for(size_t(nb[2]) * size_t(nb[1]), threads, [&](size_t b0, size_t b1) {
        const size_t m = size_t(edge + 1);
        std::vector<uint16_t> vlo(m * m * m), vhi(m * m * m), clo(m * m * m), chi(m * m * m);
        for (size_t b = b0; b < b1; ++b) {
            const int bz = int(b / size_t(nb[1])), by = int(b % size_t(nb[1]));
            for (int bx = 0; bx < nb[0]; ++bx) {
                BlockCells bc;
                bc.block[0] = bx, bc.block[1] = by, bc.block[2] = bz;
                bc.c0[0] = bx * edge, bc.c0[1] = by * edge, bc.c0[2] = bz * edge;
                for (int a = 0; a < 3; ++a) bc.n[a] = std::min(edge, cells[a] - bc.c0[a]);
                const int vx = bc.n[0] + 1, vy = bc.n[1] + 1, vz = bc.n[2] + 1;
                // 1. Voxel LUT bounds of the block's (n+1)^3 voxels.
                for (int k = 0; k < vz; ++k)
                    for (int j = 0; j < vy; ++j) {
                        const T* row = data + size_t(bc.c0[2] + k) * sz +
                                       size_t(bc.c0[1] + j) * sy + size_t(bc.c0[0]);
                        uint16_t* lo = &vlo[(size_t(k) * vy + j) * vx];
                        uint16_t* hi = &vhi[(size_t(k) * vy + j) * vx];
                        for (int i = 0; i < vx; ++i) vl.bounds(row[i], lo[i], hi[i]);
                    }
                // 2. Separable min/max over pairs: x, then y, then z. Each pass shrinks one
                // axis by one; the result has n cells per axis.
                auto pass = [](const uint16_t* in, uint16_t* out, int nx, int ny, int nz, int ax,
                               bool take_max) {
                    const int ox = nx - (ax == 0), oy = ny - (ax == 1), oz = nz - (ax == 2);
                    const size_t step = ax == 0 ? 1 : (ax == 1 ? size_t(nx) : size_t(nx) * ny);
                    for (int k = 0; k < oz; ++k)
                        for (int j = 0; j < oy; ++j) {
                            const uint16_t* a = in + (size_t(k) * ny + j) * nx;
                            uint16_t* o = out + (size_t(k) * oy + j) * ox;
                            for (int i = 0; i < ox; ++i)
                                o[i] = take_max ? std::max(a[i], a[i + step])
                                                : std::min(a[i], a[i + step]);
                        }
                };
                pass(vlo.data(), clo.data(), vx, vy, vz, 0, false);
                pass(clo.data(), vlo.data(), vx - 1, vy, vz, 1, false);
                pass(vlo.data(), clo.data(), vx - 1, vy - 1, vz, 2, false);
                pass(vhi.data(), chi.data(), vx, vy, vz, 0, true);
                pass(chi.data(), vhi.data(), vx - 1, vy, vz, 1, true);
                pass(vhi.data(), chi.data(), vx - 1, vy - 1, vz, 2, true);
                bc.lo = clo.data();
                bc.hi = chi.data();
                fn(bc);
            }
        }
    });
}

// Pair reduction of one voxel plane: out[j][i] = op over voxels (i..i+1, j..j+1).
template <bool Max, class V>
void reduce_plane(const V* in, V* out, int vx, int vy) {
    for (int j = 0; j + 1 < vy; ++j) {
        const V* a = in + size_t(j) * vx;
        const V* b = a + vx;
        V* o = out + size_t(j) * (vx - 1);
        for (int i = 0; i + 1 < vx; ++i) {
            const V x = Max ? std::max(a[i], a[i + 1]) : std::min(a[i], a[i + 1]);
            const V y = Max ? std::max(b[i], b[i + 1]) : std::min(b[i], b[i + 1]);
            o[i] = Max ? std::max(x, y) : std::min(x, y);
        }
    }
}

// Per chunk of `chunk` values of one row the min (or max): passes of pairwise op at doubling
// distance over a padded copy (plain loops the compiler vectorises) until tmp[i] covers the
// p = largest power of two <= chunk values from i; then chunk q is op(tmp[q*chunk],
// tmp[q*chunk + chunk - p]) (two overlapping windows, as in a sparse table). tmp holds n rounded
// up to chunks plus one chunk.
template <bool Max, class V>
void chunk_reduce(const V* in, V* __restrict out, int n, int chunk, V* __restrict tmp) {
    const int nq = (n + chunk - 1) / chunk, len = nq * chunk;
    const V neutral = Max ? std::numeric_limits<V>::lowest() : std::numeric_limits<V>::max();
    std::copy(in, in + n, tmp);
    std::fill(tmp + n, tmp + len + chunk, neutral);
    int p = 1;
    for (; 2 * p <= chunk; p *= 2)
        for (int i = 0; i < len; ++i)
            tmp[i] = Max ? std::max(tmp[i], tmp[i + p]) : std::min(tmp[i], tmp[i + p]);
    const int off = chunk - p;
    for (int q = 0; q < nq; ++q) {
        const V a = tmp[size_t(q) * chunk], b = tmp[size_t(q) * chunk + off];
        out[q] = Max ? std::max(a, b) : std::min(a, b);
    }
}

// Streams cells row by row; every voxel plane is reduced once (2x2 pairs in the plane, then
// pairs of planes). Integer voxels: the reduction runs on the raw values and only each cell's
// min and max corner are mapped to LUT entries (the voxel bounds are monotone in the value, so
// the lowest lower bound is that of the smallest corner: same answer, half the memory traffic
// and a quarter of the table lookups). Float voxels map every voxel first (NaN-free order).
// Chunked (chunk > 0): per row the chunk unions, cells mapped only when asked for (CellChunkRow).
template <class T, class Fn>
void rows_typed(const Volume& v, const T* data, ValueToLut map, int slab, int chunk, int threads,
                const Fn& fn) {
    const Vec3i d = v.dims();
    const int cz = d.z - 1, cx = d.x - 1, cy = d.y - 1;
    const int nslabs = (cz + slab - 1) / slab;
    const VoxelLut<T> vl(map, v.vis_range(), v.data_range());
    constexpr bool kRaw = VoxelLut<T>::kTable;
    using V = std::conditional_t<kRaw, T, uint16_t>;  // type of the reduced planes
    const size_t plane = size_t(d.x) * size_t(d.y), cplane = size_t(cx) * size_t(cy);
    const int nchunks = chunk > 0 ? (cx + chunk - 1) / chunk : 0;
    parallel_for(size_t(nslabs), threads, [&](size_t s0, size_t s1) {
        std::vector<uint16_t> vlo(kRaw ? 0 : plane), vhi(kRaw ? 0 : plane);
        // Reduced planes of the current pair of voxel planes (ping-pong) and the cell layer.
        std::vector<V> plo[2] = {std::vector<V>(cplane), std::vector<V>(cplane)};
        std::vector<V> phi[2] = {std::vector<V>(cplane), std::vector<V>(cplane)};
        std::vector<uint16_t> clo(static_cast<size_t>(cx)), chi(static_cast<size_t>(cx));
        // Chunked: per plane and row the chunk min/max of the in-plane reduction (ping-pong).
        const size_t qplane = size_t(nchunks) * size_t(cy);
        std::vector<V> pqlo[2] = {std::vector<V>(qplane), std::vector<V>(qplane)};
        std::vector<V> pqhi[2] = {std::vector<V>(qplane), std::vector<V>(qplane)};
        std::vector<V> tmp(chunk > 0 ? size_t(nchunks + 1) * size_t(chunk) : 0);
        std::vector<uint16_t> qlo(static_cast<size_t>(nchunks)), qhi(static_cast<size_t>(nchunks));
        auto load = [&](int z, int slot) {
            const T* src = data + size_t(z) * plane;
            if constexpr (kRaw) {
                reduce_plane<false>(src, plo[slot].data(), d.x, d.y);
                reduce_plane<true>(src, phi[slot].data(), d.x, d.y);
            } else {
                for (size_t i = 0; i < plane; ++i) vl.bounds(src[i], vlo[i], vhi[i]);
                reduce_plane<false>(vlo.data(), plo[slot].data(), d.x, d.y);
                reduce_plane<true>(vhi.data(), phi[slot].data(), d.x, d.y);
            }
            if (chunk > 0)
                for (int j = 0; j < cy; ++j) {
                    const size_t r = size_t(j) * cx, q = size_t(j) * nchunks;
                    chunk_reduce<false>(plo[slot].data() + r, pqlo[slot].data() + q, cx, chunk,
                                        tmp.data());
                    chunk_reduce<true>(phi[slot].data() + r, pqhi[slot].data() + q, cx, chunk,
                                       tmp.data());
                }
        };
        // Chunked rows: what cells() reads.
        struct Ctx {
            const V *a, *b, *c, *e;  // the row in the two reduced planes (min, then max)
            const VoxelLut<T>* vl;
        } ctx{nullptr, nullptr, nullptr, nullptr, &vl};
        auto map_cells = [](const void* c, int i0, int i1, uint16_t* lo, uint16_t* hi) {
            const Ctx& x = *static_cast<const Ctx*>(c);
            for (int i = i0; i < i1; ++i) {
                if constexpr (VoxelLut<T>::kTable) {
                    lo[i - i0] = x.vl->lower(std::min(x.a[i], x.b[i]));
                    hi[i - i0] = x.vl->upper(std::max(x.c[i], x.e[i]));
                } else {
                    lo[i - i0] = std::min(x.a[i], x.b[i]);
                    hi[i - i0] = std::max(x.c[i], x.e[i]);
                }
            }
        };
        for (size_t sl = s0; sl < s1; ++sl) {
            const int k0 = int(sl) * slab, k1 = std::min(cz, k0 + slab);
            load(k0, 0);
            for (int k = k0; k < k1; ++k) {
                const int cur = (k - k0) & 1, nxt = cur ^ 1;
                load(k + 1, nxt);
                for (int j = 0; j < cy; ++j) {
                    const V* a = plo[cur].data() + size_t(j) * cx;
                    const V* b = plo[nxt].data() + size_t(j) * cx;
                    const V* c = phi[cur].data() + size_t(j) * cx;
                    const V* e = phi[nxt].data() + size_t(j) * cx;
                    if (chunk > 0) {
                        const size_t r = size_t(j) * nchunks;
                        const V* ql0 = pqlo[cur].data() + r;
                        const V* ql1 = pqlo[nxt].data() + r;
                        const V* qh0 = pqhi[cur].data() + r;
                        const V* qh1 = pqhi[nxt].data() + r;
                        for (int q = 0; q < nchunks; ++q) {
                            const V l = std::min(ql0[q], ql1[q]), h = std::max(qh0[q], qh1[q]);
                            if constexpr (kRaw) {
                                qlo[size_t(q)] = vl.lower(l);
                                qhi[size_t(q)] = vl.upper(h);
                            } else {
                                qlo[size_t(q)] = l;
                                qhi[size_t(q)] = h;
                            }
                        }
                        ctx.a = a, ctx.b = b, ctx.c = c, ctx.e = e;
                        if constexpr (std::is_invocable_v<Fn, const CellChunkRow&>)
                            fn(CellChunkRow{j, k, cx, chunk, qlo.data(), qhi.data(), +map_cells,
                                            &ctx});
                        continue;
                    }
                    if constexpr (kRaw) {
                        for (int i = 0; i < cx; ++i) {
                            clo[size_t(i)] = vl.lower(std::min(a[i], b[i]));
                            chi[size_t(i)] = vl.upper(std::max(c[i], e[i]));
                        }
                    } else {
                        for (int i = 0; i < cx; ++i) {
                            clo[size_t(i)] = std::min(a[i], b[i]);
                            chi[size_t(i)] = std::max(c[i], e[i]);
                        }
                    }
                    if constexpr (std::is_invocable_v<Fn, const CellRow&>)
                        fn(CellRow{j, k, cx, clo.data(), chi.data()});
                }
            }
        }
    });
}

// apron_brick_ranges: per brick row (by, bz) the element-wise min/max of the voxel rows of its
// window (plain loops the compiler vectorises), then per brick the min/max over its x window.
// Integer voxels reduce raw values and map the extremes (the voxel bounds are monotone in the
// value); float voxels map every voxel first, as rows_typed does.
template <class T>
void apron_typed(const Volume& v, const T* data, ValueToLut map, int edge, int threads,
                 std::vector<uint16_t>& out_lo, std::vector<uint16_t>& out_hi) {
    const Vec3i d = v.dims();
    int cells[3], nb[3];
    cell_counts(v, cells);
    for (int a = 0; a < 3; ++a) nb[a] = (cells[a] + edge - 1) / edge;
    const int dv[3] = {d.x, d.y, d.z};
    out_lo.assign(size_t(nb[0]) * nb[1] * nb[2], 0);
    out_hi.assign(out_lo.size(), 0);
    const VoxelLut<T> vl(map, v.vis_range(), v.data_range());
    constexpr bool kRaw = VoxelLut<T>::kTable;
    using V = std::conditional_t<kRaw, T, uint16_t>;
    // Voxel window of brick b on axis a (inclusive).
    auto window = [&](int a, int b, int& v0, int& v1) {
        v0 = std::max(0, edge * b - 1);
        v1 = std::min(dv[a] - 1, edge * b + edge + 1);
    };
    const size_t sy = size_t(d.x), sz = size_t(d.x) * size_t(d.y);
    parallel_for(size_t(nb[1]) * size_t(nb[2]), threads, [&](size_t r0, size_t r1) {
        std::vector<V> mn(static_cast<size_t>(d.x)), mx(static_cast<size_t>(d.x));
        std::vector<uint16_t> flo(kRaw ? 0 : size_t(d.x)), fhi(kRaw ? 0 : size_t(d.x));
        for (size_t r = r0; r < r1; ++r) {
            const int by = int(r % size_t(nb[1])), bz = int(r / size_t(nb[1]));
            int y0, y1, z0, z1;
            window(1, by, y0, y1);
            window(2, bz, z0, z1);
            bool first = true;
            for (int k = z0; k <= z1; ++k)
                for (int j = y0; j <= y1; ++j) {
                    const T* row = data + size_t(k) * sz + size_t(j) * sy;
                    const V* lo_row;
                    const V* hi_row;
                    if constexpr (kRaw) {
                        lo_row = row;
                        hi_row = row;
                    } else {
                        for (int i = 0; i < d.x; ++i)
                            vl.bounds(row[i], flo[size_t(i)], fhi[size_t(i)]);
                        lo_row = flo.data();
                        hi_row = fhi.data();
                    }
                    V* __restrict a = mn.data();
                    V* __restrict b = mx.data();
                    if (first) {
                        std::copy(lo_row, lo_row + d.x, a);
                        std::copy(hi_row, hi_row + d.x, b);
                        first = false;
                        continue;
                    }
                    if constexpr (kRaw) {
                        for (int i = 0; i < d.x; ++i) {
                            const V x = row[i];
                            a[i] = std::min(a[i], x);
                            b[i] = std::max(b[i], x);
                        }
                    } else {
                        for (int i = 0; i < d.x; ++i) a[i] = std::min(a[i], lo_row[i]);
                        for (int i = 0; i < d.x; ++i) b[i] = std::max(b[i], hi_row[i]);
                    }
                }
            const size_t base = (size_t(bz) * nb[1] + by) * nb[0];
            for (int bx = 0; bx < nb[0]; ++bx) {
                int x0, x1;
                window(0, bx, x0, x1);
                V l = mn[size_t(x0)], h = mx[size_t(x0)];
                for (int i = x0 + 1; i <= x1; ++i) {
                    l = std::min(l, mn[size_t(i)]);
                    h = std::max(h, mx[size_t(i)]);
                }
                if constexpr (kRaw) {
                    out_lo[base + bx] = vl.lower(l);
                    out_hi[base + bx] = vl.upper(h);
                } else {
                    out_lo[base + bx] = l;
                    out_hi[base + bx] = h;
                }
            }
        }
    });
}

// visible_cell_mask: per cell row, per occupied brick on it, the column min/max of the row's
// four voxel rows, then per cell the min/max of two columns and one test. Integer voxels test
// raw values against a per-TF threshold table: thr[a] is the smallest raw value b whose upper
// LUT bound reaches the first visible entry at or after a's lower bound, so a cell with corner
// range [a, b] is visible iff b >= thr[a] (both bounds and next_visible are monotone, so the
// table is one merge pass). Float voxels map the two extremes. In parallel over cell layers;
// bits go in with atomic ORs (rows of neighbouring layers can share a word).
template <class T>
void mask_typed(const Volume& v, const T* data, ValueToLut map, const uint16_t* next, int edge,
                const std::function<int(int, int, int)>& brick_state, int threads,
                std::vector<uint32_t>& mask) {
    const Vec3i d = v.dims();
    int cells[3];
    cell_counts(v, cells);
    const size_t sy = size_t(d.x), sz = size_t(d.x) * size_t(d.y);
    mask.assign(v.voxel_count() / 32 + 2, 0u);
    const VoxelLut<T> vl(map, v.vis_range(), v.data_range());
    constexpr bool kRaw = VoxelLut<T>::kTable;
    constexpr int kMin = kRaw ? int(std::numeric_limits<T>::min()) : 0;
    constexpr int kMax = kRaw ? int(std::numeric_limits<T>::max()) : 0;
    std::vector<int> thr;
    if constexpr (kRaw) {
        thr.resize(size_t(kMax - kMin + 1));
        int u = kMin;
        for (int a = kMin; a <= kMax; ++a) {
            const int need = next[vl.lower(T(a))];
            while (u <= kMax && int(vl.upper(T(u))) < need) ++u;
            thr[size_t(a - kMin)] = u;  // kMax + 1: never visible
        }
    }
    const int nbx = (cells[0] + edge - 1) / edge;
    parallel_for(size_t(cells[2]), threads, [&](size_t k0, size_t k1) {
        std::vector<T> cmin(static_cast<size_t>(d.x)), cmax(static_cast<size_t>(d.x));
        std::vector<uint8_t> vis(static_cast<size_t>(cells[0]));
        std::vector<uint8_t> occ(static_cast<size_t>(nbx));
        bool any = false;
        for (int k = int(k0); k < int(k1); ++k)
            for (int j = 0, by = -1; j < cells[1]; ++j) {
                if (j / edge != by) {  // the bricks of this row, once per brick row
                    by = j / edge;
                    any = false;
                    for (int bx = 0; bx < nbx; ++bx)
                        any |= (occ[size_t(bx)] = uint8_t(brick_state(bx, by, k / edge))) != 0;
                }
                if (!any) continue;
                const size_t base = size_t(k) * sz + size_t(j) * sy;
                const T* r00 = data + base;
                const T* r10 = r00 + sy;
                const T* r01 = r00 + sz;
                const T* r11 = r01 + sy;
                std::fill(vis.begin(), vis.end(), uint8_t(0));
                for (int bx = 0; bx < nbx; ++bx) {
                    if (!occ[size_t(bx)]) continue;
                    const int i0 = bx * edge, i1 = std::min(cells[0], i0 + edge);
                    if (occ[size_t(bx)] == 2) {  // every cell visible
                        std::fill(vis.begin() + i0, vis.begin() + i1, uint8_t(1));
                        continue;
                    }
                    for (int x = i0; x <= i1; ++x) {
                        cmin[size_t(x)] =
                            std::min(std::min(r00[x], r10[x]), std::min(r01[x], r11[x]));
                        cmax[size_t(x)] =
                            std::max(std::max(r00[x], r10[x]), std::max(r01[x], r11[x]));
                    }
                    for (int i = i0; i < i1; ++i) {
                        const T a = std::min(cmin[size_t(i)], cmin[size_t(i) + 1]);
                        const T b = std::max(cmax[size_t(i)], cmax[size_t(i) + 1]);
                        if constexpr (kRaw) {
                            vis[size_t(i)] = int(b) >= thr[size_t(int(a) - kMin)];
                        } else {
                            uint16_t lo, hi, l2, h2;
                            vl.compute(float(a), lo, h2);
                            vl.compute(float(b), l2, hi);
                            vis[size_t(i)] = next[lo] <= hi;
                        }
                    }
                }
                // The row's bits into its mask words (offsets base .. base + cells - 1).
                for (int i = 0; i < cells[0];) {
                    const size_t o = base + size_t(i), w = o >> 5;
                    const int n = std::min(cells[0] - i, 32 - int(o & 31));
                    uint32_t bits = 0;
                    for (int q = 0; q < n; ++q) bits |= uint32_t(vis[size_t(i + q)]) << q;
                    if (bits)
                        std::atomic_ref<uint32_t>(mask[w]).fetch_or(bits << (o & 31),
                                                                    std::memory_order_relaxed);
                    i += n;
                }
            }
    });
}

}  // namespace

void apron_brick_ranges(const Volume& v, ValueToLut map, int edge, int threads,
                        std::vector<uint16_t>& lo, std::vector<uint16_t>& hi) {
    visit_voxels(v, [&](const auto* data) { apron_typed(v, data, map, edge, threads, lo, hi); });
}

void for_each_cell_row(const Volume& v, ValueToLut map, int slab, int threads,
                       const std::function<void(const CellRow&)>& fn) {
    visit_voxels(v, [&](const auto* data) { rows_typed(v, data, map, slab, 0, threads, fn); });
}

void for_each_cell_chunk_row(const Volume& v, ValueToLut map, int chunk, int threads,
                             const std::function<void(const CellChunkRow&)>& fn) {
    visit_voxels(v, [&](const auto* data) { rows_typed(v, data, map, chunk, chunk, threads, fn); });
}

void for_each_block_cells(const Volume& v, ValueToLut map, int edge, int threads,
                          const std::function<void(const BlockCells&)>& fn) {
    visit_voxels(v, [&](const auto* data) { blocks_typed(v, data, map, edge, threads, fn); });
}

void visible_cell_mask(const Volume& v, ValueToLut map, const uint16_t* next_visible, int edge,
                       const std::function<int(int, int, int)>& brick_state, int threads,
                       std::vector<uint32_t>& mask) {
    visit_voxels(v, [&](const auto* data) {
        mask_typed(v, data, map, next_visible, edge, brick_state, threads, mask);
    });
}

}  // namespace lacuna
