#include "serve/frame_renderer.h"

#include <chrono>
#include <cmath>
#include <mutex>
#include <optional>

#include "core/parallel.h"
#include "lacuna/error.h"
#include "lacuna/mpr.h"
#include "render/sample_analysis.h"

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

}  // namespace

FrameRenderer::FrameRenderer(Volume volume, const AccelOptions& accel_options, int threads)
    : m_accel_options(accel_options), m_threads(threads) {
    m_accel_options.threads = threads;
    m_histogram = compute_histogram(volume, kHistogramBins, threads);
    m_session = std::make_unique<Session>(std::move(volume), threads);
}

FrameRenderer::~FrameRenderer() = default;

void FrameRenderer::set_volume(Volume volume) {
    std::optional<Volume> labels;
    if (m_session->has_labels()) {
        labels = m_session->label_volume();  // shares the voxels
        check_label_volume(*labels, &volume, "labels");
    }
    auto session = std::make_unique<Session>(std::move(volume), m_threads);
    if (labels) {
        session->set_labels(std::move(*labels));
        (void)session->label_table();
    }
    m_histogram = compute_histogram(session->volume(), kHistogramBins, m_threads);
    m_session = std::move(session);
}

void FrameRenderer::set_labels(Volume labels) {
    check_label_volume(labels, &m_session->volume(), "labels");
    m_session->set_labels(std::move(labels));
    (void)m_session->label_table();  // built now, so slice() only reads it
}

FrameRenderer::SliceImage FrameRenderer::slice(const SliceRequest& req, int max_side) const {
    const Clock::time_point t0 = Clock::now();
    const bool overlay = req.overlay_opacity > 0;
    if (overlay && !m_session->has_labels())
        throw Error("slice", "overlay_opacity", "no label volume loaded (`lacuna serve --labels`)");
    SliceOptions o;
    o.interpolation = req.interpolation;
    o.max_size = req.max_size > 0 ? std::min(req.max_size, max_side) : max_side;
    o.threads = m_threads;
    const Volume& v = m_session->volume();
    const Slice s =
        sample_slice(v, slice_geometry(v, req.plane, req.point, o), o.interpolation, o.threads);
    SliceImage out;
    out.geometry = s.geometry;
    out.image = window_level(s, req.window, req.level);
    if (overlay) {
        overlay_labels(out.image, sample_labels(m_session->label_volume(), s.geometry, m_threads),
                       m_session->label_table(), req.overlay_opacity);
        out.overlay = true;
    }
    out.seconds = seconds_since(t0);
    return out;
}

ProbeResult FrameRenderer::probe(const ProbeRequest& req) const {
    const bool labels = m_session->has_labels();
    return lacuna::probe(m_session->volume(), req.point, req.interpolation,
                         labels ? &m_session->label_volume() : nullptr,
                         labels ? &m_session->label_table() : nullptr);
}

// What `lacuna render` does with the same settings: the orbit camera (fov 30, perspective), ert
// 0.99 or off, black background; Phong with the headlight for "shading"; "clip" keeps
// dot((-1,0,0), p) >= -cx, i.e. x <= cx in RAS (the patient's left half); world planes as
// `--clip` (the renderer moves them into the volume frame, docs/formats.md, World frame).
FrameSpec FrameRenderer::frame_spec(const ViewRequest& req, int width, int height) const {
    FrameSpec f;
    // Without a label volume the segments toggle does nothing (the page hides it).
    const bool segments = req.segments && m_session->has_labels();
    f.renderer = frame_renderer(req.renderer, segments);
    f.structure = frame_structure(req.accel, segments, m_accel_options);
    f.sampling.step = req.step;
    f.sampling.early_termination = req.ert ? std::optional<float>(0.99f) : std::nullopt;
    if (req.shading) f.features.shading = ShadingModel::Phong;
    if (req.clip)
        f.features.clip_planes.push_back(
            ClipPlane{{-1.f, 0.f, 0.f}, -m_session->bounds().center().x});
    for (const ClipPlane& p : req.clip_planes) f.features.clip_planes.push_back(p);
    if (segments) {
        LabelTable t = m_session->label_table();
        if (!req.hide.empty()) set_label_visibility(t, req.hide, false, "hide");
        f.segments.labels = std::move(t);
    }
    f.camera.orbit.azimuth_deg = req.camera.azimuth;
    f.camera.orbit.elevation_deg = req.camera.elevation;
    f.camera.orbit.zoom = req.camera.zoom;
    f.camera.pan_x = req.camera.pan_x;
    f.camera.pan_y = req.camera.pan_y;
    f.width = width;
    f.height = height;
    return f;
}

ViewRequest FrameRenderer::view_request(const FrameSpec& f, const TransferFunction& tf) const {
    if (f.renderer == Renderer::Segments)
        throw Error("session", "frame.renderer",
                    "the segment renderer's sessions cannot be opened in the viewer yet (a session "
                    "file does not hold the label map)");
    ViewRequest r;
    r.renderer = f.renderer == Renderer::Slicer ? RendererKind::Slice : RendererKind::March;
    const std::optional<AccelKind> kind = accel_kind(f.structure);
    std::string names;
    bool listed = false;
    for (const std::string& n : accel_names()) {
        names += (names.empty() ? "" : ", ") + n;
        listed = listed || (kind && n == to_string(*kind));
    }
    if (!listed)
        throw Error("session", "frame.structure",
                    "'" + structure_name(f.structure) +
                        "' is not one of the viewer's structures (" + names + ")");
    r.accel = *kind;
    r.ert = f.sampling.early_termination.has_value();
    r.step = f.sampling.step;
    r.shading = f.features.shading == ShadingModel::Phong;
    // The clip toggle is the first plane when it is the toggle's own (see frame_spec()).
    r.clip_planes = f.features.clip_planes;
    const ClipPlane& first = r.clip_planes.empty() ? ClipPlane{} : r.clip_planes.front();
    if (!r.clip_planes.empty() && first.normal == Vec3f{-1.f, 0.f, 0.f} &&
        first.d == -m_session->bounds().center().x) {
        r.clip = true;
        r.clip_planes.erase(r.clip_planes.begin());
    }
    r.camera.azimuth = f.camera.orbit.azimuth_deg;
    r.camera.elevation = f.camera.orbit.elevation_deg;
    r.camera.zoom = f.camera.orbit.zoom;
    r.camera.pan_x = f.camera.pan_x;
    r.camera.pan_y = f.camera.pan_y;
    r.width = f.width;
    r.height = f.height;
    r.tf = tf;
    return r;
}

void FrameRenderer::refine() {
    if (m_source)
        m_source->refine();
    else
        m_session->refine();
}

Frame FrameRenderer::render(const ViewRequest& req, int width, int height) {
    const FrameSpec spec = frame_spec(req, width, height);
    Frame f;
    // 1. A new TF goes to the session (its LUT); the frame brings the marcher and the frame's
    //    structure up to it: together the "TF change -> ready to render" time of the bitfield
    //    paper, Section 4.5. A structure not selected meanwhile catches up when next used.
    const auto t0 = Clock::now();
    f.tf_changed = m_session->set_transfer_function(req.tf);
    const double lut_seconds = seconds_since(t0);
    // 2. The frame (building its structure the first time one is asked for).
    FrameResult r = m_source ? m_source->render(req.tf, spec) : m_session->render(spec);
    if (f.tf_changed) f.tf_update_seconds = lut_seconds + r.tf_sync_seconds;
    f.accel_build_seconds = r.build_seconds;
    if (r.structure) f.accel_tf_update_seconds = r.structure->tf_update_seconds;
    f.image = std::move(r.image);
    f.stats = r.stats;
    // 3. The reference lattice count for the "space skipped" figure.
    const Camera cam = m_session->camera(spec);
    f.lattice_samples =
        count_lattice_samples(m_session->volume(), cam, spec.sampling.step, m_threads);
    f.skipped = f.lattice_samples && f.stats.samples < f.lattice_samples
                    ? 1.0 - double(f.stats.samples) / double(f.lattice_samples)
                    : 0.0;
    return f;
}

}  // namespace lacuna::serve
