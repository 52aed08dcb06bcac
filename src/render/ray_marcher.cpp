#include "lacuna/renderer.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>

#include "accel/accel_impl.h"
#include "accel/brick_grid.h"
#include "accel/no_accel.h"
#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "lacuna/error.h"
#include "render/marcher_cache.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"
#include "render/volume_frame.h"

namespace lacuna {

std::string to_string(const RenderStats& s) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%.1f ms, %llu samples, %.1f samples/ray, %.1f Msamples/s", s.seconds * 1e3,
                  (unsigned long long)s.samples, s.samples_per_ray(), s.msamples_per_second());
    return buf;
}

std::vector<Rgba> step_corrected_lut(const TransferLut& lut, float step) {
    std::vector<Rgba> out(lut.entries.size());
    for (size_t e = 0; e < out.size(); ++e) {
        const Rgba& c = lut.entries[e];
        // Zero stays exactly zero (skipping relies on it); pow keeps 1 at 1.
        const float a = c.a <= 0.f ? 0.f : 1.f - std::pow(1.f - std::min(c.a, 1.f), step);
        out[e] = {c.r * a, c.g * a, c.b * a, a};
    }
    return out;
}

RayMarcher::RayMarcher(const Volume& volume) : m_volume(volume), m_cache(std::make_unique<Cache>()) {}
RayMarcher::~RayMarcher() = default;

void RayMarcher::set_transfer_function(const TransferLut& lut) {
    m_lut = lut;
    ++m_tf_version;
}

void RayMarcher::set_back_transfer_function(const TransferLut& lut) {
    m_back_lut = lut;
    ++m_tf_version;
}

std::string to_string(ShadingModel m) {
    switch (m) {
        case ShadingModel::None: return "none";
        case ShadingModel::Phong: return "phong";
        case ShadingModel::Pbr: return "pbr";
    }
    return "?";
}

std::string to_string(LightKind k) {
    switch (k) {
        case LightKind::Head: return "head";
        case LightKind::Directional: return "directional";
        case LightKind::Spot: return "spot";
    }
    return "?";
}

std::string to_string(BlendMode m) {
    switch (m) {
        case BlendMode::Composite: return "composite";
        case BlendMode::Mip: return "mip";
        case BlendMode::MinIp: return "minip";
        case BlendMode::Average: return "average";
    }
    return "?";
}

TransferLut union_lut(const TransferLut& a, const TransferLut& b) {
    if (a.size() != b.size() || a.vis.min != b.vis.min || a.vis.max != b.vis.max)
        throw Error("--tf-back", "transfer function",
                    "expected the same LUT size and visualization range as --tf");
    TransferLut u = a;
    for (size_t e = 0; e < u.entries.size(); ++e)
        u.entries[e].a = std::max(a.entries[e].a, b.entries[e].a);
    return u;
}

Box3f RayMarcher::bounds() const { return world_bounds(m_volume); }

namespace {

template <class T, class Index, bool kNearest, class S>
void render_tile(const S& accel, const Volume& vol, const T* data, const Camera& cam, const RenderOptions& opt,
                 const std::vector<Rgba>& lut, ValueToLut map, int x0, int y0, int x1, int y1,
                 RenderResult& out, std::atomic<uint64_t>& samples, std::atomic<uint64_t>& rays) {
    const kernel::Grid<T, Index> g = kernel::make_grid<Index>(data, vol.dims());
    const Vec3f inv_sp = inverse_spacing(vol);
    const float dt = sample_distance(vol, opt.step);
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    uint64_t tile_samples = 0, tile_rays = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            const kernel::IndexRay r = index_ray(cam.generate(float(x), float(y)), inv_sp);
            kernel::Accum acc;
            uint32_t n = 0;
            float t_near, t_far;
            if (kernel::intersect_box(r, hi, t_near, t_far)) {
                ++tile_rays;
                typename S::Cursor cursor(accel, cursor_ray(r), t_near, t_far, dt,
                                          opt.ert < 1.f ? kCursorChunk * dt : 0.f);
                kernel::RayStream<T, Index, kNearest> stream(g, r, t_near, dt, lut.data(), map, opt.ert,
                                                   acc);
                for_each_lattice_run(cursor, t_near, dt, lattice_end(t_near, t_far, dt),
                                     [&](int kb, int ke) { return stream.add(kb, ke); });
                stream.finish();
                n = stream.samples();
            }
            tile_samples += n;
            write_pixel(out, opt, x, y, acc, n);
        }
    }
    samples += tile_samples;
    rays += tile_rays;
}

// The same tile, W rays at a time (core/simd_lanes.h: one ray per lane, each composited in its
// own sample order, so the bits are those of render_tile). The scheduler keeps the lanes full: a
// lane whose run ends pulls the ray's next run from its cursor; a lane whose ray is done (no runs
// left, or opaque) writes its pixel and takes the tile's next ray. `march` runs the lanes and
// calls `refill` with the mask of the lanes that wait.
constexpr int kMaxTilePixels = 64 * 64;

template <int W, class T, class S, class March>
void render_tile_lanes(const S& accel, const Volume& vol, const T* data, const Camera& cam,
                       const RenderOptions& opt, const std::vector<Rgba>& lut, ValueToLut map,
                       int x0, int y0, int x1, int y1, RenderResult& out,
                       std::atomic<uint64_t>& samples, std::atomic<uint64_t>& rays, March&& march,
                       const BrickGrid* leap = nullptr) {
    using Cursor = typename S::Cursor;
    const kernel::Grid<T, int32_t> g = kernel::make_grid<int32_t>(data, vol.dims());
    const Vec3f inv_sp = inverse_spacing(vol);
    const float dt = sample_distance(vol, opt.step);
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    const float chunk = opt.ert < 1.f ? kLaneChunk * dt : 0.f;
    const simd::LaneGrid lg{dt,
                            {g.hi_x, g.hi_y, g.hi_z},
                            {g.cell_x, g.cell_y, g.cell_z},
                            int32_t(g.sy),
                            int32_t(g.sz),
                            map.offset(),
                            map.scale(),
                            float(map.last()),
                            int32_t(lut.size() - 1),  // the zero entry render() appends
                            opt.ert,
                            leap ? leap->leap_map() : nullptr,
                            leap ? leap->leap_dims()[0] : 0,
                            leap ? leap->leap_dims()[0] * leap->leap_dims()[1] : 0};
    struct Slot {
        int x = 0, y = 0;
        std::optional<Cursor> cursor;
        std::optional<LatticeRuns<Cursor>> runs;
    };
    simd::Lanes L{};
    Slot slot[W];
    // Rays enter the lanes in 4x4 pixel blocks, not rows: the lanes' sample positions then
    // stay in a compact tube of voxels, so the cache lines one block loads serve its neighbours.
    const int w = x1 - x0, h = y1 - y0, npix = w * h;
    int order[kMaxTilePixels][2];
    {
        int q = 0;
        for (int by = 0; by < h; by += 4)
            for (int bx = 0; bx < w; bx += 4)
                for (int y = by; y < std::min(by + 4, h); ++y)
                    for (int x = bx; x < std::min(bx + 4, w); ++x) {
                        order[q][0] = x0 + x;
                        order[q][1] = y0 + y;
                        ++q;
                    }
    }
    int next_pixel = 0, live = 0;
    uint64_t tile_samples = 0, tile_rays = 0;
    // Rays are set up eight at a time (AVX2, on the 8- and 16-lane paths) in pixel order.
    constexpr bool kBatchSetup = W >= 8;
    const simd::CameraView cv = camera_view(cam);
    const float isp[3] = {inv_sp.x, inv_sp.y, inv_sp.z};
    simd::RayBatch8 rb;
    int rb_base = -8;
    auto ray_of = [&](int q, kernel::IndexRay& r, float& t_near, float& t_far) {
        if constexpr (kBatchSetup) {
            if (q >= rb_base + 8) {
                rb_base = q;
                alignas(32) float px[8], py[8];
                for (int i = 0; i < 8; ++i) {
                    const int j = std::min(q + i, npix - 1);
                    px[i] = float(order[j][0]), py[i] = float(order[j][1]);
                }
                simd::setup_rays8(cv, px, py, isp, hi, rb);
            }
            const int i = q - rb_base;
            r = {rb.ox[i], rb.oy[i], rb.oz[i], rb.dx[i], rb.dy[i], rb.dz[i]};
            t_near = rb.t_near[i], t_far = rb.t_far[i];
            return rb.hit[i] != 0;
        } else {
            r = index_ray(cam.generate(float(order[q][0]), float(order[q][1])), inv_sp);
            return kernel::intersect_box(r, hi, t_near, t_far);
        }
    };
    // Puts the tile's next ray with at least one run into lane l (pixels without one are written
    // on the way); idles the lane when the tile has no rays left.
    auto start = [&](int l) {
        while (next_pixel < npix) {
            const int x = order[next_pixel][0], y = order[next_pixel][1];
            kernel::IndexRay r;
            float t_near, t_far;
            int kb, ke;
            if (ray_of(next_pixel++, r, t_near, t_far)) {
                ++tile_rays;
                Slot& sl = slot[l];
                sl.runs.reset();
                sl.cursor.emplace(accel, cursor_ray(r), t_near, t_far, dt, chunk);
                sl.runs.emplace(*sl.cursor, t_near, dt, lattice_end(t_near, t_far, dt));
                if (sl.runs->next(kb, ke)) {
                    sl.x = x, sl.y = y;
                    L.ox[l] = r.ox, L.oy[l] = r.oy, L.oz[l] = r.oz;
                    L.dx[l] = r.dx, L.dy[l] = r.dy, L.dz[l] = r.dz;
                    L.t_base[l] = t_near;
                    L.k[l] = kb, L.kend[l] = ke;
                    L.r[l] = L.g[l] = L.b[l] = L.a[l] = 0.f;
                    L.n[l] = 0;
                    L.active[l] = -1;
                    ++live;
                    return;
                }
            }
            write_pixel(out, opt, x, y, kernel::Accum{}, 0);
        }
        L.active[l] = 0;
        L.k[l] = L.kend[l] = 0;
    };
    // The lanes that need it: the ray's next run, or its pixel and the tile's next ray.
    auto refill = [&](int need) {
        for (int l = 0; l < W; ++l) {
            if (!(need >> l & 1)) continue;
            int kb, ke;
            if (!(L.a[l] >= opt.ert) && slot[l].runs->next(kb, ke)) {
                L.k[l] = kb, L.kend[l] = ke;
                continue;
            }
            write_pixel(out, opt, slot[l].x, slot[l].y,
                        kernel::Accum{L.r[l], L.g[l], L.b[l], L.a[l]}, uint32_t(L.n[l]));
            tile_samples += uint32_t(L.n[l]);
            --live;
            start(l);
        }
        return live > 0;
    };
    for (int l = 0; l < W; ++l) start(l);
    if (live > 0) march(L, lg, data, &lut[0].r, refill);
    samples += tile_samples;
    rays += tile_rays;
}

// One tile on the active kernel path (simd::active_isa()); volumes of 2^31 voxels or more, and
// the scalar path, march one ray at a time.
template <class T, bool kNearest, class S>
void render_tile_on(simd::Isa isa, bool small, const S& accel, const Volume& vol, const T* data,
                    const Camera& cam, const RenderOptions& opt, const std::vector<Rgba>& lut,
                    ValueToLut map, int x0, int y0, int x1, int y1, RenderResult& out,
                    std::atomic<uint64_t>& samples, std::atomic<uint64_t>& rays) {
    if (!small || (x1 - x0) * (y1 - y0) > kMaxTilePixels) {
        render_tile<T, int64_t, kNearest>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out,
                                samples, rays);
        return;
    }
#if LACUNA_SIMD_X86
    // The refined grid on AVX-512 and AVX2: every ray one run, leaping in the lanes
    // (core/simd_lanes.h).
    if constexpr (std::is_same_v<S, BrickGrid> && !kNearest) {
        static const NoAccel kWholeRay;
        if (isa == simd::Isa::Avx512 && accel.leap_map()) {
            render_tile_lanes<16>(
                kWholeRay, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out, samples, rays,
                [](simd::Lanes& L, const simd::LaneGrid& lg, const T* d, const float* l, auto& refill) {
                    simd::march_lanes16<false, T, std::remove_reference_t<decltype(refill)>, true>(
                        L, lg, d, l, refill);
                },
                &accel);
            return;
        }
        if (isa == simd::Isa::Avx2 && accel.leap_map()) {
            render_tile_lanes<8>(
                kWholeRay, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out, samples, rays,
                [](simd::Lanes& L, const simd::LaneGrid& lg, const T* d, const float* l, auto& refill) {
                    simd::march_lanes8<false, T, std::remove_reference_t<decltype(refill)>, true>(
                        L, lg, d, l, refill);
                },
                &accel);
            return;
        }
    }
#endif
    switch (isa) {
#if LACUNA_SIMD_X86
        case simd::Isa::Avx512:
            render_tile_lanes<16>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out,
                                  samples, rays,
                                  [](auto&&... a) { simd::march_lanes16<kNearest, T>(a...); });
            return;
        case simd::Isa::Avx2:
            render_tile_lanes<8>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out,
                                 samples, rays,
                                  [](auto&&... a) { simd::march_lanes8<kNearest, T>(a...); });
            return;
#if defined(__SSE4_1__)
        case simd::Isa::Sse41:
            render_tile_lanes<4>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out,
                                 samples, rays,
                                  [](auto&&... a) { simd::march_lanes4<kNearest, T>(a...); });
            return;
#endif
#endif
        default:
            render_tile<T, int32_t, kNearest>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out,
                                    samples, rays);
    }
}

}  // namespace

RenderResult RayMarcher::render(const Camera& world_cam, const RenderOptions& world_opt) const {
    if (m_lut.entries.empty()) throw Error("render", "transfer function", "none was set");
    if (!m_back_lut.entries.empty() && world_opt.features.clip_planes.empty())
        throw Error("--tf-back", "clip plane", "a back TF needs a clip plane (--clip) to split at");
    // 0. World (RAS) -> the volume frame, where everything below works (lacuna/orientation.h).
    const VolumeFrame vf = volume_frame(m_volume);
    const Camera cam = to_volume_frame(vf, world_cam);
    RenderOptions mapped;
    const RenderOptions& opt = to_volume_frame(vf, world_opt, mapped);
    if (!(opt.step > 0.f) || !std::isfinite(opt.step))
        throw Error("--step", "step", "expected a positive number");
    if (cam.width() < 1 || cam.height() < 1)
        throw Error("--size", "image size", "expected at least 1x1 pixels");
    if (m_accel && m_accel->interpolation() == Interpolation::Nearest &&
        opt.interpolation != Interpolation::Nearest)
        throw Error("--interpolation", "sampling",
                    "the structure was built for nearest sampling; expected --interpolation nearest");
    if (opt.features.any()) return render_features(cam, opt);
    RenderResult out;
    out.image = Image(cam.width(), cam.height());
    if (opt.count_samples) out.sample_counts.assign(size_t(cam.width()) * cam.height(), 0);
    if (opt.keep_float) out.rgba_float.assign(size_t(cam.width()) * cam.height() * 4, 0.f);
    std::vector<Rgba> lut = step_corrected_lut(m_lut, opt.step);
    lut.push_back(Rgba{});  // the zero entry idle SIMD lanes composite (never mapped to)
    const ValueToLut map = m_lut.map();
    std::atomic<uint64_t> samples{0}, rays{0};
    const simd::Isa isa = simd::active_isa();
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = process_cpu_seconds();
    visit_voxels(m_volume, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        const bool small = m_volume.voxel_count() < (size_t(1) << 31);
        static const NoAccel kNone;
        visit_accel(m_accel ? *m_accel : kNone, [&](const auto& s) {
            auto frame = [&](auto nearest) {
                parallel_for_tiles(cam.width(), cam.height(), opt.tile, opt.threads,
                                   [&](int x0, int y0, int x1, int y1) {
                                       render_tile_on<T, decltype(nearest)::value>(
                                           isa, small, s, m_volume, data, cam, opt, lut, map, x0,
                                           y0, x1, y1, out, samples, rays);
                                   });
            };
            if (opt.interpolation == Interpolation::Nearest)
                frame(std::true_type{});
            else
                frame(std::false_type{});
        });
    });
    const auto t1 = std::chrono::steady_clock::now();
    out.stats.seconds = std::chrono::duration<double>(t1 - t0).count();
    out.stats.cpu_seconds = process_cpu_seconds() - cpu0;
    out.stats.samples = samples;
    out.stats.rays = rays;
    out.stats.pixels = uint64_t(cam.width()) * cam.height();
    return out;
}

}  // namespace lacuna
