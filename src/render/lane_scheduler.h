// The lane scheduler: one tile of rays through a lane kernel (core/simd_lanes.h march_lanes*,
// core/simd_shading.h march_shaded_lanes8), W rays at a time, one ray per lane.
//
// Why a scheduler. A lane kernel marches W rays in lockstep, each in its own sample order, so
// the bits are those of the one-ray reference. What keeps its lanes full is here: a lane whose
// run ends pulls its ray's next run from the ray's cursor; a lane whose ray is done (no runs
// left, or opaque) hands its ray to the policy (which writes the pixel) and takes the tile's
// next ray. The kernel calls `refill` with the mask of the lanes that wait.
//
// What differs between the kernels is the Policy:
//   float t_base(int x, int y, float t_near)   the ray's lattice origin (jitter)
//   void begin(int lane, int x, int y, Vec3f world_dir, int slot)   a ray enters a lane (slot:
//       its index in the last ray batch given to rays8, when the policy has one)
//   void rays8(const simd::RayBatch8&)   optional: each batch of eight rays as it is set up
//   void finish(int lane, int x, int y, const simd::Lanes&)   its ray is done: pixel or deferral
//   void empty(int x, int y)   a pixel whose ray has no run at all
//   void poll()   at every refill (deferred pixels whose shading has completed)
//   void drain()   after the kernel returned: everything still deferred
#pragma once
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <optional>
#include <type_traits>

#include "accel/brick_grid.h"
#include "accel/no_accel.h"
#include "core/simd_lanes.h"
#include "lacuna/camera.h"
#include "lacuna/renderer.h"
#include "lacuna/volume.h"
#include "render/pixel_driver.h"
#include "render/screen_cover.h"

namespace lacuna {

// Tiles up to this many pixels go through the lane scheduler (the ray order table is on the
// stack).
constexpr int kMaxTilePixels = 64 * 64;

// The lane kernels' view of the grid and the TF (LaneGrid) for a LUT with the zero entry last.
template <class T>
inline simd::LaneGrid lane_grid(const kernel::Grid<T, int32_t>& g, float dt, ValueToLut map,
                                size_t lut_entries, float ert) {
    return simd::LaneGrid{dt,
                          {g.hi_x, g.hi_y, g.hi_z},
                          {g.cell_x, g.cell_y, g.cell_z},
                          int32_t(g.sy),
                          int32_t(g.sz),
                          map.offset(),
                          map.scale(),
                          float(map.last()),
                          int32_t(lut_entries - 1),  // the zero entry idle lanes composite
                          ert};
}

// Leaping kernels (kLeap): the refined grid's leap map and its strides.
inline void set_leap(simd::LaneGrid& lg, const BrickGrid& grid) {
    const int* n = grid.leap_dims();
    lg.leap = grid.leap_map();
    lg.leap_sy = n[0];
    lg.leap_sz = n[0] * n[1];
    lg.leap_octant = int32_t(grid.leap_octant_stride());
}

// Runs `march(lanes, refill)` over the tile's rays; dt, chunk and ert as the kernel's. Pixels
// outside `cover` (when given) are written empty without marching.
template <int W, class S, class Policy, class March>
void schedule_tile_lanes(const S& accel, const Volume& vol, const Camera& cam, float dt,
                         float chunk, float ert, int x0, int y0, int x1, int y1, Policy& policy,
                         uint64_t& tile_samples, uint64_t& tile_rays, March&& march,
                         const ScreenCover* cover = nullptr) {
    using Cursor = typename S::Cursor;
    // Whole rays (NoAccel: one segment [t_near, t_far], the leaping kernels' case): the run is
    // LatticeRuns' first, computed here without a cursor, and there is never a second.
    constexpr bool kWhole = std::is_same_v<S, NoAccel>;
    const float inv_dt = 1.f / dt;
    const Vec3f inv_sp = inverse_spacing(vol);
    const Vec3i dims = vol.dims();
    const float hi[3] = {float(dims.x - 1), float(dims.y - 1), float(dims.z - 1)};
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
    // Rays are set up eight at a time (AVX2, on the 8- and 16-lane paths) in pixel order.
    constexpr bool kBatchSetup = W >= 8;
    const simd::CameraView cv = camera_view(cam);
    const float isp[3] = {inv_sp.x, inv_sp.y, inv_sp.z};
    simd::RayBatch8 rb;
    int rb_base = -8;
    auto ray_of = [&](int q, kernel::IndexRay& r, Vec3f& dir, float& t_near, float& t_far) {
        if constexpr (kBatchSetup) {
            if (q >= rb_base + 8) {
                rb_base = q;
                alignas(32) float px[8], py[8];
                for (int i = 0; i < 8; ++i) {
                    const int j = std::min(q + i, npix - 1);
                    px[i] = float(order[j][0]), py[i] = float(order[j][1]);
                }
                simd::setup_rays8(cv, px, py, isp, hi, rb);
                if constexpr (requires { policy.rays8(rb); }) policy.rays8(rb);
            }
            const int i = q - rb_base;
            r = {rb.ox[i], rb.oy[i], rb.oz[i], rb.dx[i], rb.dy[i], rb.dz[i]};
            dir = {rb.wx[i], rb.wy[i], rb.wz[i]};
            t_near = rb.t_near[i], t_far = rb.t_far[i];
            return rb.hit[i] != 0;
        } else {
            const Ray wr = cam.generate(float(order[q][0]), float(order[q][1]));
            r = index_ray(wr, inv_sp);
            dir = wr.dir;
            return kernel::intersect_box(r, hi, t_near, t_far);
        }
    };
    // Puts the tile's next ray with at least one run into lane l (pixels without one are written
    // on the way); idles the lane when the tile has no rays left.
    auto start = [&](int l) {
        while (next_pixel < npix) {
            const int x = order[next_pixel][0], y = order[next_pixel][1];
            kernel::IndexRay r;
            Vec3f dir;
            float t_near, t_far;
            int kb, ke;
            const bool hit = ray_of(next_pixel++, r, dir, t_near, t_far);
            tile_rays += hit;
            // Outside the screen cover the ray has no visible sample (render/screen_cover.h).
            if (hit && (!cover || cover->covered(x, y))) {
                Slot& sl = slot[l];
                const float t_base = policy.t_base(x, y, t_near);
                const int k_end = lattice_end(t_base, t_far, dt);
                bool run;
                // Inside the cover, only the depth its boxes allow (screen_cover.h, "Depth").
                float t0 = t_near, t1 = t_far;
                if (cover) {
                    float c0, c1;
                    cover->depth(x, y, c0, c1);
                    t0 = std::max(t0, c0 - dt), t1 = std::min(t1, c1 + dt);
                }
                if constexpr (kWhole) {
                    lattice_run(Segment{t0, t1}, t_base, inv_dt, 0, k_end, kb, ke);
                    run = 0 < k_end && ke > kb && t0 < t1;
                } else {
                    sl.runs.reset();
                    sl.cursor.emplace(accel, r, t0, std::max(t0, t1), dt, chunk);
                    sl.runs.emplace(*sl.cursor, t_base, dt, k_end);
                    run = sl.runs->next(kb, ke);
                }
                if (run) {
                    sl.x = x, sl.y = y;
                    L.ox[l] = r.ox, L.oy[l] = r.oy, L.oz[l] = r.oz;
                    L.dx[l] = r.dx, L.dy[l] = r.dy, L.dz[l] = r.dz;
                    L.t_base[l] = t_base;
                    L.k[l] = kb, L.kend[l] = ke;
                    L.kcheck[l] = kb;
                    L.r[l] = L.g[l] = L.b[l] = L.a[l] = 0.f;
                    L.n[l] = 0;
                    L.active[l] = -1;
                    policy.begin(l, x, y, dir, next_pixel - 1 - rb_base);
                    ++live;
                    return;
                }
            }
            policy.empty(x, y);
        }
        L.active[l] = 0;
        L.k[l] = L.kend[l] = 0;
    };
    // The lanes that need it: the ray's next run, or its pixel and the tile's next ray.
    auto refill = [&](uint32_t need) {
        policy.poll();
        for (int l = 0; l < W; ++l) {
            if (!(need >> l & 1)) continue;
            int kb, ke;
            if (!kWhole && !(L.a[l] >= ert) && slot[l].runs->next(kb, ke)) {
                L.k[l] = kb, L.kend[l] = ke;
                L.kcheck[l] = kb;
                continue;
            }
            policy.finish(l, slot[l].x, slot[l].y, L);
            tile_samples += uint32_t(L.n[l]);
            --live;
            start(l);
        }
        return live > 0;
    };
    for (int l = 0; l < W; ++l) start(l);
    if (live > 0) march(L, refill);
    policy.drain();
}

// The unshaded marcher's policy: lattice at t_near, pixels written as rays finish.
struct CompositePolicy {
    RenderResult& out;
    const RenderOptions& opt;
    uint32_t empty_word = empty_pixel_word(opt);
    float t_base(int, int, float t_near) const { return t_near; }
    void begin(int, int, int, Vec3f, int) {}
    void finish(int l, int x, int y, const simd::Lanes& L) {
        write_pixel(out, opt, x, y, kernel::Accum{L.r[l], L.g[l], L.b[l], L.a[l]},
                    uint32_t(L.n[l]));
    }
    void empty(int x, int y) { write_empty_pixel(out, opt, empty_word, x, y); }
    void poll() {}
    void drain() {}
};

}  // namespace lacuna
