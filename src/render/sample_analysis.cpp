#include "render/sample_analysis.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "accel/cell_ranges.h"
#include "core/parallel.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"

namespace lacuna {

VisibleCells::VisibleCells(const Volume& v, const TransferLut& lut, int threads) {
    cell_counts(v, m_cells);
    m_row_words = (size_t(m_cells[0]) + 63) / 64;
    m_bits.assign(m_row_words * size_t(m_cells[1]) * size_t(m_cells[2]), 0);
    OpacityPrefix prefix;
    prefix.build(lut);
    std::atomic<size_t> visible{0};
    // for_each_block_cells hands a whole x-row of blocks to one task, so a row's words are only
    // ever written by one thread.
    for_each_block_cells(v, lut.map(), 16, threads, [&](const BlockCells& b) {
        size_t n = 0;
        const uint16_t* lo = b.lo;
        const uint16_t* hi = b.hi;
        for (int k = 0; k < b.n[2]; ++k)
            for (int j = 0; j < b.n[1]; ++j) {
                uint64_t* r = &m_bits[row(b.c0[1] + j, b.c0[2] + k)];
                for (int i = 0; i < b.n[0]; ++i, ++lo, ++hi) {
                    if (!prefix.visible(*lo, *hi)) continue;
                    const int c = b.c0[0] + i;
                    r[c >> 6] |= uint64_t(1) << (c & 63);
                    ++n;
                }
            }
        visible += n;
    });
    m_visible = visible;
}

namespace {

// The reference's ray through pixel (x, y), set up as ray_marcher.cpp does: in index space
// (inv_sp = 1 / spacing per axis) and clipped to the grid box [0, hi]. False on a miss; else the
// lattice t_k = t_near + (k + 0.5) * dt holds k_end samples of the ray.
struct PixelRay {
    kernel::IndexRay r;
    float t_near, t_far;
    int k_end;
};
bool pixel_ray(const Camera& cam, const Vec3f& inv_sp, const float hi[3], float dt, int x, int y,
               PixelRay& p) {
    p.r = index_ray(cam.generate(float(x), float(y)), inv_sp);
    if (!kernel::intersect_box(p.r, hi, p.t_near, p.t_far)) return false;
    p.k_end = lattice_end(p.t_near, p.t_far, dt);
    return true;
}

// Visible-cell samples of the pixels [x0,x1) x [y0,y1).
template <class T>
uint64_t count_tile(const kernel::Grid<T, int64_t>& g, const VisibleCells& cells, const Volume& vol,
                    const Camera& cam, const std::vector<Rgba>& lut, ValueToLut map, float dt,
                    float ert, bool nearest, int x0, int y0, int x1, int y1) {
    const Vec3f inv_sp = inverse_spacing(vol);
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    const bool use_ert = ert < 1.f;
    uint64_t n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            // 1. The reference's ray, in index space, clipped to the box.
            PixelRay p;
            if (!pixel_ray(cam, inv_sp, hi, dt, x, y, p)) continue;
            const kernel::IndexRay& r = p.r;
            const float t_near = p.t_near;
            const int k_end = p.k_end;
            kernel::Accum acc;
            for (int s = 0; s < k_end; ++s) {
                // 2. The lattice position and its cell, computed as kernel::march does.
                const float t = t_near + (float(s) + 0.5f) * dt;
                float px = r.ox + t * r.dx, py = r.oy + t * r.dy, pz = r.oz + t * r.dz;
                px = px < 0.f ? 0.f : (px > g.hi_x ? g.hi_x : px);
                py = py < 0.f ? 0.f : (py > g.hi_y ? g.hi_y : py);
                pz = pz < 0.f ? 0.f : (pz > g.hi_z ? g.hi_z : pz);
                const int i = std::min(int(px), g.cell_x), j = std::min(int(py), g.cell_y),
                          k = std::min(int(pz), g.cell_z);
                // Nearest: the sample's own voxel decides (its opacity is the sample's).
                if (nearest) {
                    const float a = lut[size_t(map(kernel::nearest(g, px, py, pz)))].a;
                    if (!(a > 0.f)) continue;
                    ++n;
                    if (!use_ert) continue;
                    acc.a += (1.f - acc.a) * a;
                    if (acc.a >= ert) break;
                    continue;
                }
                // 3. Invisible cell: opacity 0, compositing is the identity, nothing to count.
                if (!cells.visible(i, j, k)) continue;
                ++n;
                if (!use_ert) continue;
                // 4. Visible: composite the opacity exactly as the reference does, so the ray
                // stops after the same sample.
                const float a = lut[size_t(map(kernel::trilinear(g, px, py, pz)))].a;
                const float w = 1.f - acc.a;
                acc.a += w * a;
                if (acc.a >= ert) break;
            }
        }
    return n;
}

}  // namespace

uint64_t count_visible_cell_samples(const Volume& vol, const TransferLut& lut,
                                    const VisibleCells& cells, const Camera& world_cam,
                                    const RenderOptions& opt) {
    const Camera cam = to_volume_frame(volume_frame(vol), world_cam);  // as RayMarcher::render
    if (lut.entries.empty()) throw Error("sample analysis", "transfer function", "none was set");
    const Vec3i d = vol.dims();
    if (cells.cells()[0] != d.x - 1 || cells.cells()[1] != d.y - 1 || cells.cells()[2] != d.z - 1)
        throw Error("sample analysis", "visible cells", "built for another volume");
    const std::vector<Rgba> table = step_corrected_lut(lut, opt.step);
    const ValueToLut map = lut.map();
    const float dt = sample_distance(vol, opt.step);
    std::atomic<uint64_t> total{0};
    visit_voxels(vol, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        const kernel::Grid<T, int64_t> g = kernel::make_grid<int64_t>(data, d);
        parallel_for_tiles(
            cam.width(), cam.height(), opt.tile, opt.threads, [&](int x0, int y0, int x1, int y1) {
                total += count_tile(g, cells, vol, cam, table, map, dt, opt.ert,
                                    opt.interpolation == Interpolation::Nearest, x0, y0, x1, y1);
            });
    });
    return total;
}

uint64_t count_visible_cell_samples(const Volume& vol, const TransferLut& lut, const Camera& cam,
                                    const RenderOptions& opt) {
    const VisibleCells cells(vol, lut, opt.threads);
    return count_visible_cell_samples(vol, lut, cells, cam, opt);
}

uint64_t count_lattice_samples(const Volume& vol, const Camera& world_cam, float step,
                               int threads) {
    const Camera cam = to_volume_frame(volume_frame(vol), world_cam);  // as RayMarcher::render
    const Vec3i d = vol.dims();
    const Vec3f inv_sp = inverse_spacing(vol);
    const float dt = sample_distance(vol, step);
    const float hi[3] = {float(d.x - 1), float(d.y - 1), float(d.z - 1)};
    std::atomic<uint64_t> total{0};
    parallel_for_tiles(cam.width(), cam.height(), 32, threads, [&](int x0, int y0, int x1, int y1) {
        uint64_t n = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                PixelRay p;
                if (pixel_ray(cam, inv_sp, hi, dt, x, y, p)) n += uint64_t(p.k_end);
            }
        total += n;
    });
    return total.load();
}

}  // namespace lacuna
