#include "slice/growing_boxes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "accel/cell_ranges.h"
#include "core/parallel.h"
#include "lacuna/error.h"

namespace lacuna {

namespace {

double since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The two axes other than a, x before y before z (so the inner loop runs along x when it can).
void other_axes(int a, int& u, int& w) {
    u = a == 0 ? 1 : 0;
    w = a == 2 ? 1 : 2;
}

// ---- gradient cells --------------------------------------------------------------------------

// Voxel gradient magnitude by central differences (one-sided at the grid border), compared with
// `limit` (value units per voxel) without a square root: 1 when |grad| > limit.
template <class T>
void gradient_cells(const Volume& v, const T* data, float limit, int threads,
                    std::vector<uint8_t>& cell_flags, uint64_t& total) {
    const Vec3i d = v.dims();
    const size_t sy = size_t(d.x), sz = size_t(d.x) * size_t(d.y);
    std::vector<uint8_t> vox(v.voxel_count());
    const float lim2 = limit * limit;
    parallel_for(size_t(d.z), threads, [&](size_t z0, size_t z1) {
        for (int k = int(z0); k < int(z1); ++k)
            for (int j = 0; j < d.y; ++j)
                for (int i = 0; i < d.x; ++i) {
                    const size_t c = size_t(k) * sz + size_t(j) * sy + size_t(i);
                    auto diff = [&](int p, int n, size_t stride) {
                        const size_t hi = p + 1 < n ? c + stride : c;
                        const size_t lo = p > 0 ? c - stride : c;
                        const float span = float((p + 1 < n) + (p > 0));
                        return (float(data[hi]) - float(data[lo])) / span;
                    };
                    const float gx = diff(i, d.x, 1), gy = diff(j, d.y, sy), gz = diff(k, d.z, sz);
                    vox[c] = gx * gx + gy * gy + gz * gz > lim2 ? 1 : 0;
                }
    });
    const int cx = d.x - 1, cy = d.y - 1, cz = d.z - 1;
    cell_flags.assign(size_t(cx) * size_t(cy) * size_t(cz), 0);
    std::vector<uint64_t> counts(size_t(cz), 0);
    parallel_for(size_t(cz), threads, [&](size_t z0, size_t z1) {
        for (int k = int(z0); k < int(z1); ++k) {
            uint64_t n = 0;
            for (int j = 0; j < cy; ++j) {
                const uint8_t* a = &vox[size_t(k) * sz + size_t(j) * sy];
                const uint8_t* b = a + sy;
                const uint8_t* e = a + sz;
                const uint8_t* f = e + sy;
                uint8_t* o = &cell_flags[(size_t(k) * size_t(cy) + size_t(j)) * size_t(cx)];
                for (int i = 0; i < cx; ++i) {
                    o[i] = (a[i] | a[i + 1] | b[i] | b[i + 1] | e[i] | e[i + 1] | f[i] | f[i + 1]);
                    n += o[i];
                }
            }
            counts[size_t(k)] = n;
        }
    });
    total = 0;
    for (uint64_t n : counts) total += n;
}

// ---- growth ------------------------------------------------------------------------------------

// Growth runs on a grid of blocks of min_uniform cells per axis (the last block of an axis takes
// the remainder, so every block is at least min(min_uniform, cells) thick): the minimum box size
// of the paper, and no one-cell slivers between boxes. Per block: the min and max of its voxels
// (lo..hi, so the range of a union of blocks is the union of their ranges, exactly), its cells
// and its gradient cells.
class Grower {
  public:
    explicit Grower(const BoxMeasure& m) : m_m(m), m_o(m.options()) {
        for (int a = 0; a < 3; ++a) {
            m_c[a] = m.cells()[a];
            m_e = std::max(1, m_o.min_uniform);
            m_n[a] = std::max(1, m_c[a] / m_e);
        }
        const size_t nb = size_t(m_n[0]) * size_t(m_n[1]) * size_t(m_n[2]);
        m_min.resize(nb), m_max.resize(nb), m_grad.resize(nb), m_cells.resize(nb);
        m_covered.assign(nb, 0);
        visit_voxels(m.volume(), [&](const auto* data) { block_facts(data); });
    }

    std::vector<BoxInfo> run() {
        // Phase 1: gradient boxes from blocks that are gradient boxes on their own.
        for_each_block([&](int p[3]) {
            const size_t b = block(p[0], p[1], p[2]);
            if (gradient_rule(double(m_cells[b]), double(m_grad[b]))) grow(p, BoxType::Gradient);
        });
        // Phase 2: uniform boxes from uniform blocks.
        for_each_block([&](int p[3]) {
            const size_t b = block(p[0], p[1], p[2]);
            if (m_m.uniform(m_min[b], m_max[b])) grow(p, BoxType::Uniform);
        });
        // Phase 3: other boxes fill the rest.
        for_each_block([&](int p[3]) { grow(p, BoxType::Other); });
        return std::move(m_out);
    }

  private:
    size_t block(int i, int j, int k) const {
        return (size_t(k) * size_t(m_n[1]) + size_t(j)) * size_t(m_n[0]) + size_t(i);
    }
    int start(int, int b) const { return b * m_e; }
    int end(int a, int b) const { return b + 1 == m_n[a] ? m_c[a] : (b + 1) * m_e; }

    template <class T>
    void block_facts(const T* data) {
        const Vec3i d = m_m.volume().dims();
        const size_t sy = size_t(d.x), sz = size_t(d.x) * size_t(d.y);
        parallel_for(size_t(m_n[2]), m_o.threads, [&](size_t z0, size_t z1) {
            for (int bk = int(z0); bk < int(z1); ++bk)
                for (int bj = 0; bj < m_n[1]; ++bj)
                    for (int bi = 0; bi < m_n[0]; ++bi) {
                        const int lo[3] = {start(0, bi), start(1, bj), start(2, bk)};
                        const int hi[3] = {end(0, bi), end(1, bj), end(2, bk)};
                        T mn = data[size_t(lo[2]) * sz + size_t(lo[1]) * sy + size_t(lo[0])];
                        T mx = mn;
                        uint32_t g = 0;
                        for (int k = lo[2]; k <= hi[2]; ++k)
                            for (int j = lo[1]; j <= hi[1]; ++j) {
                                const T* row = data + size_t(k) * sz + size_t(j) * sy;
                                for (int i = lo[0]; i <= hi[0]; ++i) {
                                    mn = std::min(mn, row[i]);
                                    mx = std::max(mx, row[i]);
                                }
                                if (k < hi[2] && j < hi[1])
                                    for (int i = lo[0]; i < hi[0]; ++i)
                                        g += m_m.gradient_cell(i, j, k);
                            }
                        const size_t b = block(bi, bj, bk);
                        m_min[b] = float(mn);
                        m_max[b] = float(mx);
                        m_grad[b] = g;
                        m_cells[b] = uint32_t(hi[0] - lo[0]) * uint32_t(hi[1] - lo[1]) *
                                     uint32_t(hi[2] - lo[2]);
                    }
        });
    }

    bool gradient_rule(double cells, double grads) const {
        return grads > 0 && cells - grads <= double(m_o.gradient_waste) * cells;
    }

    // fn(p) for every uncovered block, x fastest.
    template <class F>
    void for_each_block(F&& fn) {
        int p[3];
        for (p[2] = 0; p[2] < m_n[2]; ++p[2])
            for (p[1] = 0; p[1] < m_n[1]; ++p[1])
                for (p[0] = 0; p[0] < m_n[0]; ++p[0])
                    if (!m_covered[block(p[0], p[1], p[2])]) fn(p);
    }

    struct Facts {
        float mn, mx;
        uint64_t grads, cells, grad_blocks;
    };

    // Facts of the layer of blocks at `pos` on axis a across box b (block coordinates); false if
    // a block of it is covered.
    bool layer(const int lo[3], const int hi[3], int a, int pos, Facts& f) const {
        int u, w;
        other_axes(a, u, w);
        int p[3];
        p[a] = pos;
        for (p[w] = lo[w]; p[w] < hi[w]; ++p[w])
            for (p[u] = lo[u]; p[u] < hi[u]; ++p[u]) {
                const size_t b = block(p[0], p[1], p[2]);
                if (m_covered[b]) return false;
                f.mn = std::min(f.mn, m_min[b]);
                f.mx = std::max(f.mx, m_max[b]);
                f.grads += m_grad[b];
                f.cells += m_cells[b];
                f.grad_blocks += gradient_rule(double(m_cells[b]), double(m_grad[b]));
            }
        return true;
    }

    bool accept(BoxType type, const Facts& box, const Facts& with_layer) const {
        const double vol = double(with_layer.cells);
        switch (type) {
            case BoxType::Gradient:
                // A gradient box only grows over layers with gradient blocks.
                return with_layer.grad_blocks > box.grad_blocks &&
                       gradient_rule(vol, double(with_layer.grads));
            case BoxType::Uniform:
                return m_m.uniform(with_layer.mn, with_layer.mx);
            default:
                return vol * (double(with_layer.mx) - double(with_layer.mn)) /
                           double(m_m.full_scale()) <=
                       double(m_o.other_cost);
        }
    }

    // Grows a box from the seed block, one block layer at a time: always an open face on the axis
    // where the box is shortest (ties: +x, -x, +y, -y, +z, -z), so boxes stay as cubic as the
    // data lets them; a face closes for good when its layer breaks the type's rule (header).
    void grow(const int seed[3], BoxType type) {
        int lo[3] = {seed[0], seed[1], seed[2]}, hi[3] = {seed[0] + 1, seed[1] + 1, seed[2] + 1};
        Facts f{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), 0,
                0, 0};
        layer(lo, hi, 0, seed[0], f);
        bool open[6] = {true, true, true, true, true, true};
        for (;;) {
            int face = -1, best = 0;
            for (int c = 0; c < 6; ++c) {
                const int extent = hi[c / 2] - lo[c / 2];
                if (open[c] && (face < 0 || extent < best)) face = c, best = extent;
            }
            if (face < 0) break;
            const int a = face / 2;
            const bool up = face % 2 == 0;
            const int pos = up ? hi[a] : lo[a] - 1;
            Facts g = f;
            if (pos < 0 || pos >= m_n[a] || !layer(lo, hi, a, pos, g) || !accept(type, f, g)) {
                open[face] = false;
                continue;
            }
            (up ? hi[a] : lo[a]) += up ? 1 : -1;
            f = g;
        }
        for (int k = lo[2]; k < hi[2]; ++k)
            for (int j = lo[1]; j < hi[1]; ++j)
                for (int i = lo[0]; i < hi[0]; ++i) m_covered[block(i, j, k)] = 1;
        CellBox box;
        for (int a = 0; a < 3; ++a) {
            box.lo[a] = start(a, lo[a]);
            box.hi[a] = end(a, hi[a] - 1);
        }
        m_out.push_back(BoxInfo{box, f.mn, f.mx, f.grads, type});
    }

    const BoxMeasure& m_m;
    const BoxesOptions& m_o;
    int m_c[3] = {0, 0, 0}, m_n[3] = {1, 1, 1}, m_e = 1;
    std::vector<float> m_min, m_max;
    std::vector<uint32_t> m_grad, m_cells;
    std::vector<uint8_t> m_covered;
    std::vector<BoxInfo> m_out;
};

}  // namespace

std::string to_string(BoxType t) {
    switch (t) {
        case BoxType::Uniform:
            return "uniform";
        case BoxType::Gradient:
            return "gradient";
        default:
            return "other";
    }
}

std::string to_string(const CellBox& b) {
    char buf[120];
    std::snprintf(buf, sizeof buf, "[%d,%d,%d)-[%d,%d,%d)", b.lo[0], b.lo[1], b.lo[2], b.hi[0],
                  b.hi[1], b.hi[2]);
    return buf;
}

void validate(const BoxesOptions& o) {
    // Fields as FrameSpec's growing boxes and `lacuna partition` hold them ("structure.spread");
    // the CLI names its flags (apps/lacuna/frame_flags.cpp).
    auto bad = [](const char* field, const char* what, double got) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%g", got);
        return FrameError(field, std::string("expected ") + what + ", got " + buf);
    };
    if (!(o.spread >= 0.f && o.spread <= 256.f))
        throw bad("structure.spread", "0..256 (256ths)", o.spread);
    if (o.min_uniform < 1 || o.min_uniform > 4096)
        throw bad("structure.min_uniform", "1..4096 cells", o.min_uniform);
    if (!(o.gradient >= 0.f && o.gradient <= 1.f))
        throw bad("structure.gradient", "0..1 (of the full scale per voxel)", o.gradient);
    if (!(o.gradient_waste >= 0.f && o.gradient_waste <= 1.f))
        throw bad("structure.gradient_waste", "0..1", o.gradient_waste);
    if (!(o.other_cost >= 0.f && std::isfinite(o.other_cost)))
        throw bad("structure.other_cost", "a finite value >= 0 (cells)", o.other_cost);
    if (o.thin < 0 || o.thin > 4096) throw bad("structure.thin", "0..4096 cells", o.thin);
    if (o.threads < 0) throw bad("threads", ">= 0", o.threads);
    if (!(o.coalesce <= 1.f))
        throw bad("structure.coalesce", "a share <= 1 (negative: off)", o.coalesce);
    if (!(o.coalesce_edge > 0.f))
        throw bad("structure.coalesce_edge", "a length > 0 (mm)", o.coalesce_edge);
}

std::string to_string(const BoxesOptions& o) {
    char buf[240];
    std::snprintf(buf, sizeof buf,
                  "spread %g/256, min box %d, gradient %g, gradient waste %g, other cost %g, "
                  "thin %d, merge %s, coalesce %g up to %g mm",
                  double(o.spread), o.min_uniform, double(o.gradient), double(o.gradient_waste),
                  double(o.other_cost), o.thin, o.merge ? "on" : "off", double(o.coalesce),
                  double(o.coalesce_edge));
    return buf;
}

BoxMeasure::BoxMeasure(const Volume& v, const BoxesOptions& o) : m_volume(v), m_opts(o) {
    validate(o);
    const auto t0 = std::chrono::steady_clock::now();
    cell_counts(v, m_cells);
    // Full scale: 256 values for uint8 (the paper's 8-bit data), the visualization range
    // otherwise; the spread limit is `spread` 256ths of it.
    m_full = v.type() == VoxelType::UInt8 ? 256.f : v.vis_range().width();
    if (!(m_full > 0.f)) m_full = 1.f;
    m_limit = o.spread / 256.f * m_full;
    const float glimit = o.gradient * m_full;
    visit_voxels(v, [&](const auto* data) {
        gradient_cells(v, data, glimit, o.threads, m_grad, m_gradient_total);
    });
    m_seconds = since(t0);
}

BoxType BoxMeasure::type_of(const BoxInfo& i) const {
    const double vol = double(box_volume(i.box));
    if (i.gradient_cells > 0 &&
        vol - double(i.gradient_cells) <= double(m_opts.gradient_waste) * vol)
        return BoxType::Gradient;
    if (uniform(i.vmin, i.vmax)) return BoxType::Uniform;
    return BoxType::Other;
}

BoxInfo BoxMeasure::measure(const CellBox& b) const {
    BoxInfo r{b, std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), 0,
              BoxType::Other};
    const Vec3i d = m_volume.dims();
    const size_t sy = size_t(d.x), sz = size_t(d.x) * size_t(d.y);
    visit_voxels(m_volume, [&](const auto* data) {
        for (int k = b.lo[2]; k <= b.hi[2]; ++k)
            for (int j = b.lo[1]; j <= b.hi[1]; ++j) {
                const auto* row = data + size_t(k) * sz + size_t(j) * sy;
                for (int i = b.lo[0]; i <= b.hi[0]; ++i) {
                    r.vmin = std::min(r.vmin, float(row[i]));
                    r.vmax = std::max(r.vmax, float(row[i]));
                }
            }
    });
    for (int k = b.lo[2]; k < b.hi[2]; ++k)
        for (int j = b.lo[1]; j < b.hi[1]; ++j)
            for (int i = b.lo[0]; i < b.hi[0]; ++i) r.gradient_cells += gradient_cell(i, j, k);
    r.type = type_of(r);
    return r;
}

BoxInfo BoxMeasure::merge(const BoxInfo& a, const BoxInfo& b, const CellBox& merged) const {
    // Two face-adjacent boxes: the merged box's voxels lo..hi are the union of theirs, its cells
    // the disjoint union of theirs.
    BoxInfo r{merged, std::min(a.vmin, b.vmin), std::max(a.vmax, b.vmax),
              a.gradient_cells + b.gradient_cells, BoxType::Other};
    r.type = type_of(r);
    return r;
}

std::vector<BoxInfo> grow_boxes(const BoxMeasure& m) {
    return Grower(m).run();
}

// ---- classification ----------------------------------------------------------------------------

void BoxClassifier::build(const Volume& v, ValueRange vis, int lut_size,
                          const std::vector<CellBox>& boxes, int threads) {
    const auto t0 = std::chrono::steady_clock::now();
    m_vis = vis;
    m_size = lut_size;
    m_map = ValueToLut(vis, lut_size);
    int c[3];
    cell_counts(v, c);
    // 1. Every cell's LUT-entry range (the shared, widened cell ranges).
    const size_t n = size_t(c[0]) * size_t(c[1]) * size_t(c[2]);
    std::vector<uint16_t> clo(n), chi(n);
    for_each_cell_row(v, m_map, 8, threads, [&](const CellRow& r) {
        const size_t at = (size_t(r.k) * size_t(c[1]) + size_t(r.j)) * size_t(c[0]);
        std::copy_n(r.lo, r.n, &clo[at]);
        std::copy_n(r.hi, r.n, &chi[at]);
    });
    // 2. Per box, the union of the ranges of its cells: a difference array over the LUT
    // entries, swept into maximal runs.
    std::vector<std::vector<uint16_t>> runs(boxes.size());
    parallel_for(
        boxes.size(), threads,
        [&](size_t b0, size_t b1) {
            std::vector<int32_t> diff(size_t(lut_size) + 1);
            for (size_t bi = b0; bi < b1; ++bi) {
                const CellBox& b = boxes[bi];
                int lo[3], hi[3];
                for (int a = 0; a < 3; ++a) {
                    lo[a] = b.lo[a];
                    hi[a] = b.hi[a];
                }
                int first = lut_size, last = -1;
                for (int k = lo[2]; k < hi[2]; ++k)
                    for (int j = lo[1]; j < hi[1]; ++j) {
                        const size_t row = (size_t(k) * size_t(c[1]) + size_t(j)) * size_t(c[0]);
                        for (int i = lo[0]; i < hi[0]; ++i) {
                            const int l = clo[row + size_t(i)], h = chi[row + size_t(i)];
                            ++diff[size_t(l)];
                            --diff[size_t(h) + 1];
                            first = std::min(first, l);
                            last = std::max(last, h);
                        }
                    }
                std::vector<uint16_t>& out = runs[bi];
                int count = 0;
                for (int e = first; e <= last + 1 && e <= lut_size; ++e) {
                    const int before = count;
                    count += diff[size_t(e)];
                    diff[size_t(e)] = 0;
                    if (before == 0 && count > 0) out.push_back(uint16_t(e));
                    if (before > 0 && count == 0) out.push_back(uint16_t(e - 1));
                }
            }
        },
        16);
    m_offsets.assign(boxes.size() + 1, 0);
    for (size_t b = 0; b < boxes.size(); ++b)
        m_offsets[b + 1] = m_offsets[b] + uint32_t(runs[b].size() / 2);
    m_lo.resize(m_offsets.back());
    m_hi.resize(m_offsets.back());
    for (size_t b = 0; b < boxes.size(); ++b)
        for (size_t r = 0; r < runs[b].size() / 2; ++r) {
            m_lo[m_offsets[b] + r] = runs[b][2 * r];
            m_hi[m_offsets[b] + r] = runs[b][2 * r + 1];
        }
    m_seconds = since(t0);
}

bool BoxClassifier::same_map(const TransferLut& lut) const {
    return lut.size() == m_size && lut.vis.min == m_vis.min && lut.vis.max == m_vis.max;
}

void BoxClassifier::classify(const TransferLut& lut, std::vector<uint8_t>& empty) const {
    OpacityPrefix prefix;
    prefix.build(lut);
    const size_t n = boxes();
    empty.assign(n, 1);
    for (size_t b = 0; b < n; ++b)
        for (uint32_t r = m_offsets[b]; r < m_offsets[b + 1]; ++r)
            if (prefix.visible(m_lo[r], m_hi[r])) {
                empty[b] = 0;
                break;
            }
}

std::vector<std::pair<int, int>> BoxClassifier::intervals_of(size_t b) const {
    std::vector<std::pair<int, int>> r;
    for (uint32_t i = m_offsets[b]; i < m_offsets[b + 1]; ++i) r.emplace_back(m_lo[i], m_hi[i]);
    return r;
}

}  // namespace lacuna
