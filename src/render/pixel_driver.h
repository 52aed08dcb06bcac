// What every per-pixel ray loop of the renderers shares (the ray marcher, the feature path and
// the segment renderer): the pixel's ray in index space, the cursor's stretches rounded outward
// to the reference lattice, and the pixel write-out. One copy, so the three paths cannot drift
// apart in the arithmetic that makes them byte-identical to each other.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "accel/cursor.h"
#include "core/simd_lanes.h"
#include "lacuna/camera.h"
#include "lacuna/renderer.h"
#include "lacuna/volume.h"
#include "render/ray_march_kernel.h"

namespace lacuna {

// With early ray termination the cursor hands out occupied stretches of at most about this many
// samples, so a ray that turns opaque early does not walk the structure to its far end. (MIP
// narrows its skipping window at each stretch, so it wants them short.)
constexpr float kCursorChunk = 16.f;
// The same for the unshaded lane marcher, where each stretch is a scheduler event: 32 measured
// ~10% faster than 16 on the ch2 heads with the grid (interleaved runs), 64 no better than 32.
constexpr float kLaneChunk = 32.f;

// World -> index space factor per axis (1 / spacing), and the sample distance of the lattice
// (`step` smallest voxel spacings, world units).
inline Vec3f inverse_spacing(const Volume& vol) {
    return {float(1.0 / vol.spacing.x), float(1.0 / vol.spacing.y), float(1.0 / vol.spacing.z)};
}
inline float sample_distance(const Volume& vol, float step) {
    return step * float(std::min({vol.spacing.x, vol.spacing.y, vol.spacing.z}));
}

// Pixel (x, y)'s camera ray moved into index space (t stays in world units).
inline kernel::IndexRay index_ray(const Ray& wr, Vec3f inv_sp) {
    const Vec3f o = wr.origin * inv_sp, dir = wr.dir * inv_sp;
    return kernel::IndexRay{o.x, o.y, o.z, dir.x, dir.y, dir.z};
}

// The camera as the batched ray set-up reads it (core/simd_lanes.h setup_rays8).
inline simd::CameraView camera_view(const Camera& c) {
    const Vec3f e = c.eye(), f = c.forward(), r = c.right(), u = c.up();
    return simd::CameraView{{e.x, e.y, e.z},   {f.x, f.y, f.z},
                            {r.x, r.y, r.z},   {u.x, u.y, u.z},
                            c.half_height(),   float(c.width()),
                            float(c.height()), c.projection() == Projection::Orthographic};
}

// Number of lattice samples t_k = t_base + (k + 0.5)*dt with t_k < t_far.
inline int lattice_end(float t_base, float t_far, float dt) {
    return std::max(int(std::ceil((t_far - t_base) / dt - 0.5f)), 0);
}

// The runs [kb, ke) of lattice samples t_k = t_base + (k + 0.5)*dt, k < k_end, that lie in the
// cursor's segments, rounded outward (a few extra reference samples may be taken, a visible one
// is never missed), in order and disjoint: a pull source, one run per next(). The rounding keeps
// a whole sample of margin on either side (floor(u - 0.5) and floor(u - 0.5) + 2 for the exact
// u = (t - t_base) / dt), so u may be off by ulps: it is (t - t_base) * (1 / dt), a multiply
// where a division sat on the scheduler's critical path.
// One segment's run, from lattice index k on: [b, e), empty if e <= b.
inline void lattice_run(const Segment& seg, float t_base, float inv_dt, int k, int k_end, int& b,
                        int& e) {
    b = std::max(k, int(std::floor((seg.t0 - t_base) * inv_dt - 0.5f)));
    e = std::min(k_end, int(std::floor((seg.t1 - t_base) * inv_dt - 0.5f)) + 2);
}
template <class Cursor>
class LatticeRuns {
  public:
    LatticeRuns(Cursor& cursor, float t_base, float dt, int k_end)
        : m_cursor(cursor), m_t_base(t_base), m_inv_dt(1.f / dt), m_end(k_end) {}
    bool next(int& kb, int& ke) {
        Segment seg;
        while (m_k < m_end && m_cursor.next(seg)) {
            int b, e;
            lattice_run(seg, m_t_base, m_inv_dt, m_k, m_end, b, e);
            m_k = std::max(m_k, e);
            if (e > b) {
                kb = b;
                ke = e;
                return true;
            }
        }
        return false;
    }

  private:
    Cursor& m_cursor;
    float m_t_base, m_inv_dt;
    int m_end, m_k = 0;
};

// Calls fn(kb, ke) for those runs until fn returns false.
template <class Cursor, class Fn>
inline void for_each_lattice_run(Cursor& cursor, float t_base, float dt, int k_end, Fn&& fn) {
    LatticeRuns<Cursor> runs(cursor, t_base, dt, k_end);
    int kb, ke;
    while (runs.next(kb, ke))
        if (!fn(kb, ke)) return;
}

// The same, one sample at a time: fn(k) returns false to stop.
template <class Cursor, class Fn>
inline void for_each_sample(Cursor& cursor, float t_base, float dt, int k_end, Fn&& fn) {
    for_each_lattice_run(cursor, t_base, dt, k_end, [&](int kb, int ke) {
        for (int j = kb; j < ke; ++j)
            if (!fn(j)) return false;
        return true;
    });
}

// The one pixel write-out of every renderer: the background composited behind the premultiplied
// `acc` (c + (1 - a) * background per channel), each channel clamped to [0, 1], times 255,
// rounded half away from zero (std::lround; NaN becomes 0), alpha 255; the RGBA8 bytes as one
// word in memory order. The ray marcher's paths write it through write_pixel below, the slicer
// (src/slice/slice_renderer.cpp) its framebuffer through it directly.
uint32_t pixel_word(const Vec3f& background, const kernel::Accum& acc);

// Composites the background behind `acc` and writes pixel (x, y) of `out`: RGBA8, and the float
// RGBA and the sample count when the options ask for them. Out of line on purpose: inlined into
// the ray marcher's tile loop it changed the compiler's inlining of the batch kernel and cost
// ~15% of the sample rate; one call per pixel costs nothing measurable.
void write_pixel(RenderResult& out, const RenderOptions& opt, int x, int y,
                 const kernel::Accum& acc, uint32_t samples);

// The pixel of a ray without samples, write_pixel(out, opt, x, y, Accum{}, 0), with its word
// computed once per tile (empty_pixel_word(opt)): on a head half the pixels miss the volume.
uint32_t empty_pixel_word(const RenderOptions& opt);
inline void write_empty_pixel(RenderResult& out, const RenderOptions& opt, uint32_t word, int x,
                              int y) {
    std::memcpy(out.image.pixel(x, y), &word, 4);
    if (opt.keep_float || opt.count_samples) write_pixel(out, opt, x, y, kernel::Accum{}, 0);
}

}  // namespace lacuna
