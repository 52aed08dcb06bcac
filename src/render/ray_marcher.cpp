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
#include "lacuna/renderer.h"
#include "render/lane_scheduler.h"
#include "render/marcher_cache.h"
#include "render/ownership.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"
#include "render/rgb_march.h"
#include "render/screen_cover.h"
#include "render/volume_frame.h"

namespace lacuna {

std::string to_string(const RenderStats& s) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%.1f ms, %llu samples, %.1f samples/ray, %.1f Msamples/s",
                  s.seconds * 1e3, (unsigned long long)s.samples, s.samples_per_ray(),
                  s.msamples_per_second());
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

RayMarcher::RayMarcher(const Volume& volume)
    : m_volume(volume), m_cache(std::make_unique<Cache>()) {}
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
        case ShadingModel::None:
            return "none";
        case ShadingModel::Phong:
            return "phong";
        case ShadingModel::Pbr:
            return "pbr";
    }
    return "?";
}

std::string to_string(LightKind k) {
    switch (k) {
        case LightKind::Head:
            return "head";
        case LightKind::Directional:
            return "directional";
        case LightKind::Spot:
            return "spot";
    }
    return "?";
}

TransferLut union_lut(const TransferLut& a, const TransferLut& b) {
    if (a.size() != b.size() || a.vis.min != b.vis.min || a.vis.max != b.vis.max)
        throw FrameError("two_tfs",
                         "expected a back TF with the front TF's LUT size and "
                         "visualization range");
    TransferLut u = a;
    for (size_t e = 0; e < u.entries.size(); ++e)
        u.entries[e].a = std::max(a.entries[e].a, b.entries[e].a);
    return u;
}

Box3f RayMarcher::bounds() const {
    return world_bounds(m_volume);
}

namespace {

template <class T, class Index, bool kNearest, class S>
void render_tile(const S& accel, const Volume& vol, const T* data, const Camera& cam,
                 const RenderOptions& opt, const std::vector<Rgba>& lut, ValueToLut map, int x0,
                 int y0, int x1, int y1, RenderResult& out, std::atomic<uint64_t>& samples,
                 std::atomic<uint64_t>& rays, const ScreenCover* cover) {
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
            const bool hit = kernel::intersect_box(r, hi, t_near, t_far);
            tile_rays += hit;
            if (hit && (!cover || cover->covered(x, y))) {  // render/screen_cover.h
                typename S::Cursor cursor(accel, r, t_near, t_far, dt,
                                          opt.ert < 1.f ? kCursorChunk * dt : 0.f);
                kernel::RayStream<T, Index, kNearest> stream(g, r, t_near, dt, lut.data(), map,
                                                             opt.ert, acc);
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

// The same tile, W rays at a time (render/lane_scheduler.h; core/simd_lanes.h: one ray per
// lane, each composited in its own sample order, so the bits are those of render_tile).
template <int W, class T, class S, class March>
void render_tile_lanes(const S& accel, const Volume& vol, const T* data, const Camera& cam,
                       const RenderOptions& opt, const std::vector<Rgba>& lut, ValueToLut map,
                       int x0, int y0, int x1, int y1, RenderResult& out,
                       std::atomic<uint64_t>& samples, std::atomic<uint64_t>& rays, March&& march,
                       const ScreenCover* cover, const BrickGrid* leap = nullptr) {
    const kernel::Grid<T, int32_t> g = kernel::make_grid<int32_t>(data, vol.dims());
    const float dt = sample_distance(vol, opt.step);
    simd::LaneGrid lg = lane_grid(g, dt, map, lut.size(), opt.ert);
    if (leap) set_leap(lg, *leap);
    CompositePolicy policy{out, opt};
    uint64_t tile_samples = 0, tile_rays = 0;
    schedule_tile_lanes<W>(
        accel, vol, cam, dt, opt.ert < 1.f ? kLaneChunk * dt : 0.f, opt.ert, x0, y0, x1, y1, policy,
        tile_samples, tile_rays,
        [&](simd::Lanes& L, auto& refill) { march(L, lg, data, &lut[0].r, refill); }, cover);
    samples += tile_samples;
    rays += tile_rays;
}

// One tile on the active kernel path (simd::active_isa()); volumes of 2^31 voxels or more, and
// the scalar path, march one ray at a time.
template <class T, bool kNearest, class S>
void render_tile_on(simd::Isa isa, bool small, const S& accel, const Volume& vol, const T* data,
                    const Camera& cam, const RenderOptions& opt, const std::vector<Rgba>& lut,
                    ValueToLut map, int x0, int y0, int x1, int y1, RenderResult& out,
                    std::atomic<uint64_t>& samples, std::atomic<uint64_t>& rays,
                    const ScreenCover* cover) {
    if (rgb_colours(vol)) {  // colour from the data: the one-ray kernel of render/rgb_march.h only
        render_rgb_tile<T, kNearest>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out,
                                     samples, rays);
        return;
    }
    if (!small || (x1 - x0) * (y1 - y0) > kMaxTilePixels) {
        render_tile<T, int64_t, kNearest>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out,
                                          samples, rays, cover);
        return;
    }
#if LACUNA_SIMD_X86
    // The refined grid on AVX-512 and AVX2: every ray one run, leaping in the lanes
    // (core/simd_lanes.h; on AVX-512 two groups of sixteen lanes in flight, Group16).
    if constexpr (std::is_same_v<S, BrickGrid> && !kNearest) {
        static const NoAccel kWholeRay;
        if (isa == simd::Isa::Avx512 && accel.leap_map()) {
            render_tile_lanes<32>(
                kWholeRay, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out, samples, rays,
                [](simd::Lanes& L, const simd::LaneGrid& lg, const T* d, const float* l,
                   auto& refill) {
                    simd::march_lanes16<false, T, std::remove_reference_t<decltype(refill)>, true,
                                        2>(L, lg, d, l, refill);
                },
                cover, &accel);
            return;
        }
        if (isa == simd::Isa::Avx2 && accel.leap_map()) {
            render_tile_lanes<8>(
                kWholeRay, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out, samples, rays,
                [](simd::Lanes& L, const simd::LaneGrid& lg, const T* d, const float* l,
                   auto& refill) {
                    simd::march_lanes8<false, T, std::remove_reference_t<decltype(refill)>, true>(
                        L, lg, d, l, refill);
                },
                cover, &accel);
            return;
        }
    }
#endif
    switch (isa) {
#if LACUNA_SIMD_X86
        case simd::Isa::Avx512:
            render_tile_lanes<16>(
                accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out, samples, rays,
                [](auto&&... a) { simd::march_lanes16<kNearest, T>(a...); }, cover);
            return;
        case simd::Isa::Avx2:
            render_tile_lanes<8>(
                accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out, samples, rays,
                [](auto&&... a) { simd::march_lanes8<kNearest, T>(a...); }, cover);
            return;
#if defined(__SSE4_1__)
        case simd::Isa::Sse41:
            render_tile_lanes<4>(
                accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1, out, samples, rays,
                [](auto&&... a) { simd::march_lanes4<kNearest, T>(a...); }, cover);
            return;
#endif
#endif
        default:
            render_tile<T, int32_t, kNearest>(accel, vol, data, cam, opt, lut, map, x0, y0, x1, y1,
                                              out, samples, rays, cover);
    }
}

// Distributed rendering's tile (lacuna/renderer.h BrickOwnership; render/ownership.h): the whole
// grid's rays, box and lattice, the brick's voxels and structure, the owned samples only. One ray
// at a time (the lane paths have no ownership clip yet), early termination off.
template <class T, bool kNearest, class S>
void render_tile_brick(const S& accel, const Volume& vol, const T* data, const BrickOwnership& own,
                       const Camera& cam, const RenderOptions& opt, const std::vector<Rgba>& lut,
                       ValueToLut map, int x0, int y0, int x1, int y1, RenderResult& out,
                       std::atomic<uint64_t>& samples, std::atomic<uint64_t>& rays) {
    // 1. The whole grid through the brick's voxels (render/ownership.h brick_grid).
    const kernel::Grid<T, int64_t> g = brick_grid(data, vol.dims(), own);
    const Vec3f inv_sp = inverse_spacing(vol);
    const float dt = sample_distance(vol, opt.step);
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    const float off[3] = {float(own.offset.x), float(own.offset.y), float(own.offset.z)};
    uint64_t tile_samples = 0, tile_rays = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            const kernel::IndexRay r = index_ray(cam.generate(float(x), float(y)), inv_sp);
            kernel::Accum acc;
            uint32_t n = 0;
            float t_near, t_far;
            // 2. The whole grid's entry and exit, its lattice, and this rank's run of it.
            if (kernel::intersect_box(r, hi, t_near, t_far)) {
                ++tile_rays;
                const int k_end = lattice_end(t_near, t_far, dt);
                int ka, kb;
                owned_run(r, t_near, dt, k_end, own.lo, own.hi, ka, kb);
                if (ka < kb) {
                    // 3. The brick's structure walks the ray in brick index space over the run
                    // and a sample of margin each side; its segments are rounded outward to the
                    // whole lattice as always (pixel_driver.h), then clipped to the run.
                    IndexRay cr = r;
                    cr.ox -= off[0], cr.oy -= off[1], cr.oz -= off[2];
                    const float c0 = std::max(t_near, t_near + (float(ka) - 0.5f) * dt);
                    const float c1 = std::min(t_far, t_near + (float(kb) + 0.5f) * dt);
                    typename S::Cursor cursor(accel, cr, c0, c1, dt, 0.f);
                    kernel::RayStream<T, int64_t, kNearest> stream(g, r, t_near, dt, lut.data(),
                                                                   map, opt.ert, acc);
                    for_each_lattice_run(cursor, t_near, dt, kb, [&](int b, int e) {
                        b = std::max(b, ka);
                        return e > b ? stream.add(b, e) : true;
                    });
                    stream.finish();
                    n = stream.samples();
                }
            }
            tile_samples += n;
            write_pixel(out, opt, x, y, acc, n);
        }
    }
    samples += tile_samples;
    rays += tile_rays;
}

void check_brick(const Volume& vol, const BrickOwnership& b) {
    const Vec3i d = vol.dims();
    for (int a = 0; a < 3; ++a) {
        const bool ok = b.offset[a] >= 0 && b.offset[a] + d[a] <= b.whole_dims[a] &&
                        (std::isinf(b.lo[a]) || b.lo[a] >= float(b.offset[a])) &&
                        (std::isinf(b.hi[a]) || b.hi[a] <= float(b.offset[a] + d[a] - 1)) &&
                        b.lo[a] < b.hi[a];
        if (!ok)
            throw Error("render", "brick",
                        "expected the owned box inside the brick's voxels, got " + to_string(b) +
                            " for a brick of " + std::to_string(d.x) + "x" + std::to_string(d.y) +
                            "x" + std::to_string(d.z));
    }
}

}  // namespace

std::string to_string(const BrickOwnership& b) {
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "brick at (%d,%d,%d) of %dx%dx%d, owns [%g,%g) x [%g,%g) x [%g,%g)", b.offset.x,
                  b.offset.y, b.offset.z, b.whole_dims.x, b.whole_dims.y, b.whole_dims.z,
                  double(b.lo[0]), double(b.hi[0]), double(b.lo[1]), double(b.hi[1]),
                  double(b.lo[2]), double(b.hi[2]));
    return buf;
}

RenderResult RayMarcher::render(const Camera& world_cam, const RenderOptions& world_opt) const {
    if (m_lut.entries.empty()) throw Error("render", "transfer function", "none was set");
    if (!m_back_lut.entries.empty() && world_opt.features.clip_planes.empty())
        throw FrameError("two_tfs", "expected a clip plane to split the two TFs at");
    // 0. World (RAS) -> the volume frame, where everything below works (lacuna/orientation.h).
    const VolumeFrame vf = volume_frame(m_volume);
    const Camera cam = to_volume_frame(vf, world_cam);
    RenderOptions mapped;
    const RenderOptions& opt = to_volume_frame(vf, world_opt, mapped);
    if (!(opt.step > 0.f) || !std::isfinite(opt.step))
        throw FrameError("sampling.step", "expected a positive number");
    if (cam.width() < 1 || cam.height() < 1)
        throw FrameError("width", "expected at least 1x1 pixels");
    if (m_accel && m_accel->interpolation() == Interpolation::Nearest &&
        opt.interpolation != Interpolation::Nearest)
        throw FrameError("sampling.interpolation",
                         "the structure was built for nearest sampling; expected nearest");
    if (opt.brick) {
        // A brick's samples composite with the other bricks' in front of and behind them: no
        // early termination (the opacity in front is the other ranks'), and only features that
        // act on each sample alone (not shadows, which reach into other bricks, nor a second TF
        // or another blend mode, which composite differently).
        const FeatureOptions& f = opt.features;
        if (opt.ert < 1.f || f.shadows.enabled || f.blend != BlendMode::Composite ||
            !m_back_lut.entries.empty())
            throw FrameError("features",
                             "a brick renders without early termination, shadows, blend modes or "
                             "two TFs");
        check_brick(m_volume, *opt.brick);
    }
    check_rgb_options(m_volume, opt);
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
    if (opt.brick) {
        // Distributed rendering: the owned samples of this brick (render_tile_brick).
        visit_voxels(m_volume, [&](const auto* data) {
            using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
            static const NoAccel kNone;
            visit_accel(m_accel ? *m_accel : kNone, [&](const auto& s) {
                auto frame = [&](auto nearest) {
                    parallel_for_tiles(cam.width(), cam.height(), opt.tile, opt.threads,
                                       [&](int x0, int y0, int x1, int y1) {
                                           render_tile_brick<T, decltype(nearest)::value>(
                                               s, m_volume, data, *opt.brick, cam, opt, lut, map,
                                               x0, y0, x1, y1, out, samples, rays);
                                       });
                };
                if (opt.interpolation == Interpolation::Nearest)
                    frame(std::true_type{});
                else
                    frame(std::false_type{});
            });
        });
    } else {
        visit_voxels(m_volume, [&](const auto* data) {
            using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
            const bool small = m_volume.voxel_count() < (size_t(1) << 31);
            static const NoAccel kNone;
            visit_accel(m_accel ? *m_accel : kNone, [&](const auto& s) {
                // The grid, once refined for this TF, bounds the pixels that can see anything
                // (render/screen_cover.h); the rest are written empty without marching.
                std::optional<ScreenCover> cover;
                if constexpr (std::is_same_v<std::remove_cvref_t<decltype(s)>, BrickGrid>)
                    cover = ScreenCover::build(s, m_volume, cam);
                const ScreenCover* cv = cover ? &*cover : nullptr;
                auto frame = [&](auto nearest) {
                    parallel_for_tiles(cam.width(), cam.height(), opt.tile, opt.threads,
                                       [&](int x0, int y0, int x1, int y1) {
                                           render_tile_on<T, decltype(nearest)::value>(
                                               isa, small, s, m_volume, data, cam, opt, lut, map,
                                               x0, y0, x1, y1, out, samples, rays, cv);
                                       });
                };
                if (opt.interpolation == Interpolation::Nearest)
                    frame(std::true_type{});
                else
                    frame(std::false_type{});
            });
        });
    }
    const auto t1 = std::chrono::steady_clock::now();
    out.stats.seconds = std::chrono::duration<double>(t1 - t0).count();
    out.stats.cpu_seconds = process_cpu_seconds() - cpu0;
    out.stats.samples = samples;
    out.stats.rays = rays;
    out.stats.pixels = uint64_t(cam.width()) * cam.height();
    return out;
}

}  // namespace lacuna
