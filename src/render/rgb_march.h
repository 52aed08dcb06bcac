// Ray marching an RGB/RGBA volume (lacuna/rgb.h): the colour of a sample is the
// interpolated colour of the data, its opacity the TF's opacity at the opacity scalar.
//
// Exactness argument. The volume's scalar voxels *are* the opacity scalar (luminance or one
// channel, src/io/rgb_volume.h), and every skipping structure is built on them as on any scalar
// volume; a sample is composited with opacity lut[map(scalar sample)].a, the same entry the
// scalar reference reads. So a sample a structure skips has opacity exactly 0. Such a sample
// is not composited here at all (its colour is irrelevant: it adds w * 0), and each kept
// sample's position, scalar and colour are functions of its lattice index k alone, computed by
// the same code whatever the runs. Every structure therefore composites the same samples in the
// same order with the same bits: images byte-identical to `--accel none`.
//
// Only this one-ray-at-a-time kernel renders colour from data: the SIMD lane paths and the
// feature path (shading, clipping, blend modes) take a TF colour, so the ray marcher routes RGB
// volumes here (render_tile_on in ray_marcher.cpp) and refuses features for them
// (check_rgb_options). Slower than the lanes, never different.
#pragma once
#include <atomic>
#include <cstdint>
#include <vector>

#include "lacuna/error.h"
#include "lacuna/renderer.h"
#include "lacuna/rgb.h"
#include "lacuna/volume.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"

namespace lacuna {

// Throws FrameError for what an RGB volume cannot render with yet.
inline void check_rgb_options(const Volume& vol, const RenderOptions& opt) {
    if (!rgb_colours(vol)) return;
    if (opt.features.any())
        throw FrameError("features",
                         "no features (shading, clipping, crop, blend modes, jitter) "
                         "for an RGB volume: its colour comes from the data (a "
                         "shaded preset needs --shading none)");
    if (opt.brick) throw FrameError("brick", "an RGB volume is not rendered distributed");
}

namespace kernel {

// The colour (0..1 per channel) at index-space point (x, y, z) of the 4-byte voxels `rgba`
// (x fastest, strides of `g`), clamped into the box and in the cell trilinear() uses, with
// trilinear()'s operations per channel; nearest: nearest()'s voxel.
template <bool kNearest, class T, class Index>
inline void sample_rgb(const Grid<T, Index>& g, const uint8_t* rgba, float x, float y, float z,
                       float out[3]) {
    x = std::clamp(x, 0.f, g.hi_x);
    y = std::clamp(y, 0.f, g.hi_y);
    z = std::clamp(z, 0.f, g.hi_z);
    constexpr float kInv255 = 1.f / 255.f;
    if constexpr (kNearest) {
        const uint8_t* p = rgba + 4 * (ptrdiff_t(int(z + 0.5f)) * g.sz +
                                       ptrdiff_t(int(y + 0.5f)) * g.sy + int(x + 0.5f));
        for (int c = 0; c < 3; ++c) out[c] = float(p[c]) * kInv255;
        return;
    }
    const int i = std::min(int(x), g.cell_x), j = std::min(int(y), g.cell_y),
              k = std::min(int(z), g.cell_z);
    const float fx = x - float(i), fy = y - float(j), fz = z - float(k);
    const uint8_t* p = rgba + 4 * (ptrdiff_t(k) * g.sz + ptrdiff_t(j) * g.sy + i);
    const ptrdiff_t sy = 4 * g.sy, sz = 4 * g.sz;
    for (int c = 0; c < 3; ++c) {
        const float c000 = float(p[c]), c100 = float(p[4 + c]);
        const float c010 = float(p[sy + c]), c110 = float(p[sy + 4 + c]);
        const float c001 = float(p[sz + c]), c101 = float(p[sz + 4 + c]);
        const float c011 = float(p[sz + sy + c]), c111 = float(p[sz + sy + 4 + c]);
        const float c00 = c000 + fx * (c100 - c000), c10 = c010 + fx * (c110 - c010);
        const float c01 = c001 + fx * (c101 - c001), c11 = c011 + fx * (c111 - c011);
        const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
        out[c] = (c0 + fz * (c1 - c0)) * kInv255;
    }
}

// The sample stream of one ray over an RGB volume: RayStream's interface (add runs, finish),
// one sample at a time.
template <class T, class Index, bool kNearest>
class RgbRayStream {
  public:
    RgbRayStream(const Grid<T, Index>& g, const uint8_t* rgba, const IndexRay& r, float t_base,
                 float dt, const Rgba* lut, ValueToLut map, float ert, Accum& acc)
        : m_g(g),
          m_rgba(rgba),
          m_r(r),
          m_t_base(t_base),
          m_dt(dt),
          m_lut(lut),
          m_map(map),
          m_ert(ert),
          m_acc(acc) {}

    // Composites the samples [kb, ke); false once the ray is opaque.
    bool add(int kb, int ke) {
        for (int k = kb; k < ke && !m_done; ++k) {
            // 1. The lattice position t_k (the reference's arithmetic) and its opacity.
            const float t = m_t_base + (float(k) + 0.5f) * m_dt;
            const float x = m_r.ox + t * m_r.dx, y = m_r.oy + t * m_r.dy, z = m_r.oz + t * m_r.dz;
            const float a = m_lut[m_map(sample<kNearest>(m_g, x, y, z))].a;
            ++m_n;
            if (a == 0.f) continue;  // adds nothing: the samples skipping removes (see above)
            // 2. Its colour from the data, premultiplied by the TF's (step-corrected) opacity.
            float rgb[3];
            sample_rgb<kNearest>(m_g, m_rgba, x, y, z, rgb);
            // 3. Front to back, early termination at ert.
            const float w = 1.f - m_acc.a;
            m_acc.r += w * (rgb[0] * a);
            m_acc.g += w * (rgb[1] * a);
            m_acc.b += w * (rgb[2] * a);
            m_acc.a += w * a;
            m_done = m_acc.a >= m_ert;
        }
        return !m_done;
    }
    void finish() {}
    uint32_t samples() const { return m_n; }

  private:
    const Grid<T, Index>& m_g;
    const uint8_t* m_rgba;
    IndexRay m_r;
    float m_t_base, m_dt;
    const Rgba* m_lut;
    ValueToLut m_map;
    float m_ert;
    Accum& m_acc;
    uint32_t m_n = 0;
    bool m_done = false;
};

}  // namespace kernel

// One tile of an RGB volume: render_tile's loop (ray_marcher.cpp) with RgbRayStream.
template <class T, bool kNearest, class S>
void render_rgb_tile(const S& accel, const Volume& vol, const T* data, const Camera& cam,
                     const RenderOptions& opt, const std::vector<Rgba>& lut, ValueToLut map, int x0,
                     int y0, int x1, int y1, RenderResult& out, std::atomic<uint64_t>& samples,
                     std::atomic<uint64_t>& rays) {
    const kernel::Grid<T, int64_t> g = kernel::make_grid<int64_t>(data, vol.dims());
    const uint8_t* rgba = rgb_colours(vol)->rgba.data();
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
                typename S::Cursor cursor(accel, r, t_near, t_far, dt,
                                          opt.ert < 1.f ? kCursorChunk * dt : 0.f);
                kernel::RgbRayStream<T, int64_t, kNearest> stream(g, rgba, r, t_near, dt,
                                                                  lut.data(), map, opt.ert, acc);
                for_each_lattice_run(cursor, t_near, dt, lattice_end(t_near, t_far, dt),
                                     [&](int kb, int ke) { return stream.add(kb, ke); });
                n = stream.samples();
            }
            tile_samples += n;
            write_pixel(out, opt, x, y, acc, n);
        }
    }
    samples += tile_samples;
    rays += tile_rays;
}

}  // namespace lacuna
