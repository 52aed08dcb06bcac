// Segment rendering (include/lacuna/segments.h): the ray marcher's lattice and compositing with
// a label lookup per sample, skipped through the label bitfield octree (src/accel/label_octree.h).
//
// Exactness: the reference is the same loop with the NoAccel cursor. A sample whose label can
// not be seen contributes exactly nothing (its table entry is all zeros), so cutting out stretches
// where the octree proves every cell's labels invisible (or, in masked mode, the intensity TF
// transparent) changes no byte. In masked mode with every label visible at opacity 1 and tint 0
// each composited value is the ray marcher's to the bit (x * 1 and x + 0 are exact), which the
// tests check against RayMarcher.
#include <atomic>
#include <chrono>
#include <cmath>

#include "accel/accel_impl.h"
#include "accel/label_octree.h"
#include "accel/no_accel.h"
#include "core/parallel.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "lacuna/segments.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"

namespace lacuna {

struct SegmentRenderer::Impl {
    const Volume* intensity = nullptr;
    const Volume& labels;
    SegmentOptions opts;
    std::unique_ptr<LabelOctree> octree;
    const Accel* accel = nullptr;  // mask mode without the octree: an intensity structure
    TransferLut lut;
    // Per label: labels mode premultiplied colour and opacity per unit distance (step-corrected
    // at render time); masked mode colour and opacity factor (0 when hidden).
    std::vector<Rgba> table;
    Impl(const Volume* i, const Volume& l, const SegmentOptions& o)
        : intensity(i), labels(l), opts(o) {}
};

namespace {

template <class L>
struct LabelGrid {
    const L* data;
    ptrdiff_t sy, sz;
    int last_x, last_y, last_z;  // dims - 1
    // Nearest voxel of the index-space point (already clamped into [0, dims-1]): a corner of
    // the point's trilinear cell.
    L at(float x, float y, float z) const {
        const int i = std::min(int(x + 0.5f), last_x), j = std::min(int(y + 0.5f), last_y),
                  k = std::min(int(z + 0.5f), last_z);
        return data[ptrdiff_t(k) * sz + ptrdiff_t(j) * sy + i];
    }
};

struct Frame {
    const Camera& cam;
    const RenderOptions& opt;
    const Rgba* lut;  // step-corrected intensity LUT (masked mode)
    ValueToLut map;
    const Rgba* table;  // per label (see Impl::table), step-corrected in labels mode
    int table_size;
    float tint;
    bool masked;
    bool nearest;  // intensity samples by Interpolation::Nearest
    RenderResult& out;
    std::atomic<uint64_t>& samples;
    std::atomic<uint64_t>& rays;
};

template <class T, class L, class S>
void render_tile(const S& accel, const Volume& geom, const T* data, const L* labels, const Frame& f,
                 int x0, int y0, int x1, int y1) {
    const Vec3i d = geom.dims();
    const kernel::Grid<T, int64_t> g = kernel::make_grid<int64_t>(data, d);
    const LabelGrid<L> lg{labels,  ptrdiff_t(d.x), ptrdiff_t(d.x) * ptrdiff_t(d.y),
                          d.x - 1, d.y - 1,        d.z - 1};
    const Vec3f inv_sp = inverse_spacing(geom);
    const float dt = sample_distance(geom, f.opt.step);
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    const float ert = f.opt.ert;
    uint64_t tile_samples = 0, tile_rays = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            const kernel::IndexRay r = index_ray(f.cam.generate(float(x), float(y)), inv_sp);
            kernel::Accum acc;
            uint32_t n = 0;
            float t_near, t_far;
            if (kernel::intersect_box(r, hi, t_near, t_far)) {
                ++tile_rays;
                typename S::Cursor cursor(accel, r, t_near, t_far, dt,
                                          ert < 1.f ? kCursorChunk * dt : 0.f);
                for_each_sample(cursor, t_near, dt, lattice_end(t_near, t_far, dt), [&](int s) {
                    // The ray marcher's lattice and clamping (ray_march_kernel.h).
                    const float t = t_near + (float(s) + 0.5f) * dt;
                    float px = r.ox + t * r.dx, py = r.oy + t * r.dy, pz = r.oz + t * r.dz;
                    px = px < 0.f ? 0.f : (px > g.hi_x ? g.hi_x : px);
                    py = py < 0.f ? 0.f : (py > g.hi_y ? g.hi_y : py);
                    pz = pz < 0.f ? 0.f : (pz > g.hi_z ? g.hi_z : pz);
                    ++n;
                    const int l = int(lg.at(px, py, pz));
                    if (l >= f.table_size) return true;  // no style: unseen
                    const Rgba& ls = f.table[l];
                    if (ls.a == 0.f) return true;
                    Rgba c;
                    if (f.masked) {
                        const Rgba& tc = f.lut[f.map(f.nearest ? kernel::nearest(g, px, py, pz)
                                                               : kernel::trilinear(g, px, py, pz))];
                        // Premultiplied: the TF colour mixed with the label's, then the
                        // label's opacity factor.
                        const float keep = 1.f - f.tint;
                        c.r = (keep * tc.r + f.tint * ls.r * tc.a) * ls.a;
                        c.g = (keep * tc.g + f.tint * ls.g * tc.a) * ls.a;
                        c.b = (keep * tc.b + f.tint * ls.b * tc.a) * ls.a;
                        c.a = tc.a * ls.a;
                    } else {
                        c = ls;
                    }
                    const float w = 1.f - acc.a;
                    acc.r += w * c.r;
                    acc.g += w * c.g;
                    acc.b += w * c.b;
                    acc.a += w * c.a;
                    return acc.a < ert;  // early ray termination
                });
            }
            tile_samples += n;
            write_pixel(f.out, f.opt, x, y, acc, n);
        }
    }
    f.samples += tile_samples;
    f.rays += tile_rays;
}

}  // namespace

SegmentRenderer::SegmentRenderer(const Volume* intensity, const Volume& labels,
                                 const SegmentOptions& options)
    : m_impl(std::make_unique<Impl>(intensity, labels, options)) {
    if (options.mode == SegmentMode::Masked && !intensity)
        throw FrameError("segments.mode", "mask mode needs an intensity volume and a label volume");
    if (!(options.tint >= 0.f && options.tint <= 1.f))
        throw FrameError("segments.tint", "expected a number in [0,1]");
    check_label_volume(labels, intensity, "labels");
    if (options.skip) {
        const auto t0 = std::chrono::steady_clock::now();
        m_impl->octree = std::make_unique<LabelOctree>(
            labels, options.mode == SegmentMode::Masked ? intensity : nullptr, options);
        m_stats.build_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        m_stats.bytes = m_impl->octree->bytes();
        m_stats.label_words = m_impl->octree->words();
    }
}

SegmentRenderer::~SegmentRenderer() = default;

void SegmentRenderer::set_transfer_function(const TransferLut& lut) {
    m_impl->lut = lut;
    if (m_impl->octree) m_impl->octree->set_transfer_function(lut);
}

void SegmentRenderer::set_labels(const LabelTable& t) {
    const auto t0 = std::chrono::steady_clock::now();
    auto& table = m_impl->table;
    table.assign(size_t(t.size()), Rgba{});
    std::vector<uint64_t> bits(size_t(t.size() + 63) / 64, 0);
    for (int l = 0; l < t.size(); ++l) {
        const LabelStyle& s = t.styles[size_t(l)];
        if (!s.visible || !(s.opacity > 0.f)) continue;  // stays all zero: contributes nothing
        table[size_t(l)] = {s.r, s.g, s.b, std::min(s.opacity, 1.f)};
        bits[size_t(l) >> 6] |= uint64_t(1) << (l & 63);
    }
    if (m_impl->octree) m_impl->octree->set_visible(bits);
    m_stats.label_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void SegmentRenderer::set_accel(const Accel* accel) {
    if (accel && (m_impl->octree || m_impl->opts.mode != SegmentMode::Masked))
        throw FrameError("structure",
                         "an intensity structure applies to mask mode without the label octree");
    m_impl->accel = accel;
}

Box3f SegmentRenderer::bounds() const {
    return world_bounds(m_impl->labels);
}

RenderResult SegmentRenderer::render(const Camera& world_cam, const RenderOptions& opt) const {
    const Impl& im = *m_impl;
    // World (RAS) -> the label map's volume frame (lacuna/orientation.h).
    const Camera cam = to_volume_frame(volume_frame(im.labels), world_cam);
    const bool masked = im.opts.mode == SegmentMode::Masked;
    if (masked && im.lut.entries.empty())
        throw Error("render", "transfer function", "none was set (mask mode)");
    if (!(opt.step > 0.f) || !std::isfinite(opt.step))
        throw FrameError("sampling.step", "expected a positive number");
    if (im.accel && im.accel->interpolation() == Interpolation::Nearest &&
        opt.interpolation != Interpolation::Nearest)
        throw FrameError("sampling.interpolation",
                         "the structure was built for nearest sampling; expected nearest");
    RenderResult out;
    out.image = Image(cam.width(), cam.height());
    if (opt.count_samples) out.sample_counts.assign(size_t(cam.width()) * cam.height(), 0);
    if (opt.keep_float) out.rgba_float.assign(size_t(cam.width()) * cam.height() * 4, 0.f);
    const std::vector<Rgba> lut =
        masked ? step_corrected_lut(im.lut, opt.step) : std::vector<Rgba>{};
    // Labels mode: label opacity is per unit distance, corrected for the step like a TF entry.
    std::vector<Rgba> table = im.table;
    if (!masked) {
        TransferLut as_lut;
        as_lut.entries = im.table;
        table = step_corrected_lut(as_lut, opt.step);
    }
    std::atomic<uint64_t> samples{0}, rays{0};
    const Frame f{cam,
                  opt,
                  lut.data(),
                  masked ? im.lut.map() : ValueToLut{},
                  table.data(),
                  int(table.size()),
                  im.opts.tint,
                  masked,
                  opt.interpolation == Interpolation::Nearest,
                  out,
                  samples,
                  rays};
    // Labels mode samples no intensity: the label volume stands in as the (unused) grid.
    const Volume& geom = masked ? *im.intensity : im.labels;
    const auto t0 = std::chrono::steady_clock::now();
    visit_voxels(geom, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        visit_voxels(im.labels, [&](const auto* labels) {
            using L = std::remove_cv_t<std::remove_pointer_t<decltype(labels)>>;
            if constexpr (!std::is_same_v<L, float>) {
                auto run = [&](const auto& s) {
                    parallel_for_tiles(cam.width(), cam.height(), opt.tile, opt.threads,
                                       [&](int x0, int y0, int x1, int y1) {
                                           render_tile<T, L>(s, geom, data, labels, f, x0, y0, x1,
                                                             y1);
                                       });
                };
                if (im.octree)
                    run(*im.octree);
                else if (im.accel)
                    visit_accel(*im.accel, run);
                else
                    run(NoAccel{});
            }
        });
    });
    out.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out.stats.samples = samples;
    out.stats.rays = rays;
    out.stats.pixels = uint64_t(cam.width()) * cam.height();
    return out;
}

}  // namespace lacuna
