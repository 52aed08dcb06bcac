// RayMarcher::render_features: validates the feature options, sets up the feature kernel's
// context (LUTs per side, index-space clip planes, lights), fills the cache of precomputed
// gradient and light volumes, and runs src/render/feature_kernel.h over the tiles.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "accel/accel_impl.h"
#include "core/parallel.h"
#include "lacuna/error.h"
#include "lacuna/renderer.h"
#include "render/feature_kernel.h"
#include "render/marcher_cache.h"
#include "render/ownership.h"

namespace lacuna {

namespace {

bool finite3(Vec3f v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

void validate_features(const FeatureOptions& f) {
    // Errors name FeatureOptions' fields as FrameSpec holds them (FrameSpec::features).
    auto fail = [](const char* field, const std::string& expected) {
        throw FrameError(field, expected);
    };
    const PhongParams& p = f.phong;
    if (!(p.ambient >= 0 && p.diffuse >= 0 && p.specular >= 0 && p.power >= 0) ||
        !std::isfinite(p.ambient + p.diffuse + p.specular + p.power))
        fail("features.phong", "expected finite ambient, diffuse, specular, power >= 0");
    if (!(f.pbr.roughness > 0 && f.pbr.roughness <= 1) ||
        !(f.pbr.metallic >= 0 && f.pbr.metallic <= 1) ||
        !(f.pbr.ambient >= 0 && std::isfinite(f.pbr.ambient)))
        fail("features.pbr", "expected roughness in (0,1], metallic in [0,1], ambient >= 0");
    const GradientOpacity& go = f.gradient_opacity;
    if (go.enabled && go.points.empty() && !(go.lo >= 0 && go.lo <= go.hi && std::isfinite(go.hi)))
        fail("features.gradient_opacity", "expected 0 <= LO <= HI");
    if (go.enabled)
        for (size_t i = 0; i < go.points.size(); ++i) {
            const GradientOpacityPoint& q = go.points[i];
            if (!(q.x >= 0 && std::isfinite(q.x) && q.a >= 0 && q.a <= 1))
                fail("features.gradient_opacity.points",
                     "expected points (x, a) with finite x >= 0 and a in [0,1]");
            if (i > 0 && q.x < go.points[i - 1].x)
                fail("features.gradient_opacity.points", "expected points sorted by x");
            if (i > 1 && q.x == go.points[i - 2].x)
                fail("features.gradient_opacity.points",
                     "expected at most two points per x (a step)");
        }
    const Light& l = f.light;
    if (!(l.intensity >= 0 && std::isfinite(l.intensity)))
        fail("features.light.intensity", "expected a finite intensity >= 0");
    if (l.kind == LightKind::Directional && !(finite3(l.direction) && length(l.direction) > 0))
        fail("features.light.direction", "expected a finite non-zero direction");
    if (l.kind == LightKind::Spot &&
        (!finite3(l.position) || !finite3(l.target) || !(length(l.target - l.position) > 0) ||
         !(l.cone_deg > 0 && l.cone_deg < 90)))
        fail("features.light",
             "expected position != target and a cone half-angle in (0, 90) degrees");
    if (!(f.shadows.step > 0 && f.shadows.step <= 64))
        fail("features.shadows.step", "expected 0 < step <= 64");
    if (f.shadows.light_volume_stride < 1 || f.shadows.light_volume_stride > 64)
        fail("features.shadows.light_volume_stride", "expected 1..64");
    for (const ClipPlane& c : f.clip_planes)
        if (!finite3(c.normal) || !(length(c.normal) > 0) || !std::isfinite(c.d))
            fail("features.clip_planes", "expected a finite non-zero normal and a finite offset");
    if (f.crop &&
        !(finite3(f.crop_box.lo) && finite3(f.crop_box.hi) && f.crop_box.lo.x <= f.crop_box.hi.x &&
          f.crop_box.lo.y <= f.crop_box.hi.y && f.crop_box.lo.z <= f.crop_box.hi.z))
        fail("features.crop_box", "expected x0 <= x1, y0 <= y1, z0 <= z1");
}

namespace {

// Per-voxel central differences (one-sided at the faces), in voxel values per mm.
template <class T>
void gradient_volume(const Volume& v, const T* data, std::vector<float> out[3], int threads) {
    const Vec3i d = v.dims();
    for (int a = 0; a < 3; ++a) out[a].assign(v.voxel_count(), 0.f);
    const float inv[3] = {float(1.0 / v.spacing.x), float(1.0 / v.spacing.y),
                          float(1.0 / v.spacing.z)};
    parallel_for(size_t(d.z), threads, [&](size_t z0, size_t z1) {
        for (int k = int(z0); k < int(z1); ++k)
            for (int j = 0; j < d.y; ++j)
                for (int i = 0; i < d.x; ++i) {
                    auto at = [&](int x, int y, int z) {
                        x = std::clamp(x, 0, d.x - 1), y = std::clamp(y, 0, d.y - 1),
                        z = std::clamp(z, 0, d.z - 1);
                        return float(data[v.index(x, y, z)]);
                    };
                    const size_t idx = v.index(i, j, k);
                    out[0][idx] = (at(i + 1, j, k) - at(i - 1, j, k)) * 0.5f * inv[0];
                    out[1][idx] = (at(i, j + 1, k) - at(i, j - 1, k)) * 0.5f * inv[1];
                    out[2][idx] = (at(i, j, k + 1) - at(i, j, k - 1)) * 0.5f * inv[2];
                }
    });
}

// Everything the light volume depends on, exactly (hex floats).
std::string light_key(const FeatureOptions& f, Vec3f l_fixed, uint64_t tf_version, float ert) {
    std::string k;
    char buf[128];
    auto add = [&](float x) {
        std::snprintf(buf, sizeof buf, "%a,", double(x));
        k += buf;
    };
    k += to_string(f.light.kind) + ":";
    for (Vec3f v : {l_fixed, f.light.position, f.light.target}) add(v.x), add(v.y), add(v.z);
    add(f.light.cone_deg), add(f.shadows.step), add(ert), add(float(f.shadows.light_volume_stride));
    for (const ClipPlane& c : f.clip_planes)
        add(c.normal.x), add(c.normal.y), add(c.normal.z), add(c.d);
    if (f.crop)
        for (Vec3f v : {f.crop_box.lo, f.crop_box.hi}) add(v.x), add(v.y), add(v.z);
    return k + "tf" + std::to_string(tf_version);
}

}  // namespace

RenderResult RayMarcher::render_features(const Camera& cam, const RenderOptions& opt) const {
    const FeatureOptions& f = opt.features;
    validate_features(f);
    const bool two_tfs = !m_back_lut.entries.empty();
    if (two_tfs && f.clip_planes.empty())
        throw FrameError("two_tfs", "expected a clip plane to split the two TFs at");
    if (two_tfs) union_lut(m_lut, m_back_lut);  // throws if the LUTs are incompatible

    RenderResult out;
    out.image = Image(cam.width(), cam.height());
    if (opt.count_samples) out.sample_counts.assign(size_t(cam.width()) * cam.height(), 0);
    if (opt.keep_float) out.rgba_float.assign(size_t(cam.width()) * cam.height() * 4, 0.f);

    // 1. LUTs per side.
    const TransferLut& back = two_tfs ? m_back_lut : m_lut;
    const std::vector<Rgba> corr0 = step_corrected_lut(m_lut, opt.step),
                            corr1 = step_corrected_lut(back, opt.step),
                            sh0 = step_corrected_lut(m_lut, f.shadows.step),
                            sh1 = step_corrected_lut(back, f.shadows.step);
    feature::Context c;
    c.f = &f;
    c.raw[0] = m_lut.entries.data(), c.raw[1] = back.entries.data();
    c.corr[0] = corr0.data(), c.corr[1] = corr1.data();
    c.shadow_corr[0] = sh0.data(), c.shadow_corr[1] = sh1.data();
    c.map = m_lut.map();
    c.two_tfs = two_tfs;
    c.threads = opt.threads;
    // Distributed rendering: a brick's owned samples (feature::Context::brick). Its voxel offsets
    // are whole-grid offsets from a moved pointer (render/ownership.h brick_grid), so the lane
    // paths' int32 offsets must hold the brick's last voxel counted from there.
    const BrickOwnership* brick = opt.brick ? &*opt.brick : nullptr;
    c.brick = brick;
    const ptrdiff_t shift = brick ? brick_shift(*brick, m_volume.dims()) : 0;

    // 2. Geometry in index space.
    const Vec3d& s = m_volume.spacing;
    c.sp = {float(s.x), float(s.y), float(s.z)};
    c.inv_sp = {float(1.0 / s.x), float(1.0 / s.y), float(1.0 / s.z)};
    const float min_sp = float(std::min({s.x, s.y, s.z}));
    c.step = opt.step;
    c.nearest = opt.interpolation == Interpolation::Nearest;
    c.dt = opt.step * min_sp;
    c.dts = f.shadows.step * min_sp;
    c.ert = opt.ert;
    std::vector<feature::HalfSpace> clips;
    for (size_t i = 0; i < f.clip_planes.size(); ++i) {
        const feature::HalfSpace h = feature::to_index(f.clip_planes[i], c.sp);
        if (two_tfs && i == 0)
            c.split = h;
        else
            clips.push_back(h);
    }
    c.clips = clips.data();
    c.n_clips = int(clips.size());
    if (f.crop)
        for (int a = 0; a < 3; ++a) {
            c.crop_lo[a] = f.crop_box.lo[a] * c.inv_sp[a];
            c.crop_hi[a] = f.crop_box.hi[a] * c.inv_sp[a];
        }
    const bool composite = f.blend == BlendMode::Composite;
    c.need_gradient = composite && (f.shading != ShadingModel::None || f.gradient_opacity.enabled);
    c.light_dir =
        f.light.kind == LightKind::Directional ? normalize(f.light.direction) : Vec3f{0, 0, 1};
    if (f.light.kind == LightKind::Spot) c.spot_axis = normalize(f.light.target - f.light.position);
    const bool shadows = composite && f.shadows.enabled;

    std::lock_guard<std::mutex> lock(m_cache->mutex);
    // 3. The precomputed gradient volume (once per marcher: it depends on the volume only).
    if (c.need_gradient && f.gradient == GradientSource::Precomputed) {
        if (m_cache->grad[0].empty()) {
            const auto t0 = std::chrono::steady_clock::now();
            visit_voxels(m_volume, [&](const auto* data) {
                gradient_volume(m_volume, data, m_cache->grad, opt.threads);
            });
            out.stats.gradient_volume_seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        for (int a = 0; a < 3; ++a) c.grad[a] = shift_to_whole(m_cache->grad[a].data(), shift);
        out.stats.gradient_volume_bytes = 3 * m_cache->grad[0].size() * sizeof(float);
    }

    std::atomic<uint64_t> samples{0}, rays{0}, shadow{0};
    const Vec3i d = m_volume.dims();
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = process_cpu_seconds();
    visit_voxels(m_volume, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        // The feature path always indexes with int64 (it is not the hot path for huge grids).
        const kernel::Grid<T, int64_t> g =
            brick ? brick_grid(data, d, *brick) : kernel::make_grid<int64_t>(data, d);
        static const NoAccel kNone;
        visit_accel(m_accel ? *m_accel : kNone, [&](const auto& acc) {
            // 4. The light volume, when the light, TF or clipping changed since it was made.
            if (shadows && f.shadows.light_volume) {
                const Vec3f l_fixed =
                    f.light.kind == LightKind::Head ? -cam.forward() : c.light_dir;
                const std::string key = light_key(f, l_fixed, m_tf_version, opt.ert);
                const int stride = f.shadows.light_volume_stride;
                int* m = m_cache->light_dims;
                if (key != m_cache->light_key) {
                    const auto l0 = std::chrono::steady_clock::now();
                    m[0] = std::max(2, (d.x - 2) / stride + 2);
                    m[1] = std::max(2, (d.y - 2) / stride + 2);
                    m[2] = std::max(2, (d.z - 2) / stride + 2);
                    m_cache->light.assign(size_t(m[0]) * m[1] * m[2], 1.f);
                    for (int a = 0; a < 3; ++a) c.light_dims[a] = m[a];
                    feature::build_light_volume(c, g, acc, l_fixed, float(stride),
                                                m_cache->light.data(), shadow);
                    m_cache->light_key = key;
                    out.stats.light_volume_seconds =
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - l0)
                            .count();
                }
                for (int a = 0; a < 3; ++a) c.light_dims[a] = m[a];
                c.light = m_cache->light.data();
                c.inv_stride = 1.f / float(stride);
                out.stats.light_volume_bytes = m_cache->light.size() * sizeof(float);
            }
            // 5. The frame: composite rays without shadows or gradient opacity on the batched SIMD
            // path of the active ISA (int32 offsets: grids under 2^31 voxels), the rest one sample
            // at a time (feature::composite_ray, the reference; also the scalar ISA path).
            const Vec3i w = brick ? brick->whole_dims : d;  // the grid the rays sample
            const int dims[3] = {w.x, w.y, w.z};
            simd::ShadeGrid sg = feature::shade_grid(c, dims);
            sg.sy = int32_t(g.sy), sg.sz = int32_t(g.sz);  // a brick's strides (else the same)
            // The structure's visible-cell mask (refined grids), for the plain batched case: one
            // TF (the structure's), no clip planes or crop box, trilinear samples (not a brick's:
            // its cells are in brick index space).
            if constexpr (requires { acc.cell_mask(); })
                if (!c.nearest && !c.two_tfs && c.n_clips == 0 && !f.crop && !brick)
                    sg.cell_mask = acc.cell_mask();
            // Nearest sampling runs the reference too (one path for every ISA, so still exact).
            const bool batched = composite && !f.shadows.enabled && !f.gradient_opacity.enabled &&
                                 !c.nearest &&
                                 size_t(shift) + m_volume.voxel_count() < (size_t(1) << 31);
            auto frame = [&](auto ops) {
                using Ops = typename decltype(ops)::type;
                parallel_for_tiles(cam.width(), cam.height(), opt.tile, opt.threads,
                                   [&](int x0, int y0, int x1, int y1) {
                                       feature::Counts n;
                                       feature::render_tile<Ops>(c, acc, g, sg, cam, opt, x0, y0,
                                                                 x1, y1, out, n);
                                       samples += n.samples;
                                       rays += n.rays;
                                       shadow += n.shadow;
                                   });
            };
            const simd::Isa isa = batched ? simd::active_isa() : simd::Isa::Scalar;
#if LACUNA_SIMD_X86
            // The refined grid, Phong with a fixed light, one TF, no clipping: shaded rays in
            // lanes, leaping (simd::march_shaded_lanes8; tiles too large for the scheduler take
            // ShadedStream).
            if constexpr (std::is_same_v<std::decay_t<decltype(acc)>, BrickGrid>) {
                if ((isa == simd::Isa::Avx2 || isa == simd::Isa::Avx512) &&
                    feature::lanes_shade(c) && acc.leap_map() && !brick) {
                    std::vector<Rgba> corr_z = corr0;
                    corr_z.push_back(Rgba{});  // the zero entry idle lanes composite
                    simd::ShadeGrid sg_lanes = sg;
                    sg_lanes.cell_mask = nullptr;
                    const simd::ShadeFrame sf{
                        sg_lanes,
                        &c.raw[0][0].r,
                        c.grad[0] ? c.grad : nullptr,
                        {f.phong.ambient, f.phong.diffuse, f.phong.specular, f.phong.power},
                        f.light.intensity,
                        f.light.kind == LightKind::Head,
                        {c.light_dir.x, c.light_dir.y, c.light_dir.z}};
                    // One TF, no clipping: the grid's occupancy bounds the pixels that can see
                    // anything (render/screen_cover.h).
                    const std::optional<ScreenCover> cover = ScreenCover::build(acc, m_volume, cam);
                    parallel_for_tiles(cam.width(), cam.height(), opt.tile, opt.threads,
                                       [&](int x0, int y0, int x1, int y1) {
                                           feature::Counts n;
                                           if ((x1 - x0) * (y1 - y0) <= kMaxTilePixels)
                                               feature::render_tile_shaded_lanes(
                                                   c, acc, m_volume, data, sf, corr_z, cam, opt, x0,
                                                   y0, x1, y1, out, n, cover ? &*cover : nullptr);
                                           else
                                               feature::render_tile<feature::ShadeOps<8>>(
                                                   c, acc, g, sg, cam, opt, x0, y0, x1, y1, out, n);
                                           samples += n.samples;
                                           rays += n.rays;
                                       });
                    return;
                }
            }
            if (isa == simd::Isa::Avx512) return frame(std::type_identity<feature::ShadeOps<16>>{});
            if (isa == simd::Isa::Avx2) return frame(std::type_identity<feature::ShadeOps<8>>{});
#if defined(__SSE4_1__)
            if (isa == simd::Isa::Sse41) return frame(std::type_identity<feature::ShadeOps<4>>{});
#endif
#endif
            frame(std::type_identity<void>{});
        });
    });
    out.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out.stats.cpu_seconds = process_cpu_seconds() - cpu0;
    out.stats.samples = samples;
    out.stats.rays = rays;
    out.stats.shadow_samples = shadow;
    out.stats.pixels = uint64_t(cam.width()) * cam.height();
    return out;
}

}  // namespace lacuna
