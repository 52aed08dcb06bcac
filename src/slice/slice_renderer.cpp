#include "slice/slice_renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include "core/parallel.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "lacuna/renderer.h"
#include "render/pixel_driver.h"
#include "render/ray_march_kernel.h"
#include "slice/polygon.h"

namespace lacuna {

std::string to_string(const SliceStats& s) {
    char buf[320];
    std::snprintf(
        buf, sizeof buf,
        "%.1f ms (set-up %.1f%% of CPU, %.1f%% of wall; occlusion %.1f ms), %llu samples, "
        "%llu polygons, "
        "%llu boxes (%llu culled, %llu clipped), %.1f%% voxels skipped, %d/%d map updates",
        s.seconds * 1e3, 100 * s.setup_cpu_fraction(), 100 * s.setup_fraction(),
        s.occlusion_seconds * 1e3, (unsigned long long)s.samples, (unsigned long long)s.polygons,
        (unsigned long long)s.boxes, (unsigned long long)s.boxes_culled,
        (unsigned long long)s.boxes_clipped, 100 * s.skipped_fraction(), s.map_updates,
        s.desired_updates);
    return buf;
}

SliceRenderer::SliceRenderer(const Volume& volume) : m_volume(volume) {}

void SliceRenderer::set_transfer_function(const TransferLut& lut) {
    m_lut = lut;
}

Box3f SliceRenderer::bounds() const {
    return world_bounds(m_volume);
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Per pixel: the ray in index space (t in world units) and the terms of t on plane k.
struct PixelRays {
    std::vector<float> ox, oy, oz, dx, dy, dz, a, c;
};

// Index space -> continuous pixel coordinates (pixel (x, y) has its centre at (x+0.5, y+0.5)),
// the inverse of Camera::generate.
struct ScreenProjection {
    Vec3d eye, right, up, fwd, sp;
    double sx, sy;  // aspect * half_h, half_h
    double w, h;
    bool persp;
    double ku = 0, kv = 0;  // 0.5 * w / sx, 0.5 * h / sy (set by prepare())
    void prepare() {
        ku = 0.5 * w / sx;
        kv = 0.5 * h / sy;
    }
    // One division per vertex (perspective) instead of four: polygon set-up projects every
    // vertex of every slicing polygon. The pixels tried carry a margin; ownership decides.
    void project(const Vec3d& p, double& u, double& v) const {
        const Vec3d rel = Vec3d{p.x * sp.x, p.y * sp.y, p.z * sp.z} - eye;
        double xr = dot(rel, right), yu = dot(rel, up);
        if (persp) {
            const double inv = 1.0 / dot(rel, fwd);
            xr *= inv;
            yu *= inv;
        }
        u = xr * ku + 0.5 * w;
        v = 0.5 * h - yu * kv;
    }
};

// A slicing polygon on screen.
struct Poly {
    int k;
    int first, count;  // vertices in BoxWork::uv (pairs u, v)
    float umin, umax, vmin, vmax;
};

// A box scheduled for rendering: who owns which samples, and its polygons.
struct BoxWork {
    float lo[3], hi_excl[3];  // ownership: lo <= P < hi_excl (the source's cell box)
    float clo[3], chi[3];     // occlusion clip box: clo <= P <= chi
    std::vector<Poly> polys;
    std::vector<float> uv;
    float umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
};

struct Frame {
    const Camera* cam;
    Vec3d eye_world, fwd;
    Vec3d sp;
    double dt;
    float dt_f;
    ScreenProjection screen;
};

// The slicing polygons of the box [lo, hi] (index space) for every plane that may meet it.
void set_up_box(const Frame& f, Vec3d lo, Vec3d hi, BoxWork& out, uint64_t& polygons) {
    // A margin so a plane that grazes the box in one rounding still yields a polygon; the
    // ownership test decides which samples are taken.
    const double eps = 1e-3;
    for (int a = 0; a < 3; ++a) {
        lo[a] -= eps;
        hi[a] += eps;
    }
    const Vec3d n{f.sp.x * f.fwd.x, f.sp.y * f.fwd.y, f.sp.z * f.fwd.z};  // g(P) = dot(n, P)
    const double g_eye = dot(f.eye_world, f.fwd);
    double zmin = INFINITY, zmax = -INFINITY;
    for (int c = 0; c < 8; ++c) {
        Vec3d p;
        for (int a = 0; a < 3; ++a) p[a] = (c >> a) & 1 ? hi[a] : lo[a];
        const double z = dot(n, p) - g_eye;
        zmin = std::min(zmin, z);
        zmax = std::max(zmax, z);
    }
    const int k0 = std::max(0, int(std::ceil(zmin / f.dt - 0.5)) - 1);
    const int k1 = int(std::floor(zmax / f.dt - 0.5)) + 1;
    if (k1 < k0) return;
    IncrementalSlicer slicer(lo, hi, n, (k0 + 0.5) * f.dt + g_eye, f.dt);
    out.polys.reserve(out.polys.size() + size_t(k1 - k0 + 1));
    out.uv.reserve(out.uv.size() + 12 * size_t(k1 - k0 + 1));  // up to 6 vertices, 2 floats
    SlicePolygon poly;
    for (int k = k0; k <= k1; ++k) {
        slicer.next(poly);
        if (poly.count == 0) continue;
        Poly p{k, int(out.uv.size() / 2), poly.count, INFINITY, -INFINITY, INFINITY, -INFINITY};
        for (int i = 0; i < poly.count; ++i) {
            double u, v;
            f.screen.project(poly.v[size_t(i)], u, v);
            out.uv.push_back(float(u));
            out.uv.push_back(float(v));
            p.umin = std::min(p.umin, float(u));
            p.umax = std::max(p.umax, float(u));
            p.vmin = std::min(p.vmin, float(v));
            p.vmax = std::max(p.vmax, float(v));
        }
        if (!(p.umax >= p.umin && p.vmax >= p.vmin)) continue;  // NaN: behind the eye
        out.umin = std::min(out.umin, p.umin);
        out.umax = std::max(out.umax, p.umax);
        out.vmin = std::min(out.vmin, p.vmin);
        out.vmax = std::max(out.vmax, p.vmax);
        out.polys.push_back(p);
        ++polygons;
    }
}

// Horizontal extent [u0, u1] of the convex hull of the polygon's vertices at height v: the
// extreme crossings of all vertex pairs (robust to any vertex order and to degenerate polygons).
inline bool span_at(const float* uv, int n, float v, float& u0, float& u1) {
    u0 = INFINITY;
    u1 = -INFINITY;
    for (int i = 0; i < n; ++i) {
        const float ui = uv[2 * i], vi = uv[2 * i + 1];
        if (vi == v) {
            u0 = std::min(u0, ui);
            u1 = std::max(u1, ui);
        }
        for (int j = i + 1; j < n; ++j) {
            const float uj = uv[2 * j], vj = uv[2 * j + 1];
            if ((vi - v) * (vj - v) < 0.f) {
                const float u = ui + (v - vi) * (uj - ui) / (vj - vi);
                u0 = std::min(u0, u);
                u1 = std::max(u1, u);
            }
        }
    }
    return u0 <= u1;
}

// Pixels tried beyond a polygon's projected outline. The polygon comes from the box widened by
// 1e-3 voxel, computed in double; the margin covers the float rounding of its screen position.
constexpr float kMargin = 0.05f;

// Composites the boxes of one batch into the tile [x0, x1) x [y0, y1), box after box, each
// polygon front to back.
template <class T>
void raster_tile(const kernel::Grid<T, int64_t>& g, const Rgba* lut, ValueToLut map,
                 const PixelRays& px, const std::vector<const BoxWork*>& batch, float dt, float ert,
                 bool nearest, int width, int x0, int y0, int x1, int y1, kernel::Accum* fb,
                 uint64_t& samples) {
    for (const BoxWork* b : batch) {
        if (b->polys.empty() || b->umax < float(x0) - 1.f || b->umin > float(x1) + 1.f ||
            b->vmax < float(y0) - 1.f || b->vmin > float(y1) + 1.f)
            continue;
        for (const Poly& p : b->polys) {
            if (p.umax < float(x0) - 1.f || p.umin > float(x1) + 1.f || p.vmax < float(y0) - 1.f ||
                p.vmin > float(y1) + 1.f)
                continue;
            const float* uv = &b->uv[size_t(p.first) * 2];
            const float zk = (float(p.k) + 0.5f) * dt;  // the plane, independent of the box
            // Rows and columns clamped to the tile before converting (vertices near the eye
            // can project far off screen).
            const int ya = std::max(
                y0,
                int(std::ceil(std::clamp(p.vmin - 0.5f - kMargin, float(y0) - 1.f, float(y1)))));
            const int yb = std::min(
                y1 - 1,
                int(std::floor(std::clamp(p.vmax - 0.5f + kMargin, float(y0) - 1.f, float(y1)))));
            for (int y = ya; y <= yb; ++y) {
                float u0, u1;
                const float vc = std::clamp(float(y) + 0.5f, p.vmin, p.vmax);
                if (!span_at(uv, p.count, vc, u0, u1)) continue;
                // Every pixel whose sample on this plane may lie in the box (a pixel's samples
                // project exactly onto its centre), with a rounding margin; the ownership test
                // below decides.
                const int xa = std::max(
                    x0,
                    int(std::ceil(std::clamp(u0 - 0.5f - kMargin, float(x0) - 1.f, float(x1)))));
                const int xb = std::min(
                    x1 - 1,
                    int(std::floor(std::clamp(u1 - 0.5f + kMargin, float(x0) - 1.f, float(x1)))));
                for (int x = xa; x <= xb; ++x) {
                    const size_t i = size_t(y) * size_t(width) + size_t(x);
                    kernel::Accum& acc = fb[i];
                    if (acc.a >= ert) continue;  // terminated pixel
                    // The lattice sample (pixel, plane), computed only from those two.
                    const float t = (zk - px.a[i]) * px.c[i];
                    const float sx = px.ox[i] + t * px.dx[i];
                    const float sy = px.oy[i] + t * px.dy[i];
                    const float sz = px.oz[i] + t * px.dz[i];
                    // Ownership (half-open cell box) and the occlusion clip box.
                    if (!(sx >= b->lo[0] && sx < b->hi_excl[0] && sy >= b->lo[1] &&
                          sy < b->hi_excl[1] && sz >= b->lo[2] && sz < b->hi_excl[2] &&
                          sx >= b->clo[0] && sx <= b->chi[0] && sy >= b->clo[1] &&
                          sy <= b->chi[1] && sz >= b->clo[2] && sz <= b->chi[2]))
                        continue;
                    const Rgba& c = lut[map(nearest ? kernel::nearest(g, sx, sy, sz)
                                                    : kernel::trilinear(g, sx, sy, sz))];
                    ++samples;
                    const float w = 1.f - acc.a;
                    acc.r += w * c.r;
                    acc.g += w * c.g;
                    acc.b += w * c.b;
                    acc.a += w * c.a;
                }
            }
        }
    }
}

double cells_of(const Vec3d& lo, const Vec3d& hi) {
    return std::max(hi.x - lo.x, 0.0) * std::max(hi.y - lo.y, 0.0) * std::max(hi.z - lo.z, 0.0);
}

// ---- The steps of a frame (SliceRenderer::render runs them in order) ---------------------------

// 0. What a frame needs; FrameErrors name the FrameSpec field (lacuna/frame_spec.h).
void check_frame(const TransferLut& lut, const Camera& cam, const SliceOptions& opt) {
    if (lut.entries.empty()) throw Error("render", "transfer function", "none was set");
    if (!(opt.step > 0.f) || !std::isfinite(opt.step))
        throw FrameError("sampling.step", "expected a positive number");
    if (cam.width() < 1 || cam.height() < 1)
        throw FrameError("width", "expected at least 1x1 pixels");
    const OcclusionOptions& oo = opt.occlusion;
    if (oo.mode != OcclusionMode::Off) {
        if (!(oo.threshold > 0.f && oo.threshold <= 1.f))
            throw FrameError("slicer.occlusion_threshold", "expected 0 < T <= 1");
        if (oo.map_size < 1 || oo.map_size > 4096)
            throw FrameError("slicer.occlusion_map", "expected 1..4096 cells");
        if (oo.updates < 0) throw FrameError("slicer.occlusion_updates", "expected >= 0");
    }
}

// 1. Per pixel: the camera ray in index space (t in world units) and the terms of t on plane k.
PixelRays pixel_rays(const Camera& cam, const Vec3f& inv_sp, int threads) {
    const int W = cam.width(), H = cam.height();
    const size_t np = size_t(W) * size_t(H);
    const Vec3f eye = cam.eye(), fwd = cam.forward();
    PixelRays px;
    for (auto* v : {&px.ox, &px.oy, &px.oz, &px.dx, &px.dy, &px.dz, &px.a, &px.c}) v->resize(np);
    parallel_for(size_t(H), threads, [&](size_t r0, size_t r1) {
        for (size_t y = r0; y < r1; ++y)
            for (int x = 0; x < W; ++x) {
                const size_t i = y * size_t(W) + size_t(x);
                const Ray wr = cam.generate(float(x), float(y));
                const Vec3f o = wr.origin * inv_sp, d = wr.dir * inv_sp;
                px.ox[i] = o.x, px.oy[i] = o.y, px.oz[i] = o.z;
                px.dx[i] = d.x, px.dy[i] = d.y, px.dz[i] = d.z;
                px.a[i] = dot(wr.origin - eye, fwd);
                px.c[i] = 1.f / dot(wr.dir, fwd);
            }
    });
    return px;
}

// 2. The boxes, front to back: the source's for this view, or the whole volume ('Basic').
std::vector<CellBox> boxes_in_order(const BoxSource* source, const Camera& cam, const Vec3f& inv_sp,
                                    const int cells[3]) {
    if (!source) return {{{0, 0, 0}, {cells[0], cells[1], cells[2]}}};
    return cam.projection() == Projection::Orthographic
               ? source->boxes_front_to_back_along(cam.forward() * inv_sp)
               : source->boxes_front_to_back(cam.eye() * inv_sp);
}

// The planes' geometry and the screen projection of the frame.
Frame frame_geometry(const Camera& cam, const Vec3d& sp, float step) {
    Frame f;
    f.cam = &cam;
    f.eye_world = Vec3d(cam.eye());
    f.fwd = Vec3d(cam.forward());
    f.sp = sp;
    const float min_sp = float(std::min({sp.x, sp.y, sp.z}));
    f.dt_f = step * min_sp;
    f.dt = double(f.dt_f);
    const double W = double(cam.width()), H = double(cam.height());
    f.screen = {f.eye_world,
                Vec3d(cam.right()),
                Vec3d(cam.up()),
                f.fwd,
                sp,
                W / H * cam.half_height(),
                double(cam.half_height()),
                W,
                H,
                cam.projection() == Projection::Perspective};
    f.screen.prepare();
    return f;
}

// 4a. The boxes of the next batch: from `next` on, culled and clipped against the current map,
// until DeltaVoxels more voxels are rendered (a map update follows: update_after) or the boxes
// end. Without occlusion (delta = infinity) that is one batch of every box.
struct BatchCutter {
    const std::vector<CellBox>& boxes;
    const OcclusionOptions& oo;
    const OcclusionMap* map;  // null: no occlusion
    const int* cells;
    double delta_voxels;
    size_t next = 0;
    double rendered = 0, next_update = delta_voxels;

    bool done() const { return next >= boxes.size(); }
    // Fills `work` and `regions` (the clipped box of each); returns update_after.
    bool cut(std::vector<BoxWork>& work, std::vector<std::pair<Vec3d, Vec3d>>& regions,
             SliceStats& st) {
        work.clear();
        regions.clear();
        while (next < boxes.size()) {
            const CellBox& cb = boxes[next++];
            const Vec3d lo{double(cb.lo[0]), double(cb.lo[1]), double(cb.lo[2])};
            const Vec3d hi{double(cb.hi[0]), double(cb.hi[1]), double(cb.hi[2])};
            Vec3d rlo = lo, rhi = hi;
            if (map && map->valid()) {
                const BoxClip bc = clip_box(*map, lo, hi, oo.threshold);
                const double vol = cells_of(lo, hi);
                if (oo.mode == OcclusionMode::CullClip || oo.mode == OcclusionMode::CullOnly) {
                    if (bc.culled) {
                        ++st.boxes_culled;
                        st.voxels_culled += vol;
                        continue;
                    }
                }
                if (oo.mode == OcclusionMode::CullClip && !(bc.lo == lo && bc.hi == hi)) {
                    ++st.boxes_clipped;
                    st.voxels_clipped += vol - cells_of(bc.lo, bc.hi);
                    rlo = bc.lo;
                    rhi = bc.hi;
                }
            }
            BoxWork w;
            for (int a = 0; a < 3; ++a) {
                w.lo[a] = float(cb.lo[a]);
                w.hi_excl[a] = cb.hi[a] >= cells[a] ? std::nextafter(float(cb.hi[a]), INFINITY)
                                                    : float(cb.hi[a]);
                // Rounded outward: the clip box may take a sample more, never one less.
                w.clo[a] = std::nextafter(float(rlo[a]), -INFINITY);
                w.chi[a] = std::nextafter(float(rhi[a]), INFINITY);
            }
            work.push_back(std::move(w));
            regions.push_back({rlo, rhi});
            rendered += cells_of(rlo, rhi);
            if (map && rendered >= next_update && next < boxes.size()) {
                next_update = (std::floor(rendered / delta_voxels) + 1) * delta_voxels;
                return true;
            }
        }
        return false;
    }
};

// 4b. The slicing polygons of every box of the batch (incremental intersection), in parallel;
// their wall and CPU time go to the set-up counters.
void set_up_batch(const Frame& f, const std::vector<std::pair<Vec3d, Vec3d>>& regions,
                  std::vector<BoxWork>& work, int threads, SliceStats& st) {
    const auto t_setup = Clock::now();
    std::vector<uint64_t> polys(work.size(), 0);
    std::atomic<int64_t> setup_cpu_ns{0};
    parallel_for(work.size(), threads, [&](size_t b0, size_t b1) {
        const double c0 = thread_cpu_seconds();
        for (size_t b = b0; b < b1; ++b)
            set_up_box(f, regions[b].first, regions[b].second, work[b], polys[b]);
        setup_cpu_ns += int64_t(1e9 * (thread_cpu_seconds() - c0));
    });
    st.setup_cpu_seconds += 1e-9 * double(setup_cpu_ns.load());
    for (uint64_t n : polys) st.polygons += n;
    st.setup_seconds += seconds_since(t_setup);
}

// What compositing a batch reads: the step-corrected LUT, the value-to-entry map, the rays.
struct Compositor {
    const Volume& volume;
    const std::vector<Rgba>& lut;
    ValueToLut map;
    const PixelRays& px;
    float dt, ert;
    bool nearest;
    int width, height, tile, threads;

    // 4c. Composites the batch into `fb`, tile by tile; returns the samples taken.
    uint64_t composite(const std::vector<BoxWork>& work, kernel::Accum* fb) const {
        std::vector<const BoxWork*> batch;
        for (const BoxWork& w : work) batch.push_back(&w);
        std::atomic<uint64_t> samples{0};
        visit_voxels(volume, [&](const auto* data) {
            using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
            const kernel::Grid<T, int64_t> g = kernel::make_grid<int64_t>(data, volume.dims());
            parallel_for_tiles(width, height, std::max(tile, 1), threads,
                               [&](int x0, int y0, int x1, int y1) {
                                   uint64_t n = 0;
                                   raster_tile(g, lut.data(), map, px, batch, dt, ert, nearest,
                                               width, x0, y0, x1, y1, fb, n);
                                   samples += n;
                               });
        });
        return samples;
    }
};

// 5. The framebuffer over the background in 8 bits, by the ray marcher's write-out
// (pixel_word, render/pixel_driver.h), and the float RGBA when asked.
void write_out(const std::vector<kernel::Accum>& fb, const SliceOptions& opt, SliceResult& out) {
    const size_t np = fb.size();
    if (opt.keep_float) out.rgba_float.resize(np * 4);
    for (size_t i = 0; i < np; ++i) {
        const kernel::Accum& acc = fb[i];
        const uint32_t word = pixel_word(opt.background, acc);
        std::memcpy(&out.image.rgba[i * 4], &word, 4);
        if (opt.keep_float) {
            float* q = &out.rgba_float[i * 4];
            q[0] = acc.r, q[1] = acc.g, q[2] = acc.b, q[3] = acc.a;
        }
    }
}

}  // namespace

// A frame in five steps: the rays (1), the boxes in visibility order (2), the occlusion map (3),
// then batch after batch of boxes between map updates: cut and clip (4a), slicing polygons (4b),
// compositing (4c), the map update (4d); finally the write-out (5).
SliceResult SliceRenderer::render(const Camera& world_cam, const SliceOptions& opt,
                                  AdaptiveUpdates* adaptive) const {
    // World (RAS) -> the volume frame, where the boxes and rays live (lacuna/orientation.h).
    const Camera cam = to_volume_frame(volume_frame(m_volume), world_cam);
    check_frame(m_lut, cam, opt);
    const auto t_start = Clock::now();
    const double cpu_start = process_cpu_seconds();
    const int W = cam.width(), H = cam.height();
    SliceResult out;
    out.image = Image(W, H);
    SliceStats& st = out.stats;

    // 1. Rays; 2. boxes.
    const Vec3d sp = m_volume.spacing;
    const Vec3f inv_sp{float(1.0 / sp.x), float(1.0 / sp.y), float(1.0 / sp.z)};
    const PixelRays px = pixel_rays(cam, inv_sp, opt.threads);
    const Vec3i dims = m_volume.dims();
    const int cells[3] = {dims.x - 1, dims.y - 1, dims.z - 1};
    const std::vector<CellBox> boxes = boxes_in_order(m_source, cam, inv_sp, cells);
    st.boxes = boxes.size();
    for (const CellBox& b : boxes)
        st.voxels += cells_of({double(b.lo[0]), double(b.lo[1]), double(b.lo[2])},
                              {double(b.hi[0]), double(b.hi[1]), double(b.hi[2])});
    const Frame f = frame_geometry(cam, sp, opt.step);

    // 3. Occlusion: the map's geometry and each pixel's cells, the DeltaVoxels schedule.
    const OcclusionOptions& oo = opt.occlusion;
    std::unique_ptr<OcclusionMap> omap;
    double delta_voxels = INFINITY;
    if (oo.mode != OcclusionMode::Off) {
        const auto t0 = Clock::now();
        omap = std::make_unique<OcclusionMap>(cam, dims, sp, oo.map_size);
        omap->assign_pixels(px.ox, px.oy, px.oz, px.dx, px.dy, px.dz);
        st.desired_updates = adaptive ? adaptive->desired() : oo.updates;
        delta_voxels = st.voxels / double(st.desired_updates + 1);
        st.occlusion_seconds += seconds_since(t0);
    }

    // 4. Batches of boxes between map updates (one batch without occlusion).
    std::vector<kernel::Accum> fb(size_t(W) * size_t(H));
    const std::vector<Rgba> lut = step_corrected_lut(m_lut, opt.step);
    const Compositor comp{m_volume,    lut,        m_lut.map(),
                          px,          f.dt_f,     opt.ert >= 1.f ? kNoEarlyTermination : opt.ert,
                          opt.nearest, W,          H,
                          opt.tile,    opt.threads};
    BatchCutter cutter{boxes, oo, omap.get(), cells, delta_voxels};
    std::vector<BoxWork> work;
    std::vector<std::pair<Vec3d, Vec3d>> regions;
    uint64_t samples = 0;
    while (!cutter.done()) {
        const auto t_occ = Clock::now();
        const bool update_after = cutter.cut(work, regions, st);  // 4a
        if (omap) st.occlusion_seconds += seconds_since(t_occ);
        set_up_batch(f, regions, work, opt.threads, st);  // 4b
        samples += comp.composite(work, fb.data());       // 4c
        if (update_after) {                               // 4d
            const auto t0 = Clock::now();
            omap->update(&fb[0].a, 4);
            ++st.map_updates;
            st.occlusion_seconds += seconds_since(t0);
        }
    }

    // 5. Background and 8 bits.
    write_out(fb, opt, out);
    st.samples = samples;
    st.seconds = seconds_since(t_start);
    st.cpu_seconds = process_cpu_seconds() - cpu_start;
    if (adaptive && omap) adaptive->report(st.skipped_fraction(), st.map_updates);
    return out;
}

}  // namespace lacuna
