// The feature kernel: the ray marcher's sample loop with shading, gradient opacity, lights and
// shadow rays, clip planes, a crop box, two TFs split by a plane, MIP / MinIP / average blending
// and jittered ray starts (docs/shading.md). The features-off path stays the fast kernel of
// render/ray_march_kernel.h; this one is scalar, one sample at a time, and runs only when a
// feature is on (RenderOptions::features.any()).
//
// Exactness (docs/architecture.md, invariant 1) holds per feature:
//  - Every sample the structure may drop has TF opacity exactly 0 on its side of the split plane
//    (the structure is given union_lut(front, back)). Such a sample contributes nothing here
//    either: it is tested (`raw.a > 0`) and left out before any shading, so the kept samples and
//    their order - hence every float operation - are those of the unaccelerated ray.
//  - Gradient opacity multiplies the TF opacity: zero stays zero. Gradients read a neighbourhood
//    of the sample (+-1 voxel) but are only evaluated for samples that are kept anyway.
//  - Shadow rays march the same structure with their own lattice from the sample toward the
//    light and drop only zero-opacity samples, so their transmittance is bit-identical to the
//    unaccelerated shadow ray's (ShadowOptions::accelerate = false).
//  - Clip planes and the crop box remove samples by a per-sample test of the same position in
//    both paths; they never change which samples a structure may skip.
//  - MIP / MinIP skip through src/accel/entry_window.h (exact by its own argument); average
//    averages the values of samples with non-zero TF opacity, so zero-opacity samples may go.
//  - Jitter shifts the lattice per pixel by the same amount in both paths.
#pragma once
#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "accel/cursor.h"
#include "accel/entry_window.h"
#include "accel/no_accel.h"
#include "core/gradient.h"
#include "core/parallel.h"
#include "core/simd_shading.h"
#include "lacuna/camera.h"
#include "lacuna/image.h"
#include "lacuna/renderer.h"
#include "render/lane_scheduler.h"
#include "render/ownership.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"
#include "render/shading.h"

namespace lacuna::feature {

// A half-space in index space: kept when nx*x + ny*y + nz*z >= d.
struct HalfSpace {
    float nx = 0, ny = 0, nz = 0, d = 0;
    bool inside(float x, float y, float z) const { return nx * x + ny * y + nz * z >= d; }
};

// World plane dot(n, p) >= d as an index-space half-space (p = index * spacing).
inline HalfSpace to_index(const ClipPlane& p, Vec3f sp) {
    return {p.normal.x * sp.x, p.normal.y * sp.y, p.normal.z * sp.z, p.d};
}

// A float grid sampled with the renderer's trilinear() (gradient and light volumes).
inline kernel::Grid<float, int64_t> float_grid(const float* data, const int m[3]) {
    return {data,
            ptrdiff_t(m[0]),
            ptrdiff_t(m[0]) * m[1],
            float(m[0] - 1),
            float(m[1] - 1),
            float(m[2] - 1),
            m[0] - 2,
            m[1] - 2,
            m[2] - 2};
}

// Everything a feature sample needs, set up once per frame (src/render/ray_marcher.cpp).
struct Context {
    const FeatureOptions* f = nullptr;
    // [side]: 0 = front TF, 1 = back TF (equal to front when there is no back TF).
    const Rgba* raw[2] = {};          // straight colour, opacity per unit distance
    const Rgba* corr[2] = {};         // step_corrected_lut(step)
    const Rgba* shadow_corr[2] = {};  // step_corrected_lut(shadows.step)
    ValueToLut map;
    bool two_tfs = false;
    HalfSpace split;                   // clip plane 0 when two_tfs
    const HalfSpace* clips = nullptr;  // the clipping half-spaces (plane 0 excluded when two_tfs)
    int n_clips = 0;
    float crop_lo[3] = {}, crop_hi[3] = {};  // index space
    float step = 0.5f, dt = 0, dts = 0, ert = kNoEarlyTermination;
    Vec3f sp{1, 1, 1}, inv_sp{1, 1, 1};
    bool nearest = false;  // Interpolation::Nearest: value() reads the nearest voxel
    bool need_gradient = false;
    const float* grad[3] = {};     // precomputed world gradient, or null: on the fly
    const float* light = nullptr;  // light volume (transmittance), or null
    int light_dims[3] = {0, 0, 0};
    float inv_stride = 1.f;
    Vec3f light_dir{0, 0, 1};   // directional: unit vector to the light
    Vec3f spot_axis{0, 0, -1};  // spot: unit vector from the light to its target
    int threads = 0;
    // Distributed rendering (lacuna/renderer.h BrickOwnership): the owned samples only, the grid
    // the whole grid seen through the brick's voxels (render/ownership.h brick_grid), the
    // structure walked in brick index space. Null: the whole volume.
    const BrickOwnership* brick = nullptr;

    bool kept(float x, float y, float z) const {
        for (int i = 0; i < n_clips; ++i)
            if (!clips[i].inside(x, y, z)) return false;
        if (f->crop && !(x >= crop_lo[0] && x <= crop_hi[0] && y >= crop_lo[1] && y <= crop_hi[1] &&
                         z >= crop_lo[2] && z <= crop_hi[2]))
            return false;
        return true;
    }
    int side(float x, float y, float z) const { return two_tfs && !split.inside(x, y, z) ? 1 : 0; }
};

// Deterministic per-pixel jitter in [0, 1) (a 32-bit integer hash of pixel and seed).
inline float jitter(uint32_t x, uint32_t y, uint32_t seed) {
    uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ (seed + 1u) * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return float(h >> 8) * (1.f / 16777216.f);
}

// The sample value at index point (x,y,z) under the frame's interpolation.
template <class T, class Index>
inline float value(const Context& c, const kernel::Grid<T, Index>& g, float x, float y, float z) {
    return c.nearest ? kernel::nearest(g, x, y, z) : kernel::trilinear(g, x, y, z);
}

// World-space gradient (voxel values per mm) at index point (x,y,z). Under nearest sampling, the
// gradient of the voxel the sample reads (the point moved to that voxel: central differences of
// voxels, as VTK's nearest mode shades with per-voxel normals).
template <class T, class Index>
inline Vec3f gradient(const Context& c, const kernel::Grid<T, Index>& g, float x, float y,
                      float z) {
    const float isp[3] = {c.inv_sp.x, c.inv_sp.y, c.inv_sp.z};
    if (c.nearest) {
        const int i = int(std::clamp(x, 0.f, g.hi_x) + 0.5f),
                  j = int(std::clamp(y, 0.f, g.hi_y) + 0.5f),
                  k = int(std::clamp(z, 0.f, g.hi_z) + 0.5f);
        if (!c.grad[0]) {
            const int last[3] = {g.cell_x + 1, g.cell_y + 1, g.cell_z + 1};
            float gr[3];
            voxel_gradient(g.data, g.sy, g.sz, last, isp, i, j, k, gr);
            return {gr[0], gr[1], gr[2]};
        }
        x = float(i), y = float(j), z = float(k);
    }
    if (c.grad[0]) {
        // The gradient volume is laid out as the voxels are (with a brick's strides and moved
        // pointer under distributed rendering): the voxels' grid with its data swapped.
        auto of = [&](const float* d) {
            return kernel::Grid<float, int64_t>{d,      g.sy,     g.sz,     g.hi_x,  g.hi_y,
                                                g.hi_z, g.cell_x, g.cell_y, g.cell_z};
        };
        return {kernel::trilinear(of(c.grad[0]), x, y, z),
                kernel::trilinear(of(c.grad[1]), x, y, z),
                kernel::trilinear(of(c.grad[2]), x, y, z)};
    }
    // The voxels' central differences, interpolated at the sample (core/gradient.h).
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    const int cell[3] = {g.cell_x, g.cell_y, g.cell_z};
    float gr[3];
    central_gradient(g.data, g.sy, g.sz, hi, cell, isp, x, y, z, gr);
    return {gr[0], gr[1], gr[2]};
}

// Transmittance from index point (x,y,z) toward the light along world direction l (unit), up to
// world distance t_max: a shadow ray on its own lattice t_k = (k + 0.5)*dts through the same
// skipping structure (or every sample when !accelerate), opacity from the shadow-step LUT of
// each sample's side, clipped samples transparent, early termination at the frame's ert.
template <class T, class Index, class S>
float transmittance(const Context& c, const kernel::Grid<T, Index>& g, const S& accel, float x,
                    float y, float z, Vec3f l, float t_max, uint64_t& n) {
    const kernel::IndexRay r{x, y, z, l.x * c.inv_sp.x, l.y * c.inv_sp.y, l.z * c.inv_sp.z};
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    float t0, t1;
    if (!kernel::intersect_box(r, hi, t0, t1)) return 1.f;
    t1 = std::min(t1, t_max);
    const int k_end = std::max(int(std::ceil(t1 / c.dts - 0.5f)), 0);
    float a = 0.f;
    auto fn = [&](int k) {
        const float t = (float(k) + 0.5f) * c.dts;
        const float qx = r.ox + t * r.dx, qy = r.oy + t * r.dy, qz = r.oz + t * r.dz;
        if (!c.kept(qx, qy, qz)) return true;
        ++n;
        const float as = c.shadow_corr[c.side(qx, qy, qz)][c.map(value(c, g, qx, qy, qz))].a;
        if (as > 0.f) {
            a += (1.f - a) * as;
            if (a >= c.ert) return false;
        }
        return true;
    };
    const IndexRay& cr = r;
    const float chunk = c.ert < 1.f ? 16.f * c.dts : 0.f;
    if (c.f->shadows.accelerate) {
        typename S::Cursor cursor(accel, cr, 0.f, t1, c.dts, chunk);
        for_each_sample(cursor, 0.f, c.dts, k_end, fn);
    } else {
        static const NoAccel kNone;
        NoAccel::Cursor cursor(kNone, cr, 0.f, t1);
        for_each_sample(cursor, 0.f, c.dts, k_end, fn);
    }
    return 1.f - a;
}

// The light at a sample: direction l to it, its intensity li there (spot falloff applied) and
// the distance to it (infinite for directional lights). `view` is the unit vector to the eye.
inline void light_at(const Context& c, Vec3f pw, Vec3f view, Vec3f& l, float& li, float& dist) {
    const Light& L = c.f->light;
    li = L.intensity;
    dist = INFINITY;
    switch (L.kind) {
        case LightKind::Head:
            l = view;
            break;
        case LightKind::Directional:
            l = c.light_dir;
            break;
        case LightKind::Spot: {
            const Vec3f d = L.position - pw;
            dist = length(d);
            l = dist > 0.f ? d / dist : c.spot_axis * -1.f;
            li *= shading::spot_factor(-dot(l, c.spot_axis), L.cone_deg);
            break;
        }
    }
}

// The light volume: transmittance toward the light at every stride-th voxel (index points
// (i,j,k)*stride clamped into the box), computed with shadow rays through the structure.
// `l_fixed` is the light direction for head and directional lights.
template <class T, class Index, class S>
void build_light_volume(const Context& c, const kernel::Grid<T, Index>& g, const S& accel,
                        Vec3f l_fixed, float stride, float* out, std::atomic<uint64_t>& samples) {
    const int* m = c.light_dims;
    parallel_for(size_t(m[2]), c.threads, [&](size_t z0, size_t z1) {
        uint64_t n = 0;
        for (size_t k = z0; k < z1; ++k)
            for (int j = 0; j < m[1]; ++j)
                for (int i = 0; i < m[0]; ++i) {
                    const float x = std::min(float(i) * stride, g.hi_x),
                                y = std::min(float(j) * stride, g.hi_y),
                                z = std::min(float(k) * stride, g.hi_z);
                    Vec3f l = l_fixed;
                    float t_max = INFINITY;
                    if (c.f->light.kind == LightKind::Spot) {
                        const Vec3f d = c.f->light.position - Vec3f{x, y, z} * c.sp;
                        t_max = length(d);
                        l = t_max > 0.f ? d / t_max : c.spot_axis * -1.f;
                    }
                    out[(k * size_t(m[1]) + size_t(j)) * size_t(m[0]) + size_t(i)] =
                        transmittance(c, g, accel, x, y, z, l, t_max, n);
                }
        samples += n;
    });
}

// Per-tile counters.
struct Counts {
    uint64_t samples = 0, rays = 0, shadow = 0;
};

// Composite: the shaded, lit, clipped emission-absorption ray. Returns the samples taken.
template <class T, class Index, class S, class Cursor>
inline uint32_t composite_ray(const Context& c, const kernel::Grid<T, Index>& g, const S& accel,
                              Cursor& cursor, const kernel::IndexRay& r, Vec3f view, float t_base,
                              int k_end, kernel::Accum& acc, uint64_t& shadow_n, int k_begin = 0) {
    const FeatureOptions& f = *c.f;
    uint32_t n = 0;
    for_each_sample(cursor, t_base, c.dt, k_end, [&](int k) {
        if (k < k_begin) return true;  // a brick's: before its owned run
        // 1. Position; clipped samples are not taken.
        const float t = t_base + (float(k) + 0.5f) * c.dt;
        const float x = r.ox + t * r.dx, y = r.oy + t * r.dy, z = r.oz + t * r.dz;
        if (!c.kept(x, y, z)) return true;
        // 2. The TF of this side; zero opacity contributes nothing (and may be skipped).
        const int s = c.side(x, y, z);
        const int e = c.map(value(c, g, x, y, z));
        ++n;
        const Rgba& raw = c.raw[s][e];
        if (!(raw.a > 0.f)) return true;
        float a = c.corr[s][e].a;
        Vec3f rgb{raw.r, raw.g, raw.b};
        // 3. Gradient: opacity modulation, then shading.
        if (c.need_gradient) {
            const Vec3f grad = gradient(c, g, x, y, z);
            if (f.gradient_opacity.enabled) {
                const float am = std::min(raw.a, 1.f) *
                                 shading::gradient_opacity(f.gradient_opacity, length(grad));
                if (!(am > 0.f)) return true;
                a = 1.f - std::pow(1.f - am, c.step);
            }
            Vec3f nrm;
            if (f.shading != ShadingModel::None && shading::normal_from_gradient(grad, view, nrm)) {
                const Vec3f pw = Vec3f{x, y, z} * c.sp;
                Vec3f l;
                float li, dist;
                light_at(c, pw, view, l, li, dist);
                if (f.shadows.enabled && li > 0.f) {
                    if (c.light)
                        li *= kernel::trilinear(float_grid(c.light, c.light_dims), x * c.inv_stride,
                                                y * c.inv_stride, z * c.inv_stride);
                    else
                        li *= transmittance(c, g, accel, x, y, z, l, dist, shadow_n);
                }
                rgb = f.shading == ShadingModel::Phong
                          ? shading::phong(f.phong, rgb, nrm, l, view, li)
                          : shading::pbr(f.pbr, rgb, nrm, l, view, li);
            }
        }
        if (f.shading == ShadingModel::None && f.shadows.enabled) {
            // Unshaded but lit: the TF colour times the light reaching the sample.
            const Vec3f pw = Vec3f{x, y, z} * c.sp;
            Vec3f l;
            float li, dist;
            light_at(c, pw, view, l, li, dist);
            if (li > 0.f) {
                if (c.light)
                    li *= kernel::trilinear(float_grid(c.light, c.light_dims), x * c.inv_stride,
                                            y * c.inv_stride, z * c.inv_stride);
                else
                    li *= transmittance(c, g, accel, x, y, z, l, dist, shadow_n);
            }
            rgb = rgb * li;
        }
        // 4. Front-to-back compositing with early termination.
        const float w = 1.f - acc.a;
        acc.r += w * rgb.x * a;
        acc.g += w * rgb.y * a;
        acc.b += w * rgb.z * a;
        acc.a += w * a;
        return !(acc.a >= c.ert);
    });
    return n;
}

// ---- The batched composite ray (the SIMD paths; composite_ray above is the reference) --------
//
// composite_ray's samples in two queues. Lattice samples are queued kLatticeBatch at a time
// across the cursor's runs (as kernel::RayStream queues them); a full queue gets its positions,
// trilinear values, LUT entries and TF-opacity mask in SIMD lanes, then, per sample in k order,
// the clip test and the side (when there are any) and - for a sample with non-zero opacity - the
// opacity chain w = 1 - A, A += w * a with
// early termination. Opacity does not depend on the gradient (gradient opacity stays on
// composite_ray), so the chain finds the terminating sample before any gradient is taken, and
// the visible samples up to it go to the second queue with their w and a. A full visible queue
// (or the ray's end) gets its gradients in SIMD lanes, then shading (in lanes on AVX2 for head
// and directional lights) and the colour chains C += w * rgb * a in k order.
//
// Every quantity is the one composite_ray computes for the same sample with the same operations
// (core/simd_shading.h for the lanes; for head and directional lights the half vector once per
// ray, by the function phong() and pbr() call per sample), each of the four accumulation chains
// sees the same terms in the same order, and the counted samples are the same, so the bits are
// the same. Work past the terminating sample (the values of the rest of its lattice batch) is
// discarded, never composited or counted; no gradient is taken for a sample that is not
// composited. Shadows and gradient opacity stay on composite_ray.
inline constexpr int kShadeBatch = 8;
// Lattice samples per evaluation: two lane batches, whose loads overlap.
inline constexpr int kLatticeBatch = 2 * kShadeBatch;

// Lane operations of one ISA path over kShadeBatch positions: lattice samples (positions,
// values, LUT entries, opacity mask), on-the-fly gradients, gradient-volume lookups, shading.
// W = 4: SSE4.1 (two calls per batch; shading per sample), W = 8: AVX2 (also the path for
// AVX-512 CPUs: a batch is 8 samples).
template <int W>
struct ShadeOps;
#if LACUNA_SIMD_X86 && defined(__SSE4_1__)
template <>
struct ShadeOps<4> {
    static constexpr bool kShades = false;             // scalar shading (phong_h, pbr_h)
    static constexpr int kLatticeLanes = kShadeBatch;  // samples() takes half a lattice batch
    static void phong(const simd::PhongLanes&, const simd::ShadeLight&, const float*, const float*,
                      const float*, float*, float*, float*, int) {}
    static void pbr(const simd::PbrLanes&, const simd::ShadeLight&, const float*, const float*,
                    const float*, float*, float*, float*) {}
    // The first n of 8 lattice samples (four at a time); returns the opacity mask.
    template <class T>
    static unsigned samples(const simd::ShadeGrid& g, const simd::ShadeRay& r, const T* d,
                            const int32_t* k, float* x, float* y, float* z, float* v, int32_t* e,
                            int n) {
        unsigned mask = unsigned(simd::samples4(g, r, d, k, x, y, z, v, e));
        if (n > 4)
            mask |= unsigned(simd::samples4(g, r, d, k + 4, x + 4, y + 4, z + 4, v + 4, e + 4))
                    << 4;
        return mask;
    }
    // Gradients of the first n positions (four at a time).
    template <class T>
    static void gradients(const simd::ShadeGrid& g, const T* d, const float* x, const float* y,
                          const float* z, float* gx, float* gy, float* gz, int n) {
        for (int l = 0; l < n; l += 4)
            simd::gradients4(g, d, x + l, y + l, z + l, gx + l, gy + l, gz + l);
    }
    static void volume_gradients(const simd::ShadeGrid& g, const float* const grad[3],
                                 const float* x, const float* y, const float* z, float* gx,
                                 float* gy, float* gz, int n) {
        for (int l = 0; l < n; l += 4)
            simd::volume_gradients4(g, grad, x + l, y + l, z + l, gx + l, gy + l, gz + l);
    }
};
#endif
#if LACUNA_SIMD_X86
template <>
struct ShadeOps<8> {
    static constexpr bool kShades = true;  // simd::phong8, simd::pbr8
    static constexpr int kLatticeLanes = kShadeBatch;
    static void phong(const simd::PhongLanes& p, const simd::ShadeLight& L, const float* gx,
                      const float* gy, const float* gz, float* r, float* g, float* b, int n) {
        simd::phong8(p, L, gx, gy, gz, r, g, b, n);
    }
    static void pbr(const simd::PbrLanes& p, const simd::ShadeLight& L, const float* gx,
                    const float* gy, const float* gz, float* r, float* g, float* b) {
        simd::pbr8(p, L, gx, gy, gz, r, g, b);
    }
    template <class T>
    static unsigned samples(const simd::ShadeGrid& g, const simd::ShadeRay& r, const T* d,
                            const int32_t* k, float* x, float* y, float* z, float* v, int32_t* e,
                            int) {
        return unsigned(simd::samples8(g, r, d, k, x, y, z, v, e));
    }
    template <class T>
    static void gradients(const simd::ShadeGrid& g, const T* d, const float* x, const float* y,
                          const float* z, float* gx, float* gy, float* gz, int) {
        simd::gradients8(g, d, x, y, z, gx, gy, gz);
    }
    static void volume_gradients(const simd::ShadeGrid& g, const float* const grad[3],
                                 const float* x, const float* y, const float* z, float* gx,
                                 float* gy, float* gz, int) {
        simd::volume_gradients8(g, grad, x, y, z, gx, gy, gz);
    }
};
// AVX-512 CPUs: ShadeOps<8>, with the whole lattice batch in sixteen lanes.
template <>
struct ShadeOps<16> : ShadeOps<8> {
    static constexpr int kLatticeLanes = kLatticeBatch;
    template <class T>
    static unsigned samples(const simd::ShadeGrid& g, const simd::ShadeRay& r, const T* d,
                            const int32_t* k, float* x, float* y, float* z, float* v, int32_t* e,
                            int) {
        return unsigned(simd::samples16(g, r, d, k, x, y, z, v, e));
    }
};
#endif

inline simd::ShadeGrid shade_grid(const Context& c, const int dims[3]) {
    return {{float(dims[0] - 1), float(dims[1] - 1), float(dims[2] - 1)},
            {dims[0] - 2, dims[1] - 2, dims[2] - 2},
            int32_t(dims[0]),
            int32_t(dims[0]) * int32_t(dims[1]),
            {c.inv_sp.x, c.inv_sp.y, c.inv_sp.z},
            c.map.offset(),
            c.map.scale(),
            float(c.map.last()),
            &c.raw[0][0].a};
}

template <class T, class Ops>
class ShadedStream {
  public:
    ShadedStream(const Context& c, const T* data, const simd::ShadeGrid& sg,
                 const kernel::IndexRay& r, Vec3f view, float t_base, kernel::Accum& acc)
        : m_c(c),
          m_data(data),
          m_sg(sg),
          m_sr{{r.ox, r.oy, r.oz}, {r.dx, r.dy, r.dz}, t_base, c.dt},
          m_view(view),
          m_acc(acc),
          m_alpha(acc.a) {
        // Head and directional lights: l, li and the half vector are those of every sample.
        const Light& L = c.f->light;
        m_fixed_light = L.kind != LightKind::Spot;
        if (m_fixed_light) {
            m_l = L.kind == LightKind::Head ? view : c.light_dir;
            m_li = L.intensity;
            m_h_ok = shading::half_vector(m_l, view, m_h);
            m_lanes_light = {{m_l.x, m_l.y, m_l.z},
                             {view.x, view.y, view.z},
                             {m_h.x, m_h.y, m_h.z},
                             m_h_ok,
                             m_li};
        }
        m_plain = !c.two_tfs && c.n_clips == 0 && !c.f->crop;
        // Whole batches shaded in lanes: a fixed light, and for PBR a half vector.
        m_lane_shading =
            Ops::kShades && c.need_gradient && m_fixed_light &&
            (c.f->shading == ShadingModel::Phong || (c.f->shading == ShadingModel::Pbr && m_h_ok));
    }

    // Queues the samples [kb, ke); false once the ray is opaque.
    bool add(int kb, int ke) {
        while (kb < ke) {
            const int take = std::min(ke - kb, kLatticeBatch - m_m);
            for (int l = 0; l < take; ++l) m_k[m_m + l] = kb + l;
            m_m += take;
            kb += take;
            if (m_m == kLatticeBatch) {
                flush_lattice();
                if (m_done) return false;
            }
        }
        return true;
    }
    // Evaluates what is still queued; the accumulator is complete afterwards.
    void finish() {
        if (m_m > 0 && !m_done) flush_lattice();
        if (m_nv > 0) flush_visible();
        m_acc.a = m_alpha;
    }
    uint32_t samples() const { return m_n; }

  private:
    // The m_m queued lattice samples (composite_ray's steps 1, 2 and the opacity chain of 4).
    void flush_lattice() {
        const Context& c = m_c;
        const int m = m_m;
        m_m = 0;
        for (int l = m; l < kLatticeBatch; ++l) m_k[l] = m_k[m - 1];  // padding
        alignas(32) float x[kLatticeBatch], y[kLatticeBatch], z[kLatticeBatch], v[kLatticeBatch];
        alignas(32) int32_t e[kLatticeBatch];  // c.map(v), in lanes
        unsigned visible =
            Ops::samples(m_sg, m_sr, m_data, m_k, x, y, z, v, e, std::min(m, kShadeBatch));
        if (Ops::kLatticeLanes < kLatticeBatch && m > kShadeBatch)
            visible |= Ops::samples(m_sg, m_sr, m_data, m_k + kShadeBatch, x + kShadeBatch,
                                    y + kShadeBatch, z + kShadeBatch, v + kShadeBatch,
                                    e + kShadeBatch, m - kShadeBatch)
                       << kShadeBatch;
        visible &= (1u << m) - 1u;
        if (m_plain) {
            // Every sample kept, one TF: the lanes' opacity mask says which are visible.
            int counted = m;
            while (visible) {
                const int l = __builtin_ctz(visible);
                visible &= visible - 1u;
                if (push(x[l], y[l], z[l], c.raw[0][e[l]], c.corr[0][e[l]].a)) {
                    counted = l + 1;
                    break;
                }
            }
            m_n += uint32_t(counted);
            return;
        }
        for (int l = 0; l < m; ++l) {
            if (!c.kept(x[l], y[l], z[l])) continue;
            ++m_n;
            const int s = c.side(x[l], y[l], z[l]);
            if (!(c.raw[s][e[l]].a > 0.f)) continue;
            if (push(x[l], y[l], z[l], c.raw[s][e[l]], c.corr[s][e[l]].a)) return;
        }
    }

    // A visible sample with step-corrected opacity a: the opacity chain, the visible queue;
    // true (and m_done) when the ray is now opaque.
    bool push(float x, float y, float z, const Rgba& raw, float a) {
        const float w = 1.f - m_alpha;
        m_alpha += w * a;
        const int j = m_nv++;
        m_vx[j] = x, m_vy[j] = y, m_vz[j] = z;
        m_vrgb[j] = &raw;
        m_vw[j] = w, m_va[j] = a;
        if (m_nv == kShadeBatch) flush_visible();
        m_done = m_alpha >= m_c.ert;
        return m_done;
    }

    // The queued visible samples: gradients, shading, the colour chains of step 4.
    void flush_visible() {
        const Context& c = m_c;
        const FeatureOptions& f = *c.f;
        const int nv = m_nv;
        m_nv = 0;
        alignas(32) float gx[kShadeBatch], gy[kShadeBatch], gz[kShadeBatch];
        if (c.need_gradient) {
            for (int j = nv; j < kShadeBatch; ++j)  // padding
                m_vx[j] = m_vx[nv - 1], m_vy[j] = m_vy[nv - 1], m_vz[j] = m_vz[nv - 1];
            if (c.grad[0])
                Ops::volume_gradients(m_sg, c.grad, m_vx, m_vy, m_vz, gx, gy, gz, nv);
            else
                Ops::gradients(m_sg, m_data, m_vx, m_vy, m_vz, gx, gy, gz, nv);
        }
        kernel::Accum acc = m_acc;
        if (m_lane_shading) {
            alignas(32) float r[kShadeBatch], g[kShadeBatch], b[kShadeBatch];
            for (int j = 0; j < kShadeBatch; ++j) {
                const Rgba& raw = *m_vrgb[std::min(j, nv - 1)];
                r[j] = raw.r, g[j] = raw.g, b[j] = raw.b;
            }
            if (f.shading == ShadingModel::Phong)
                Ops::phong({f.phong.ambient, f.phong.diffuse, f.phong.specular, f.phong.power},
                           m_lanes_light, gx, gy, gz, r, g, b, nv);
            else
                Ops::pbr({f.pbr.roughness, f.pbr.metallic, f.pbr.ambient}, m_lanes_light, gx, gy,
                         gz, r, g, b);
            for (int j = 0; j < nv; ++j) {
                const float w = m_vw[j], a = m_va[j];
                acc.r += w * r[j] * a;
                acc.g += w * g[j] * a;
                acc.b += w * b[j] * a;
            }
            m_acc = acc;
            return;
        }
        for (int j = 0; j < nv; ++j) {
            const Rgba& raw = *m_vrgb[j];
            Vec3f rgb{raw.r, raw.g, raw.b};
            Vec3f nrm;
            if (f.shading != ShadingModel::None &&
                shading::normal_from_gradient({gx[j], gy[j], gz[j]}, m_view, nrm)) {
                if (m_fixed_light) {
                    rgb = f.shading == ShadingModel::Phong
                              ? shading::phong_h(f.phong, rgb, nrm, m_l, m_h, m_h_ok, m_li)
                              : shading::pbr_h(f.pbr, rgb, nrm, m_l, m_view, m_h_ok ? m_h : nrm,
                                               m_li);
                } else {
                    const Vec3f pw = Vec3f{m_vx[j], m_vy[j], m_vz[j]} * c.sp;
                    Vec3f lt;
                    float li, dist;
                    light_at(c, pw, m_view, lt, li, dist);
                    rgb = f.shading == ShadingModel::Phong
                              ? shading::phong(f.phong, rgb, nrm, lt, m_view, li)
                              : shading::pbr(f.pbr, rgb, nrm, lt, m_view, li);
                }
            }
            const float w = m_vw[j], a = m_va[j];
            acc.r += w * rgb.x * a;
            acc.g += w * rgb.y * a;
            acc.b += w * rgb.z * a;
        }
        m_acc = acc;
    }

    const Context& m_c;
    const T* m_data;
    const simd::ShadeGrid& m_sg;
    simd::ShadeRay m_sr;
    Vec3f m_view;
    kernel::Accum& m_acc;  // r, g, b; a is m_alpha until finish()
    float m_alpha;
    bool m_fixed_light = false, m_h_ok = false, m_done = false, m_lane_shading = false;
    bool m_plain = false;  // no clip plane, crop box or second TF
    Vec3f m_l{0, 0, 1}, m_h{0, 0, 1};
    simd::ShadeLight m_lanes_light{};
    float m_li = 0.f;
    alignas(32) int32_t m_k[kLatticeBatch];  // lattice queue
    int m_m = 0;
    alignas(32) float m_vx[kShadeBatch], m_vy[kShadeBatch], m_vz[kShadeBatch];  // visible queue
    float m_vw[kShadeBatch], m_va[kShadeBatch];
    const Rgba* m_vrgb[kShadeBatch];
    int m_nv = 0;
    uint32_t m_n = 0;
};

// MIP / MinIP: track the extreme LUT entry (src/accel/entry_window.h); `lo`/`hi` is the window
// of entries that can still change it, read by an EntryWindowView cursor.
template <class T, class Index, class Cursor>
inline uint32_t extreme_ray(const Context& c, const kernel::Grid<T, Index>& g, Cursor& cursor,
                            const kernel::IndexRay& r, float t_base, int k_end, bool maximum,
                            int& lo, int& hi, kernel::Accum& acc) {
    const int last = c.map.last();
    int cur = maximum ? -1 : INT_MAX, cur_side = 0;
    lo = 0;
    hi = last;
    uint32_t n = 0;
    for_each_sample(cursor, t_base, c.dt, k_end, [&](int k) {
        const float t = t_base + (float(k) + 0.5f) * c.dt;
        const float x = r.ox + t * r.dx, y = r.oy + t * r.dy, z = r.oz + t * r.dz;
        if (!c.kept(x, y, z)) return true;
        const int e = c.map(value(c, g, x, y, z));
        ++n;
        if (maximum ? e > cur : e < cur) {
            cur = e;
            cur_side = c.side(x, y, z);
            if (maximum)
                lo = cur + 1;
            else
                hi = cur - 1;
        }
        return maximum ? cur < last : cur > 0;  // nothing can beat the end of the table
    });
    if (cur >= 0 && cur <= last) {
        const Rgba& raw = c.raw[cur_side][cur];
        const float a = std::clamp(raw.a, 0.f, 1.f);
        acc = {raw.r * a, raw.g * a, raw.b * a, a};
    }
    return n;
}

// Average: the TF at the mean value of the samples with non-zero TF opacity (on their side).
template <class T, class Index, class Cursor>
inline uint32_t average_ray(const Context& c, const kernel::Grid<T, Index>& g, Cursor& cursor,
                            const kernel::IndexRay& r, float t_base, int k_end,
                            kernel::Accum& acc) {
    float sum = 0.f;
    uint32_t count = 0, n = 0;
    for_each_sample(cursor, t_base, c.dt, k_end, [&](int k) {
        const float t = t_base + (float(k) + 0.5f) * c.dt;
        const float x = r.ox + t * r.dx, y = r.oy + t * r.dy, z = r.oz + t * r.dz;
        if (!c.kept(x, y, z)) return true;
        const float v = value(c, g, x, y, z);
        ++n;
        if (c.raw[c.side(x, y, z)][c.map(v)].a > 0.f) {
            sum += v;
            ++count;
        }
        return true;
    });
    if (count) {
        const Rgba& raw = c.raw[0][c.map(sum / float(count))];
        const float a = std::clamp(raw.a, 0.f, 1.f);
        acc = {raw.r * a, raw.g * a, raw.b * a, a};
    }
    return n;
}

// One tile of the feature path: per pixel, the ray, its (jittered) lattice, the cursor of the
// blend mode, and the pixel.
//
// Ops: ShadeOps<W> of the active SIMD path, run for composite rays without shadows or gradient
// opacity through ShadedStream (`sg` is then the grid's int32 geometry); void: composite_ray,
// the reference.
template <class Ops, class T, class Index, class S>
void render_tile(const Context& c, const S& accel, const kernel::Grid<T, Index>& g,
                 const simd::ShadeGrid& sg, const Camera& cam, const RenderOptions& opt, int x0,
                 int y0, int x1, int y1, RenderResult& out, Counts& counts) {
    const FeatureOptions& f = *c.f;
    const float hi[3] = {g.hi_x, g.hi_y, g.hi_z};
    const float chunk = kCursorChunk * c.dt;
    // The eight-lane paths set rays up eight pixels at a time (simd::setup_rays8: the operations
    // of Camera::generate, index_ray and intersect_box, lane by lane).
    constexpr bool kBatchSetup = [] {
        if constexpr (std::is_void_v<Ops>)
            return false;
        else
            return Ops::kShades;
    }();
    [[maybe_unused]] const simd::CameraView cv = camera_view(cam);
    [[maybe_unused]] const float isp[3] = {c.inv_sp.x, c.inv_sp.y, c.inv_sp.z};
    [[maybe_unused]] simd::RayBatch8 rb;
    for (int py = y0; py < y1; ++py) {
        for (int px = x0; px < x1; ++px) {
            kernel::IndexRay r;
            Vec3f view;
            float t_near, t_far;
            bool hit;
            if constexpr (kBatchSetup) {
                const int i = (px - x0) & 7;
                if (i == 0) {
                    alignas(32) float bx[8], by[8];
                    for (int q = 0; q < 8; ++q)
                        bx[q] = float(std::min(px + q, x1 - 1)), by[q] = float(py);
                    simd::setup_rays8(cv, bx, by, isp, hi, rb);
                }
                r = {rb.ox[i], rb.oy[i], rb.oz[i], rb.dx[i], rb.dy[i], rb.dz[i]};
                view = -Vec3f{rb.wx[i], rb.wy[i], rb.wz[i]};
                t_near = rb.t_near[i], t_far = rb.t_far[i];
                hit = rb.hit[i] != 0;
            } else {
                const Ray wr = cam.generate(float(px), float(py));
                r = index_ray(wr, c.inv_sp);
                view = -wr.dir;
                hit = kernel::intersect_box(r, hi, t_near, t_far);
            }
            kernel::Accum acc;
            uint32_t n = 0;
            if (hit) {
                ++counts.rays;
                const float j = f.jitter ? jitter(uint32_t(px), uint32_t(py), f.jitter_seed) : 0.5f;
                const float t_base = t_near + (j - 0.5f) * c.dt;
                int k_begin = 0, k_end = lattice_end(t_base, t_far, c.dt);
                IndexRay cr = r;
                float c0 = t_near, c1 = t_far;
                if (c.brick) {
                    // A brick's owned run of the lattice; its structure walks the ray in brick
                    // index space over the run and a sample of margin each side, the runs are
                    // clipped to it (render_tile_brick's steps, ray_marcher.cpp).
                    owned_run(r, t_base, c.dt, k_end, c.brick->lo, c.brick->hi, k_begin, k_end);
                    cr.ox -= float(c.brick->offset.x), cr.oy -= float(c.brick->offset.y);
                    cr.oz -= float(c.brick->offset.z);
                    c0 = std::max(t_near, t_base + (float(k_begin) - 0.5f) * c.dt);
                    c1 = std::min(t_far, t_base + (float(k_end) + 0.5f) * c.dt);
                }
                if (k_begin >= k_end) {
                    // no owned sample (a brick's ray)
                } else if (f.blend == BlendMode::Mip || f.blend == BlendMode::MinIp) {
                    const bool maximum = f.blend == BlendMode::Mip;
                    int lo = 0, hi_e = c.map.last();
                    bool done = false;
                    if constexpr (HasEntryWindow<S>) {
                        if (same_map(accel.value_map(), c.map)) {
                            const EntryWindowView<S> view_s{&accel, &lo, &hi_e};
                            RegionCursor<EntryWindowView<S>> cursor(view_s, cr, t_near, t_far, c.dt,
                                                                    chunk);
                            n = extreme_ray(c, g, cursor, r, t_base, k_end, maximum, lo, hi_e, acc);
                            done = true;
                        }
                    }
                    if (!done) {
                        static const NoAccel kNone;
                        NoAccel::Cursor cursor(kNone, cr, t_near, t_far);
                        n = extreme_ray(c, g, cursor, r, t_base, k_end, maximum, lo, hi_e, acc);
                    }
                } else {
                    typename S::Cursor cursor(
                        accel, cr, c0, c1, c.dt,
                        f.blend == BlendMode::Composite && c.ert < 1.f ? chunk : 0.f);
                    if (f.blend == BlendMode::Average) {
                        n = average_ray(c, g, cursor, r, t_base, k_end, acc);
                    } else if constexpr (!std::is_void_v<Ops>) {
                        ShadedStream<T, Ops> stream(c, g.data, sg, r, view, t_base, acc);
                        for_each_lattice_run(cursor, t_base, c.dt, k_end, [&](int kb, int ke) {
                            kb = std::max(kb, k_begin);
                            return ke > kb ? stream.add(kb, ke) : true;
                        });
                        stream.finish();
                        n = stream.samples();
                    } else {
                        n = composite_ray(c, g, accel, cursor, r, view, t_base, k_end, acc,
                                          counts.shadow, k_begin);
                    }
                }
            }
            counts.samples += n;
            write_pixel(out, opt, px, py, acc, n);
        }
    }
}

// ---- Shaded rays in lanes (AVX2 and AVX-512 CPUs): simd::march_shaded_lanes8 ----------------
//
// For Phong composite rays with a head or directional light, one TF and no clipping
// (lanes_shade() says when): the lane scheduler (render/lane_scheduler.h) with this policy.
// A ray's record (simd::ShadeRecords) holds its colour and its fixed light; when the ray is done
// its pixel is written at once if none of its samples still waits in the shading queue, else as
// soon as the queue has shaded them (poll, at every refill) or at the tile's end (drain).
inline bool lanes_shade(const Context& c) {
    const FeatureOptions& f = *c.f;
    return f.shading == ShadingModel::Phong && f.light.kind != LightKind::Spot && !c.two_tfs &&
           c.n_clips == 0 && !f.crop && !c.nearest && c.ert > 0.f;
}

#if LACUNA_SIMD_X86
template <class T>
class ShadedLanesPolicy {
  public:
    ShadedLanesPolicy(const Context& c, const simd::ShadeFrame& sf, const T* data,
                      RenderResult& out, const RenderOptions& opt)
        : m_c(c), m_sf(sf), m_data(data), m_out(out), m_opt(opt), m_empty(empty_pixel_word(opt)) {
        for (int i = 0; i < simd::kShadeRecords; ++i) m_free[i] = simd::kShadeRecords - 1 - i;
        m_nfree = simd::kShadeRecords;
    }
    const int32_t* lane_records() const { return m_rec; }
    simd::ShadeQueue& queue() { return m_q; }
    simd::ShadeRecords& records() { return m_R; }

    // render_tile's lattice: t_near + (j - 0.5) * dt, j the pixel's jitter or 0.5.
    float t_base(int x, int y, float t_near) const {
        const FeatureOptions& f = *m_c.f;
        const float j = f.jitter ? jitter(uint32_t(x), uint32_t(y), f.jitter_seed) : 0.5f;
        return t_near + (j - 0.5f) * m_c.dt;
    }
    // ShadedStream's per-ray light: l (the view for a head light), and the half vector, made
    // for eight rays at a time as the scheduler sets them up (rays8; `slot` is the ray's).
    void rays8(const simd::RayBatch8& rb) {
        const float l[3] = {m_c.light_dir.x, m_c.light_dir.y, m_c.light_dir.z};
        simd::half_vectors8(rb, m_c.f->light.kind == LightKind::Head, l, m_bh, m_bok);
    }
    void begin(int lane, int x, int y, Vec3f dir, int slot) {
        const int i = m_free[--m_nfree];
        m_rec[lane] = i;
        m_R.r[i] = m_R.g[i] = m_R.b[i] = 0.f;
        m_R.pending[i] = 0;
        m_R.h_ok[i] = m_bok[slot];
        m_R.v[0][i] = -dir.x, m_R.v[1][i] = -dir.y, m_R.v[2][i] = -dir.z;
        m_R.h[0][i] = m_bh[0][slot], m_R.h[1][i] = m_bh[1][slot], m_R.h[2][i] = m_bh[2][slot];
        m_x[i] = x, m_y[i] = y;
    }
    void finish(int lane, int, int, const simd::Lanes& L) {
        const int i = m_rec[lane];
        m_a[i] = L.a[lane];
        m_n[i] = uint32_t(L.n[lane]);
        if (m_R.pending[i] == 0)
            write(i);
        else
            m_deferred[m_ndeferred++] = i;
    }
    void empty(int x, int y) { write_empty_pixel(m_out, m_opt, m_empty, x, y); }
    void poll() {
        int kept = 0;
        for (int d = 0; d < m_ndeferred; ++d) {
            const int i = m_deferred[d];
            if (m_R.pending[i] == 0)
                write(i);
            else
                m_deferred[kept++] = i;
        }
        m_ndeferred = kept;
    }
    void drain() {
        while (m_q.n > 0) simd::shade_queue8(m_sf, m_data, m_q, m_R);
        poll();
    }

  private:
    void write(int i) {
        write_pixel(m_out, m_opt, m_x[i], m_y[i],
                    kernel::Accum{m_R.r[i], m_R.g[i], m_R.b[i], m_a[i]}, m_n[i]);
        m_free[m_nfree++] = i;
    }
    const Context& m_c;
    const simd::ShadeFrame& m_sf;
    const T* m_data;
    RenderResult& m_out;
    const RenderOptions& m_opt;
    const uint32_t m_empty;
    alignas(32) float m_bh[3][8] = {};  // the last ray batch's half vectors (rays8)
    alignas(32) int32_t m_bok[8] = {};
    simd::ShadeRecords m_R{};
    simd::ShadeQueue m_q{};
    alignas(64) int32_t m_rec[simd::kMaxLanes] = {};
    int m_free[simd::kShadeRecords], m_nfree = 0;
    int m_deferred[simd::kShadeRecords], m_ndeferred = 0;
    int m_x[simd::kShadeRecords] = {}, m_y[simd::kShadeRecords] = {};
    float m_a[simd::kShadeRecords] = {};
    uint32_t m_n[simd::kShadeRecords] = {};
};

// One tile of shaded rays in lanes, leaping through the refined `grid` (leap_map() set);
// pixels outside `cover` are written empty (render/screen_cover.h).
// `corr_z`: the step-corrected LUT with a zero entry appended.
template <class T>
void render_tile_shaded_lanes(const Context& c, const BrickGrid& grid, const Volume& vol,
                              const T* data, const simd::ShadeFrame& sf,
                              const std::vector<Rgba>& corr_z, const Camera& cam,
                              const RenderOptions& opt, int x0, int y0, int x1, int y1,
                              RenderResult& out, Counts& counts, const ScreenCover* cover) {
    const kernel::Grid<T, int32_t> g = kernel::make_grid<int32_t>(data, vol.dims());
    simd::LaneGrid lg = lane_grid(g, c.dt, c.map, corr_z.size(), c.ert);
    set_leap(lg, grid);
    ShadedLanesPolicy<T> policy(c, sf, data, out, opt);
    const float* lut = &corr_z[0].r;
    // Every ray one run: the lanes leap (core/simd_lanes.h); on AVX-512 CPUs two groups of
    // sixteen lanes.
    static const NoAccel kWholeRay;
    if (simd::active_isa() == simd::Isa::Avx512) {
        schedule_tile_lanes<32>(
            kWholeRay, vol, cam, c.dt, 0.f, c.ert, x0, y0, x1, y1, policy, counts.samples,
            counts.rays,
            [&](simd::Lanes& L, auto& refill) {
                simd::march_shaded_lanes16<T, std::remove_reference_t<decltype(refill)>>(
                    L, lg, data, lut, sf, policy.queue(), policy.records(), policy.lane_records(),
                    refill);
            },
            cover);
        return;
    }
    schedule_tile_lanes<8>(
        kWholeRay, vol, cam, c.dt, 0.f, c.ert, x0, y0, x1, y1, policy, counts.samples, counts.rays,
        [&](simd::Lanes& L, auto& refill) {
            simd::march_shaded_lanes8<T, std::remove_reference_t<decltype(refill)>, true>(
                L, lg, data, lut, sf, policy.queue(), policy.records(), policy.lane_records(),
                refill);
        },
        cover);
}
#endif

}  // namespace lacuna::feature
