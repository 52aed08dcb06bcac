// Session (include/lacuna/session.h): the lazily built structures, their TF versions, and the one
// translation of a FrameSpec into each renderer's options.
#include "lacuna/session.h"

#include <chrono>
#include <cmath>

#include "core/check.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "lacuna/rgb.h"
#include "session/structure_registry.h"
#include "slice/box_sources.h"
#include "slice/slice_renderer.h"

namespace lacuna {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The one place FrameSpec's nullopt becomes the renderers' "off" (lacuna/renderer.h).
float ert_of(const Sampling& s) {
    return s.early_termination.value_or(kNoEarlyTermination);
}

// Something built for some TF: it holds version `version` of the session's TF, as the front LUT
// alone or (two_tfs) as the union of front and back.
struct TfHeld {
    uint64_t version = 0;  // 0: no TF yet (the session's versions start at 1)
    bool with_back = false;
    bool current(uint64_t v, bool back) const { return version == v && with_back == back; }
};

}  // namespace

struct Session::State {
    std::unique_ptr<RayMarcher> marcher;
    std::unique_ptr<SliceRenderer> slicer;
    // What the marcher and the slicer hold (the marcher's back LUT separately: setting it
    // invalidates the marcher's cached gradient and light volumes).
    uint64_t marcher_version = 0, slicer_version = 0;
    bool marcher_back = false;
    uint64_t marcher_back_version = 0;

    struct BuiltAccel {
        Structure structure;
        Interpolation interpolation;
        std::unique_ptr<Accel> accel;
        TfHeld held;
    };
    struct BuiltSource {
        Structure structure;
        std::unique_ptr<BoxSource> source;
        TfHeld held;
    };
    struct BuiltSegments {
        SegmentOptions options;
        bool own_labels = false;  // built over the session's label volume (else the volume)
        std::unique_ptr<SegmentRenderer> renderer;
        TfHeld held;
    };
    std::vector<BuiltAccel> accels;
    std::vector<BuiltSource> sources;
    std::vector<BuiltSegments> segments;
    SegmentRenderer* current_segments = nullptr;  // the one prepare() set up for the frame

    // The slicer's adaptive map updates (SlicerSpec::adaptive_updates): the controller and the
    // frames it learns from (their structure and slicer spec). Any other frame drops it.
    struct Adaptive {
        Structure structure;
        SlicerSpec slicer;
        AdaptiveUpdates controller;
    };
    std::optional<Adaptive> adaptive;
};

Session::Session(Volume volume, int threads)
    : m_volume(std::make_unique<Volume>(std::move(volume))),
      m_threads(threads),
      m_state(std::make_unique<State>()) {}

Session::~Session() = default;

Box3f Session::bounds() const {
    return m_brick ? m_whole_bounds : world_bounds(*m_volume);
}

void Session::set_brick(const BrickOwnership& brick, const Box3f& whole_bounds) {
    m_brick = brick;
    m_whole_bounds = whole_bounds;
}

bool Session::set_transfer_function(const TransferFunction& tf) {
    if (m_has_tf && tf == m_tf) return false;
    m_tf = tf;
    m_has_tf = true;
    m_lut = discretise(m_tf, m_volume->vis_range());
    ++m_tf_version;
    return true;
}

void Session::set_back_transfer_function(const std::optional<TransferFunction>& tf) {
    if (tf)
        m_back_lut = discretise(*tf, m_volume->vis_range());
    else
        m_back_lut.reset();
    ++m_tf_version;
}

void Session::set_labels(Volume labels) {
    check_label_volume(labels, m_volume.get(), "labels");
    m_labels = std::make_unique<Volume>(std::move(labels));
    m_label_table.reset();
    m_state->segments.clear();
    m_state->current_segments = nullptr;
}

const LabelTable& Session::label_table() const {
    if (!m_label_table) m_label_table = default_label_table(label_volume());
    return *m_label_table;
}

Camera Session::camera(const FrameSpec& spec) const {
    // The segment renderer frames its label map (the same grid; its geometry may differ).
    const Box3f b =
        m_brick
            ? m_whole_bounds
            : world_bounds(spec.renderer == Renderer::Segments && m_labels ? *m_labels : *m_volume);
    OrbitParams op = spec.camera.orbit;
    if (spec.camera.pan_x != 0.f || spec.camera.pan_y != 0.f) {
        // Pan moves the orbit's target along the view plane (the orbit camera's right and up),
        // in units of the bounding sphere's radius.
        const Camera base = Camera::orbit(b, op, spec.width, spec.height);
        const Vec3f right = base.right();
        const Vec3f up = base.up();
        const float radius = 0.5f * length(b.extent());
        op.has_target = true;
        op.target =
            b.center() + right * (spec.camera.pan_x * radius) + up * (spec.camera.pan_y * radius);
    }
    return Camera::orbit(b, op, spec.width, spec.height);
}

void Session::check_tfs(const FrameSpec& spec) const {
    const bool labels_alone =
        spec.renderer == Renderer::Segments && spec.segments.mode == SegmentMode::Labels;
    if (!m_has_tf && !labels_alone)
        throw Error("session", "transfer function",
                    "none was set (Session::set_transfer_function)");
    if (spec.two_tfs && !m_back_lut)
        throw Error("session", "back transfer function",
                    "two_tfs needs one (Session::set_back_transfer_function)");
    if (spec.renderer == Renderer::Segments && spec.segments.mode == SegmentMode::Masked &&
        !m_labels)
        throw Error("session", "labels", "mask mode needs a label volume (Session::set_labels)");
}

namespace {

// Brings `target` to the session's TF: the front LUT, or with two TFs their union (the structure
// then skips only where both are transparent). Returns the seconds it took (0: it held it).
template <class T>
double sync_tf(T& target, TfHeld& held, uint64_t version, bool with_back, const TransferLut& lut,
               const std::optional<TransferLut>& back) {
    if (held.current(version, with_back)) return 0;
    const auto t0 = Clock::now();
    target.set_transfer_function(with_back ? union_lut(lut, *back) : lut);
    held = {version, with_back};
    return seconds_since(t0);
}

}  // namespace

// The intensity structure of the ray marcher, or of the segment renderer's mask mode: built the
// first time, then brought to the session's TF (with two TFs, their union).
Accel& Session::intensity_structure(const FrameSpec& spec, FrameResult& out) {
    State& s = *m_state;
    const Interpolation interp = spec.sampling.interpolation;
    State::BuiltAccel* found = nullptr;
    for (auto& b : s.accels)
        if (b.structure == spec.structure && b.interpolation == interp) found = &b;
    if (!found) {
        // validate() granted this renderer the structure, so it has a ray face.
        LACUNA_CHECK(accel_kind(spec.structure).has_value());
        const auto t0 = Clock::now();
        auto accel = make_accel(*accel_kind(spec.structure), *m_volume,
                                *accel_options(spec.structure, interp, m_threads));
        out.build_seconds += seconds_since(t0);
        s.accels.push_back({spec.structure, interp, std::move(accel), {}});
        found = &s.accels.back();
    }
    out.tf_sync_seconds +=
        sync_tf(*found->accel, found->held, m_tf_version, spec.two_tfs, m_lut, m_back_lut);
    return *found->accel;
}

void Session::prepare_marcher(const FrameSpec& spec, FrameResult& out) {
    State& s = *m_state;
    const bool back = spec.two_tfs;
    if (!s.marcher) s.marcher = std::make_unique<RayMarcher>(*m_volume);
    if (s.marcher_version != m_tf_version) {
        const auto t0 = Clock::now();
        s.marcher->set_transfer_function(m_lut);
        s.marcher_version = m_tf_version;
        out.tf_sync_seconds += seconds_since(t0);
    }
    // The back LUT only when it changes: setting it drops the marcher's cached gradient and
    // light volumes.
    if (back != s.marcher_back || (back && s.marcher_back_version != m_tf_version)) {
        const auto t0 = Clock::now();
        s.marcher->set_back_transfer_function(back ? *m_back_lut : TransferLut{});
        s.marcher_back = back;
        s.marcher_back_version = m_tf_version;
        out.tf_sync_seconds += seconds_since(t0);
    }
    Accel& a = intensity_structure(spec, out);
    s.marcher->set_accel(&a);
    out.structure = a.stats();
}

void Session::prepare_slicer(const FrameSpec& spec, FrameResult& out) {
    State& s = *m_state;
    if (!s.slicer) s.slicer = std::make_unique<SliceRenderer>(*m_volume);
    if (s.slicer_version != m_tf_version) {
        const auto t0 = Clock::now();
        s.slicer->set_transfer_function(m_lut);
        s.slicer_version = m_tf_version;
        out.tf_sync_seconds += seconds_since(t0);
    }
    // None: the whole volume as one box (no source; the 'Basic' slicer).
    if (std::holds_alternative<structure::None>(spec.structure)) {
        s.slicer->set_box_source(nullptr);
        return;
    }
    State::BuiltSource* found = nullptr;
    for (auto& b : s.sources)
        if (b.structure == spec.structure) found = &b;
    if (!found) {
        // The registry's box face, with the structure's parameters.
        const auto t0 = Clock::now();
        AccelOptions ao;
        ao.threads = m_threads;
        if (const auto ray = accel_options(spec.structure, Interpolation::Trilinear, m_threads))
            ao = *ray;
        BoxesOptions bo;
        if (const auto* gb = std::get_if<structure::GrowingBoxes>(&spec.structure)) {
            bo.coalesce = gb->coalesce;
            bo.coalesce_edge = gb->coalesce_edge;
        }
        const registry::Entry& e = registry::entry(spec.structure);
        LACUNA_CHECK(e.make_boxes != nullptr);  // validate(): the slicer takes box faces only
        s.sources.push_back({spec.structure, e.make_boxes(*m_volume, ao, bo), {}});
        out.build_seconds += seconds_since(t0);
        found = &s.sources.back();
    }
    out.tf_sync_seconds +=
        sync_tf(*found->source, found->held, m_tf_version, false, m_lut, m_back_lut);
    s.slicer->set_box_source(found->source.get());
}

void Session::prepare_segments(const FrameSpec& spec, FrameResult& out) {
    State& s = *m_state;
    const bool masked = spec.segments.mode == SegmentMode::Masked;
    const auto* octree = std::get_if<structure::LabelOctree>(&spec.structure);
    SegmentOptions so;
    so.mode = spec.segments.mode;
    so.tint = spec.segments.tint;
    so.skip = octree != nullptr;
    if (octree) {
        so.leaf_cells = octree->leaf_cells;
        so.bitfield_bits = octree->bits;
    }
    // One segment renderer per options and label map (the label volume, else the volume).
    const bool own = m_labels != nullptr;
    State::BuiltSegments* found = nullptr;
    for (auto& b : s.segments)
        if (b.own_labels == own && b.options.mode == so.mode && b.options.skip == so.skip &&
            b.options.leaf_cells == so.leaf_cells && b.options.bitfield_bits == so.bitfield_bits &&
            b.options.tint == so.tint)
            found = &b;
    if (!found) {
        const auto t0 = Clock::now();
        auto seg = std::make_unique<SegmentRenderer>(masked ? m_volume.get() : nullptr,
                                                     own ? *m_labels : *m_volume, so);
        out.build_seconds += seconds_since(t0);
        s.segments.push_back({so, own, std::move(seg), {}});
        found = &s.segments.back();
    }
    SegmentRenderer& seg = *found->renderer;
    s.current_segments = &seg;
    if (masked) {
        out.tf_sync_seconds += sync_tf(seg, found->held, m_tf_version, false, m_lut, m_back_lut);
        // Without the label octree, any intensity structure skips (exact: the mask only lowers
        // opacities); None marches every sample.
        if (!octree) {
            const Accel* a = nullptr;
            if (!std::holds_alternative<structure::None>(spec.structure)) {
                Accel& acc = intensity_structure(spec, out);
                out.structure = acc.stats();
                a = &acc;
            }
            seg.set_accel(a);
        }
    }
    out.segments = seg.stats();
}

FrameResult Session::prepare(const FrameSpec& spec) {
    validate(spec);
    check_tfs(spec);
    // A brick session renders its owned samples through the ray marcher's plain path only
    // (lacuna/renderer.h BrickOwnership).
    if (m_brick) {
        if (spec.renderer != Renderer::RayMarcher)
            throw FrameError("renderer", "distributed rendering takes the ray marcher only");
        // Features that act on each sample alone (shading, gradient opacity, clip planes, crop,
        // jitter); not shadows (they reach into other bricks) or what composites differently.
        const FeatureOptions& f = spec.features;
        if (f.shadows.enabled || f.blend != BlendMode::Composite || spec.two_tfs)
            throw FrameError("features",
                             "distributed rendering takes no shadows, blend modes or two TFs yet");
    }
    if (rgb_colours(*m_volume) && spec.renderer != Renderer::RayMarcher)  // src/render/rgb_march.h
        throw FrameError("renderer", "an RGB volume renders with the ray marcher only");
    FrameResult out;
    switch (spec.renderer) {
        case Renderer::RayMarcher:
            prepare_marcher(spec, out);
            break;
        case Renderer::Slicer:
            prepare_slicer(spec, out);
            break;
        case Renderer::Segments:
            prepare_segments(spec, out);
            break;
    }
    return out;
}

namespace {

// The ray marcher's and the segment renderer's options for a spec.
RenderOptions render_options(const FrameSpec& spec, int threads) {
    RenderOptions ro;
    ro.step = spec.sampling.step;
    ro.interpolation = spec.sampling.interpolation;
    ro.ert = ert_of(spec.sampling);
    ro.threads = threads;
    ro.background = spec.background;
    ro.count_samples = spec.count_samples;
    ro.keep_float = spec.keep_float;
    ro.features = spec.features;
    return ro;
}

// The slicer's.
SliceOptions slice_options(const FrameSpec& spec, int threads) {
    SliceOptions o;
    o.step = spec.sampling.step;
    o.ert = ert_of(spec.sampling);
    o.threads = threads;
    o.background = spec.background;
    o.nearest = spec.sampling.interpolation == Interpolation::Nearest;
    o.keep_float = spec.keep_float;
    if (spec.slicer.occlusion) {
        switch (spec.slicer.occlusion_use) {
            case OcclusionUse::CullClip:
                o.occlusion.mode = OcclusionMode::CullClip;
                break;
            case OcclusionUse::CullOnly:
                o.occlusion.mode = OcclusionMode::CullOnly;
                break;
            case OcclusionUse::MapOnly:
                o.occlusion.mode = OcclusionMode::MapOnly;
                break;
        }
        o.occlusion.threshold = spec.slicer.occlusion_threshold;
        o.occlusion.map_size = spec.slicer.occlusion_map;
        o.occlusion.updates = spec.slicer.occlusion_updates;
    }
    return o;
}

SlicerFrameStats slicer_stats(const SliceStats& st) {
    SlicerFrameStats fs;
    fs.boxes = st.boxes;
    fs.polygons = st.polygons;
    fs.setup_fraction = st.setup_fraction();
    fs.setup_cpu_fraction = st.setup_cpu_fraction();
    fs.map_updates = st.map_updates;
    fs.desired_updates = st.desired_updates;
    fs.boxes_culled = st.boxes_culled;
    fs.boxes_clipped = st.boxes_clipped;
    fs.skipped_fraction = st.skipped_fraction();
    fs.culled_fraction = st.culled_fraction();
    fs.clipped_fraction = st.clipped_fraction();
    fs.occlusion_seconds = st.occlusion_seconds;
    fs.voxels = st.voxels;
    return fs;
}

}  // namespace

FrameResult Session::render(const FrameSpec& spec) {
    FrameResult out = prepare(spec);
    State& s = *m_state;
    const Camera cam = camera(spec);
    if (!(spec.renderer == Renderer::Slicer && spec.slicer.occlusion &&
          spec.slicer.adaptive_updates))
        s.adaptive.reset();
    RenderResult r;
    switch (spec.renderer) {
        case Renderer::RayMarcher:
            if (m_brick) {
                // Every rank marches its rays to their end: the opacity in front of its brick
                // is another rank's.
                RenderOptions ro = render_options(spec, m_threads);
                ro.ert = kNoEarlyTermination;
                ro.brick = &*m_brick;
                r = s.marcher->render(cam, ro);
            } else {
                r = s.marcher->render(cam, render_options(spec, m_threads));
            }
            break;
        case Renderer::Slicer: {
            // The adaptive controller learns over consecutive frames of one structure and
            // slicer spec (the camera moves); a frame of another starts it afresh.
            AdaptiveUpdates* adaptive = nullptr;
            if (spec.slicer.occlusion && spec.slicer.adaptive_updates) {
                if (!s.adaptive || !(s.adaptive->structure == spec.structure) ||
                    !(s.adaptive->slicer == spec.slicer)) {
                    AdaptiveOptions ao;
                    ao.initial = spec.slicer.occlusion_updates;
                    s.adaptive.emplace(
                        State::Adaptive{spec.structure, spec.slicer, AdaptiveUpdates(ao)});
                }
                adaptive = &s.adaptive->controller;
            }
            SliceResult sr = s.slicer->render(cam, slice_options(spec, m_threads), adaptive);
            r.image = std::move(sr.image);
            r.rgba_float = std::move(sr.rgba_float);
            r.stats.seconds = sr.stats.seconds;
            r.stats.cpu_seconds = sr.stats.cpu_seconds;
            r.stats.samples = sr.stats.samples;
            r.stats.pixels = uint64_t(spec.width) * uint64_t(spec.height);
            r.stats.rays = r.stats.pixels;  // the slicer has no rays: samples per pixel
            out.slicer = slicer_stats(sr.stats);
            break;
        }
        case Renderer::Segments: {
            LACUNA_CHECK(s.current_segments != nullptr);  // prepare_segments set it
            SegmentRenderer& seg = *s.current_segments;
            seg.set_labels(spec.segments.labels ? *spec.segments.labels : label_table());
            r = seg.render(cam, render_options(spec, m_threads));
            out.segments = seg.stats();
            break;
        }
    }
    out.image = std::move(r.image);
    out.sample_counts = std::move(r.sample_counts);
    out.rgba_float = std::move(r.rgba_float);
    out.stats = r.stats;
    return out;
}

void Session::refine() {
    for (auto& b : m_state->accels) b.accel->refine();
}

void Session::drop_structures() {
    m_state->accels.clear();
    m_state->sources.clear();
    m_state->segments.clear();
    m_state->current_segments = nullptr;
    m_state->adaptive.reset();
    if (m_state->marcher) m_state->marcher->set_accel(nullptr);
    if (m_state->slicer) m_state->slicer->set_box_source(nullptr);
}

const Accel* Session::built_structure(const FrameSpec& spec) const {
    const bool marched =
        spec.renderer == Renderer::RayMarcher ||
        (spec.renderer == Renderer::Segments && spec.segments.mode == SegmentMode::Masked &&
         !std::holds_alternative<structure::LabelOctree>(spec.structure));
    if (!marched) return nullptr;
    for (const auto& b : m_state->accels)
        if (b.structure == spec.structure && b.interpolation == spec.sampling.interpolation)
            return b.accel.get();
    return nullptr;
}

const BoxSource* Session::built_box_source(const FrameSpec& spec) const {
    if (spec.renderer != Renderer::Slicer) return nullptr;
    for (const auto& b : m_state->sources)
        if (b.structure == spec.structure) return b.source.get();
    return nullptr;
}

size_t Session::built_count() const {
    return m_state->accels.size() + m_state->sources.size() + m_state->segments.size();
}

}  // namespace lacuna
