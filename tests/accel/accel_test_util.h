// Shared helpers for the skipping-structure unit tests: a deterministic PRNG, random volumes and
// LUTs, and the brute-force oracles every structure is compared against (STYLE.md habit 8).
//
// Two notions of a cell's LUT range appear in these tests:
//   brute range    [map(min of the 8 corners), map(max of the 8 corners)], computed here from
//                  Volume::value() with no widening: what "visible cell" means in the brief.
//   built range    what for_each_block_cells reports (slightly widened); the structures are built
//                  from it, so their exact expected answers are computed from it. The CellRanges
//                  tests check built ranges against brute ranges and trilinear samples.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "accel/cell_ranges.h"
#include "accel/region.h"
#include "common/rng.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::accel_test {

using test::Rng;

inline const VoxelType kAllTypes[] = {VoxelType::UInt8, VoxelType::Int16, VoxelType::UInt16,
                                      VoxelType::Float32};

// Values a voxel type can hold (float32: a "typical" range; awkward floats are made separately).
inline void type_limits(VoxelType t, float& lo, float& hi) {
    switch (t) {
        case VoxelType::UInt8:
            lo = 0, hi = 255;
            break;
        case VoxelType::Int16:
            lo = -32768, hi = 32767;
            break;
        case VoxelType::UInt16:
            lo = 0, hi = 65535;
            break;
        case VoxelType::Float32:
            lo = -1, hi = 1;
            break;
    }
}

// A random value of type t in [lo, hi] (integers for integer types).
inline float random_value(VoxelType t, float lo, float hi, Rng& rng) {
    const double v = double(lo) + (double(hi) - double(lo)) * rng.uniform_d();
    if (t == VoxelType::Float32) return float(v);
    return float(std::clamp(std::floor(v + 0.5), double(lo), double(hi)));
}

// An awkward float: huge, tiny, denormal, signed zero, negative, or plain; mixed in one volume.
inline float awkward_float(Rng& rng) {
    const float sign = rng.coin() ? -1.f : 1.f;
    switch (rng.range(0, 7)) {
        case 0:
            return sign * std::pow(10.f, float(rng.range(3, 36))) * (1.f + rng.uniform());
        case 1:
            return sign * std::pow(10.f, -float(rng.range(3, 37))) * (1.f + rng.uniform());
        case 2:
            return sign * 1e-45f * float(rng.range(1, 1000));  // denormals
        case 3:
            return rng.coin() ? 0.f : -0.f;
        case 4:
            return sign * float(rng.range(0, 1 << 24));  // large integers, exact in float
        case 5:
            return sign * (1.f + rng.uniform()) * 1e7f;
        default:
            return sign * rng.uniform();
    }
}

// A small random volume with structure: a background value and random boxes painted with either
// a constant level or per-voxel random values from a random sub-range, so cell ranges vary from
// a single value to the whole range. compute_range() has been called.
inline Volume random_volume(VoxelType t, Vec3i dims, Rng& rng, bool awkward = false) {
    Volume v(dims, t, "random");
    float lo, hi;
    type_limits(t, lo, hi);
    if (t == VoxelType::Int16 && rng.coin()) lo = -1024, hi = 3071;  // CT-like
    if (t == VoxelType::Float32 && !awkward && rng.coin()) {
        const float s = std::pow(10.f, float(rng.range(-3, 6)));
        lo *= s, hi *= s;
    }
    auto value = [&](float a, float b) {
        return awkward ? awkward_float(rng) : random_value(t, a, b, rng);
    };
    const float bg = rng.coin() ? lo : value(lo, hi);
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            for (int i = 0; i < dims.x; ++i) v.set_value(i, j, k, bg);
    const int boxes = rng.range(0, 6);
    for (int b = 0; b < boxes; ++b) {
        int b0[3], b1[3];
        for (int a = 0; a < 3; ++a) {
            const int n = dims[a];
            b0[a] = rng.range(0, n - 1);
            b1[a] = std::min(n - 1, b0[a] + rng.range(0, std::max(1, n / 2)));
        }
        float s0 = value(lo, hi), s1 = value(lo, hi);
        if (s0 > s1) std::swap(s0, s1);
        const bool constant = rng.coin(3);
        for (int k = b0[2]; k <= b1[2]; ++k)
            for (int j = b0[1]; j <= b1[1]; ++j)
                for (int i = b0[0]; i <= b1[0]; ++i)
                    v.set_value(
                        i, j, k,
                        constant ? s0
                                 : (awkward ? awkward_float(rng) : random_value(t, s0, s1, rng)));
    }
    // A few isolated points (the sharpest case for a structure).
    const int points = rng.range(0, 8);
    for (int p = 0; p < points; ++p)
        v.set_value(rng.range(0, dims.x - 1), rng.range(0, dims.y - 1), rng.range(0, dims.z - 1),
                    value(lo, hi));
    v.compute_range("random");
    return v;
}

inline Vec3i random_dims(Rng& rng, int lo, int hi) {
    return {rng.range(lo, hi), rng.range(lo, hi), rng.range(lo, hi)};
}

inline TransferLut empty_lut(ValueRange vis, int size = kDefaultLutSize) {
    TransferLut lut;
    lut.vis = vis;
    lut.entries.assign(size_t(size), Rgba{});
    return lut;
}

// A random LUT over `vis`: one spike, several spikes, bumps, all transparent or all opaque, with
// opacities down to denormals (any a > 0 is visible). `hits` are entries the data actually
// reads; spikes prefer them so that something is visible.
inline TransferLut random_lut(ValueRange vis, int size, Rng& rng,
                              const std::vector<int>& hits = {}) {
    TransferLut lut = empty_lut(vis, size);
    auto opacity = [&] {
        switch (rng.range(0, 4)) {
            case 0:
                return 1e-45f;
            case 1:
                return 1e-30f;
            case 2:
                return 1.f;
            default:
                return 0.01f + 0.99f * rng.uniform();
        }
    };
    auto entry = [&] {
        if (!hits.empty() && rng.coin(3) == false) {
            const int e = hits[size_t(rng.range(0, int(hits.size()) - 1))] + rng.range(-1, 1);
            return std::clamp(e, 0, size - 1);
        }
        return rng.range(0, size - 1);
    };
    switch (rng.range(0, 9)) {
        case 0:
            break;  // all transparent
        case 1:
            for (auto& e : lut.entries) e.a = opacity();
            break;
        case 2:
        case 3:
        case 4:
            lut.entries[size_t(entry())].a = opacity();
            break;  // a single-entry spike
        case 5:
        case 6: {
            const int n = rng.range(2, 6);
            for (int s = 0; s < n; ++s) lut.entries[size_t(entry())].a = opacity();
            break;
        }
        default: {
            const int n = rng.range(1, 3);
            for (int s = 0; s < n; ++s) {
                const int c = entry(), w = rng.range(0, std::max(1, size / 16));
                for (int e = std::max(0, c - w); e <= std::min(size - 1, c + w); ++e)
                    lut.entries[size_t(e)].a = opacity();
            }
        }
    }
    for (auto& e : lut.entries) e.r = e.a > 0 ? 0.5f : 0.f;
    return lut;
}

// Brute-force scan: does any entry in [lo, hi] have non-zero opacity?
inline bool scan_visible(const TransferLut& lut, int lo, int hi) {
    for (int e = lo; e <= hi; ++e)
        if (lut.entries[size_t(e)].a > 0.f) return true;
    return false;
}

// Per-cell data over the whole grid, x fastest.
struct CellGrid {
    int n[3] = {0, 0, 0};
    size_t count() const { return size_t(n[0]) * n[1] * n[2]; }
    size_t index(int i, int j, int k) const { return (size_t(k) * n[1] + j) * n[0] + i; }
};

inline CellGrid cell_grid(const Volume& v) {
    CellGrid g;
    cell_counts(v, g.n);
    return g;
}

// Brute range of every cell: min/max of its 8 corners (Volume::value), mapped, no widening.
struct BruteRanges {
    CellGrid g;
    std::vector<int> lo, hi;
    std::vector<float> vmin, vmax;
};

inline BruteRanges brute_ranges(const Volume& v, ValueToLut map) {
    BruteRanges r;
    r.g = cell_grid(v);
    const size_t n = r.g.count();
    r.lo.resize(n), r.hi.resize(n), r.vmin.resize(n), r.vmax.resize(n);
    for (int k = 0; k < r.g.n[2]; ++k)
        for (int j = 0; j < r.g.n[1]; ++j)
            for (int i = 0; i < r.g.n[0]; ++i) {
                float a = INFINITY, b = -INFINITY;
                for (int c = 0; c < 8; ++c) {
                    const float x = v.value(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                    a = std::min(a, x);
                    b = std::max(b, x);
                }
                const size_t id = r.g.index(i, j, k);
                r.vmin[id] = a, r.vmax[id] = b;
                r.lo[id] = map(a), r.hi[id] = map(b);
            }
    return r;
}

// Built ranges of every cell, gathered from for_each_block_cells into one grid.
struct BuiltRanges {
    CellGrid g;
    std::vector<int> lo, hi;
};

// edge > 0: from for_each_block_cells with that block edge; edge < 0: from for_each_cell_row
// with slabs of -edge cell layers (what the structures build from).
inline BuiltRanges built_ranges(const Volume& v, ValueToLut map, int edge = 4, int threads = 1) {
    BuiltRanges r;
    r.g = cell_grid(v);
    r.lo.assign(r.g.count(), -1), r.hi.assign(r.g.count(), -1);
    if (edge < 0) {
        for_each_cell_row(v, map, -edge, threads, [&](const CellRow& row) {
            for (int i = 0; i < row.n; ++i) {
                const size_t id = r.g.index(i, row.j, row.k);
                r.lo[id] = row.lo[i], r.hi[id] = row.hi[i];
            }
        });
        return r;
    }
    for_each_block_cells(v, map, edge, threads, [&](const BlockCells& b) {
        for (int k = 0; k < b.n[2]; ++k)
            for (int j = 0; j < b.n[1]; ++j)
                for (int i = 0; i < b.n[0]; ++i) {
                    const size_t c = (size_t(k) * b.n[1] + j) * b.n[0] + i;
                    const size_t id = r.g.index(b.c0[0] + i, b.c0[1] + j, b.c0[2] + k);
                    r.lo[id] = b.lo[c], r.hi[id] = b.hi[c];
                }
    });
    return r;
}

// Summed-volume table over a per-cell 0/1 flag: O(1) "any flagged cell in this box?".
class BoxCount {
  public:
    BoxCount() = default;
    BoxCount(const CellGrid& g, const std::vector<uint8_t>& flag) : m_g(g) {
        const int X = g.n[0] + 1, Y = g.n[1] + 1, Z = g.n[2] + 1;
        m_s.assign(size_t(X) * Y * Z, 0);
        for (int k = 1; k < Z; ++k)
            for (int j = 1; j < Y; ++j)
                for (int i = 1; i < X; ++i)
                    at(i, j, k) = int64_t(flag[g.index(i - 1, j - 1, k - 1)]) + at(i - 1, j, k) +
                                  at(i, j - 1, k) + at(i, j, k - 1) - at(i - 1, j - 1, k) -
                                  at(i - 1, j, k - 1) - at(i, j - 1, k - 1) +
                                  at(i - 1, j - 1, k - 1);
    }
    int64_t count(const CellBox& b) const {
        const int *l = b.lo, *h = b.hi;
        return get(h[0], h[1], h[2]) - get(l[0], h[1], h[2]) - get(h[0], l[1], h[2]) -
               get(h[0], h[1], l[2]) + get(l[0], l[1], h[2]) + get(l[0], h[1], l[2]) +
               get(h[0], l[1], l[2]) - get(l[0], l[1], l[2]);
    }

  private:
    int64_t& at(int i, int j, int k) {
        return m_s[(size_t(k) * (m_g.n[1] + 1) + j) * (m_g.n[0] + 1) + i];
    }
    int64_t get(int i, int j, int k) const {
        return m_s[(size_t(k) * (m_g.n[1] + 1) + j) * (m_g.n[0] + 1) + i];
    }
    CellGrid m_g;
    std::vector<int64_t> m_s;
};

// Flags cells whose [lo, hi] holds a visible entry (brute-force scan).
inline std::vector<uint8_t> visible_cells(const TransferLut& lut, const std::vector<int>& lo,
                                          const std::vector<int>& hi) {
    std::vector<uint8_t> f(lo.size());
    for (size_t c = 0; c < lo.size(); ++c) f[c] = scan_visible(lut, lo[c], hi[c]);
    return f;
}

inline std::string box_string(const CellBox& b) {
    return "[" + std::to_string(b.lo[0]) + "," + std::to_string(b.hi[0]) + ")x[" +
           std::to_string(b.lo[1]) + "," + std::to_string(b.hi[1]) + ")x[" +
           std::to_string(b.lo[2]) + "," + std::to_string(b.hi[2]) + ")";
}
inline bool same_box(const CellBox& a, const CellBox& b) {
    return std::memcmp(&a, &b, sizeof(CellBox)) == 0;
}
inline bool same_region(const Region& a, const Region& b) {
    return a.empty == b.empty && same_box(a.box, b.box);
}
inline std::string region_string(const Region& r) {
    return std::string(r.empty ? "empty " : "occupied ") + box_string(r.box);
}
inline std::string cell_string(const int c[3]) {
    return "cell (" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," +
           std::to_string(c[2]) + ")";
}

// (a): the region's box contains the cell and lies within the grid.
inline ::testing::AssertionResult box_contains_cell(const Region& r, const int cell[3],
                                                    const int cells[3]) {
    for (int a = 0; a < 3; ++a)
        if (r.box.lo[a] < 0 || r.box.hi[a] > cells[a] || r.box.lo[a] > cell[a] ||
            cell[a] >= r.box.hi[a])
            return ::testing::AssertionFailure()
                   << region_string(r) << " does not contain " << cell_string(cell)
                   << " within grid " << cells[0] << "x" << cells[1] << "x" << cells[2];
    return ::testing::AssertionSuccess();
}

inline std::string describe(const Volume& v, const TransferLut& lut) {
    return to_string(v) + " vis " + std::to_string(lut.vis.min) + ".." +
           std::to_string(lut.vis.max) + " lut size " + std::to_string(lut.size());
}

// Entries the data reads at its voxels (spike targets that make something visible).
inline std::vector<int> voxel_entries(const Volume& v, ValueToLut map, Rng& rng, int count = 16) {
    std::vector<int> out;
    const Vec3i d = v.dims();
    for (int s = 0; s < count; ++s)
        out.push_back(
            map(v.value(rng.range(0, d.x - 1), rng.range(0, d.y - 1), rng.range(0, d.z - 1))));
    return out;
}

// A random visualization range: the data range, or a window inside or around it.
inline ValueRange random_vis(const Volume& v, Rng& rng) {
    const ValueRange d = v.vis_range();
    if (rng.coin()) return d;
    const double w = double(d.max) - double(d.min);
    double a = double(d.min) + w * (rng.uniform_d() * 1.2 - 0.1);
    double b = double(d.min) + w * (rng.uniform_d() * 1.2 - 0.1);
    if (a > b) std::swap(a, b);
    if (b - a < w * 1e-3 + 1e-6) b = a + w * 1e-3 + 1e-3;
    ValueRange r{float(a), float(b)};
    if (!(r.max > r.min)) r.max = std::nextafter(r.min, INFINITY);
    return r;
}

}  // namespace lacuna::accel_test
