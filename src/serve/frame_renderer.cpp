#include "serve/frame_renderer.h"

#include <chrono>
#include <cmath>
#include <mutex>

#include "core/parallel.h"
#include "render/sample_analysis.h"
#include "slice/box_sources.h"

namespace lacuna::serve {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::vector<uint64_t> compute_histogram(const Volume& v, int bins, int threads) {
    std::vector<uint64_t> total(size_t(bins), 0);
    const ValueRange r = v.vis_range();
    const double scale = r.max > r.min ? double(bins) / (double(r.max) - double(r.min)) : 0.0;
    std::mutex merge;
    visit_voxels(v, [&](const auto* data) {
        parallel_for(
            v.voxel_count(), threads,
            [&](size_t b, size_t e) {
                std::vector<uint64_t> local(size_t(bins), 0);
                for (size_t i = b; i < e; ++i) {
                    const double u = (double(data[i]) - double(r.min)) * scale;
                    const int bin = u < 0 ? 0 : (u >= bins ? bins - 1 : int(u));
                    ++local[size_t(bin)];
                }
                std::lock_guard<std::mutex> lock(merge);
                for (int i = 0; i < bins; ++i) total[size_t(i)] += local[size_t(i)];
            },
            size_t(1) << 20);
    });
    return total;
}

// A structure, box source or segment renderer that missed TF changes (it was not selected
// then) catches up: `held` is the TF version it holds, `version` the current one.
template <class T>
void catch_up_tf(T& target, uint64_t& held, const TransferLut& lut, uint64_t version) {
    if (held == version) return;
    target.set_transfer_function(lut);
    held = version;
}

}  // namespace

FrameRenderer::FrameRenderer(Volume volume, const AccelOptions& accel_options, int threads)
    : m_volume(std::make_unique<Volume>(std::move(volume))),
      m_accel_options(accel_options),
      m_threads(threads) {
    m_accel_options.threads = threads;
    m_histogram = compute_histogram(*m_volume, kHistogramBins, threads);
    m_marcher = std::make_unique<RayMarcher>(*m_volume);
}

FrameRenderer::~FrameRenderer() = default;

Camera FrameRenderer::camera(const ViewCamera& c, int width, int height) const {
    OrbitParams op;
    op.azimuth_deg = c.azimuth;
    op.elevation_deg = c.elevation;
    op.zoom = c.zoom;
    const Box3f bounds = m_marcher->bounds();
    if (c.pan_x != 0.f || c.pan_y != 0.f) {
        // Pan moves the orbit's target along the view plane (the camera's right and up, as
        // Camera::orbit derives them), in units of the bounding sphere's radius.
        const Camera base = Camera::orbit(bounds, op, width, height);
        const Vec3f f = base.forward();
        Vec3f world_up{0, 0, 1};
        if (std::abs(dot(world_up, f)) > 0.999f) world_up = {0, 1, 0};
        const Vec3f right = normalize(cross(f, world_up));
        const Vec3f up = cross(right, f);
        const float radius = 0.5f * length(bounds.extent());
        op.has_target = true;
        op.target = bounds.center() + right * (c.pan_x * radius) + up * (c.pan_y * radius);
    }
    return Camera::orbit(bounds, op, width, height);
}

RenderOptions FrameRenderer::render_options(const ViewRequest& req) const {
    RenderOptions ro;
    ro.step = req.step;
    ro.ert = req.ert ? 0.99f : 2.f;  // as `lacuna render --ert 1`: opacity never reaches 2
    ro.threads = m_threads;
    if (req.shading) ro.features.shading = ShadingModel::Phong;  // default light: the headlight
    if (req.clip) {
        // Keep dot((-1,0,0), p) >= -cx, i.e. x <= cx in RAS: the patient's left half.
        const Box3f b = m_marcher->bounds();
        ro.features.clip_planes.push_back(ClipPlane{{-1.f, 0.f, 0.f}, -b.center().x});
    }
    // World (patient RAS mm) planes, as `lacuna render --clip`: the renderer moves them into
    // the volume frame with the camera (docs/formats.md, World frame).
    for (const ClipPlane& p : req.clip_planes) ro.features.clip_planes.push_back(p);
    return ro;
}

Accel& FrameRenderer::accel(AccelKind k, double& build_seconds) {
    Built& b = m_accels[k];
    if (!b.accel) {
        const auto t0 = Clock::now();
        b.accel = make_accel(k, *m_volume, m_accel_options);
        build_seconds = seconds_since(t0);
        b.tf_version = 0;  // holds no TF yet
    }
    return *b.accel;
}

bool FrameRenderer::update_tf(const TransferFunction& tf) {
    if (m_has_tf && tf == m_tf) return false;
    m_tf = tf;
    m_has_tf = true;
    ++m_tf_version;
    m_lut = discretise(m_tf, m_volume->vis_range());
    m_marcher->set_transfer_function(m_lut);
    return true;
}

Frame FrameRenderer::render_slice(const ViewRequest& req, int width, int height) {
    Frame f;
    const auto t0 = Clock::now();
    if (!m_slicer) m_slicer = std::make_unique<SliceRenderer>(*m_volume);
    f.tf_changed = update_tf(req.tf);
    m_slicer->set_transfer_function(m_lut);
    BuiltSource& b = m_sources[req.accel];
    if (!b.source) {
        const auto tb = Clock::now();
        b.source = make_box_source(req.accel == AccelKind::KdTree ? "kdtree" : "none", *m_volume,
                                   m_accel_options);
        f.accel_build_seconds = seconds_since(tb);
    }
    catch_up_tf(*b.source, b.tf_version, m_lut, m_tf_version);
    if (f.tf_changed) f.tf_update_seconds = seconds_since(t0);
    m_slicer->set_box_source(b.source.get());
    const Camera cam = camera(req.camera, width, height);
    SliceOptions so;
    so.step = req.step;
    so.ert = req.ert ? 0.99f : 2.f;
    so.threads = m_threads;
    SliceResult r = m_slicer->render(cam, so);
    f.image = std::move(r.image);
    f.stats.seconds = r.stats.seconds;
    f.stats.samples = r.stats.samples;
    f.stats.pixels = uint64_t(width) * uint64_t(height);
    f.stats.rays = f.stats.pixels;  // the slicer has no rays: samples per pixel
    f.lattice_samples = count_lattice_samples(*m_volume, cam, req.step, m_threads);
    f.skipped = f.lattice_samples && f.stats.samples < f.lattice_samples
                    ? 1.0 - double(f.stats.samples) / double(f.lattice_samples)
                    : 0.0;
    return f;
}

void FrameRenderer::set_labels(Volume labels) {
    check_label_volume(labels, m_volume.get(), "--labels");
    m_labels = std::make_unique<Volume>(std::move(labels));
    m_label_table = default_label_table(*m_labels);
    for (auto& s : m_segments) s = {};
}

Frame FrameRenderer::render_segments(const ViewRequest& req, int width, int height) {
    Frame f;
    const auto t0 = Clock::now();
    f.tf_changed = update_tf(req.tf);
    const bool octree = req.accel == AccelKind::Bitfield;
    BuiltSegments& b = m_segments[octree ? 1 : 0];
    if (!b.renderer) {
        const auto tb = Clock::now();
        SegmentOptions so;
        so.skip = octree;
        so.leaf_cells = m_accel_options.leaf_cells;
        so.bitfield_bits = m_accel_options.bitfield_bits;
        b.renderer = std::make_unique<SegmentRenderer>(m_volume.get(), *m_labels, so);
        f.accel_build_seconds = seconds_since(tb);
    }
    catch_up_tf(*b.renderer, b.tf_version, m_lut, m_tf_version);
    if (!octree) {
        const Accel* a = nullptr;
        if (req.accel != AccelKind::None) {
            Accel& acc = accel(req.accel, f.accel_build_seconds);
            catch_up_tf(acc, m_accels[req.accel].tf_version, m_lut, m_tf_version);
            a = &acc;
        }
        b.renderer->set_accel(a);
    }
    if (f.tf_changed) f.tf_update_seconds = seconds_since(t0);
    LabelTable t = m_label_table;
    if (!req.hide.empty()) set_label_visibility(t, req.hide, false, "hide");
    b.renderer->set_labels(t);
    const Camera cam = camera(req.camera, width, height);
    const RenderOptions ro = render_options(req);
    RenderResult r = b.renderer->render(cam, ro);
    f.image = std::move(r.image);
    f.stats = r.stats;
    f.lattice_samples = count_lattice_samples(*m_volume, cam, ro.step, m_threads);
    f.skipped = f.lattice_samples ? 1.0 - double(f.stats.samples) / double(f.lattice_samples) : 0.0;
    return f;
}

void FrameRenderer::refine() {
    for (auto& [kind, b] : m_accels)
        if (b.accel) b.accel->refine();
}

Frame FrameRenderer::render(const ViewRequest& req, int width, int height) {
    if (req.renderer == RendererKind::Slice) return render_slice(req, width, height);
    if (req.segments && m_labels) return render_segments(req, width, height);
    Frame f;
    // 1. A new TF: discretise it and hand it to the marcher and the current structure (the
    //    "TF change -> ready to render" time of the bitfield paper, Section 4.5).
    Accel& a = accel(req.accel, f.accel_build_seconds);
    Built& built = m_accels[req.accel];
    const auto t0 = Clock::now();
    f.tf_changed = update_tf(req.tf);
    // 2. A structure that missed TF changes (it was not selected then) catches up.
    catch_up_tf(a, built.tf_version, m_lut, m_tf_version);
    if (f.tf_changed) f.tf_update_seconds = seconds_since(t0);
    f.accel_tf_update_seconds = a.stats().tf_update_seconds;
    m_marcher->set_accel(&a);

    // 3. The frame, and the reference lattice count for the "space skipped" figure.
    const Camera cam = camera(req.camera, width, height);
    const RenderOptions ro = render_options(req);
    RenderResult r = m_marcher->render(cam, ro);
    f.image = std::move(r.image);
    f.stats = r.stats;
    f.lattice_samples = count_lattice_samples(*m_volume, cam, ro.step, m_threads);
    f.skipped = f.lattice_samples ? 1.0 - double(f.stats.samples) / double(f.lattice_samples) : 0.0;
    return f;
}

}  // namespace lacuna::serve
