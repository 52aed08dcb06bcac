// FrameSpec's names, the capabilities table and validate() (include/lacuna/frame_spec.h).
#include "lacuna/frame_spec.h"

#include <algorithm>
#include <cmath>

#include "session/structure_registry.h"

namespace lacuna {

std::string to_string(Renderer r) {
    switch (r) {
        case Renderer::RayMarcher:
            return "march";
        case Renderer::Slicer:
            return "slice";
        case Renderer::Segments:
            return "segments";
    }
    return "?";
}

// ---- Structures (the registry: src/session/structure_registry.h) -------------------------------
using registry::kHasOctree;

std::string structure_name(const Structure& s) {
    return registry::entry(s).name;
}

std::optional<AccelKind> accel_kind(const Structure& s) {
    return registry::entry(s).ray;
}

Structure structure_of(AccelKind k, const AccelOptions& o) {
    // The alternative whose registry entry has kind k, its parameters from o (the inverse of
    // accel_options below).
    Structure out = structure::None{};
    [&]<size_t... I>(std::index_sequence<I...>) {
        (
            [&] {
                using T = std::variant_alternative_t<I, Structure>;
                if (registry::kStructures[I].ray != k) return;
                T v{};
                if constexpr (kHasOctree<T>)
                    v.octree = {o.leaf_cells, o.initial_level, o.bidirectional};
                if constexpr (std::is_same_v<T, structure::Bitfield>) v.bits = o.bitfield_bits;
                if constexpr (std::is_same_v<T, structure::Distance> ||
                              std::is_same_v<T, structure::Chebyshev>)
                    v.block = o.distance_block;
                if constexpr (std::is_same_v<T, structure::KdTree>)
                    v = {o.kd_max_boxes, o.kd_delta, o.kd_min_volume, o.kd_min_gain,
                         o.kd_max_depth};
                out = v;
            }(),
            ...);
    }
    (std::make_index_sequence<std::variant_size_v<Structure>>{});
    return out;
}

Structure parse_structure(const std::string& name, Renderer r, const AccelOptions& o,
                          const structure::GrowingBoxes& boxes) {
    const structure::LabelOctree label_octree{o.leaf_cells, o.bitfield_bits};
    if (r == Renderer::Segments && (name == "auto" || name == "bitfield")) return label_octree;
    if (r == Renderer::Slicer && name == "auto") return structure::None{};
    if (name == "auto") return structure_of(default_accel(), o);
    if (name == "boxes") return boxes;
    if (name == "label-octree") return label_octree;
    for (const registry::Entry& e : registry::kStructures)
        if (e.ray && name == e.name) return structure_of(*e.ray, o);
    std::string valid = "auto";
    for (const registry::Entry& e : registry::kStructures) valid += std::string(", ") + e.name;
    throw FrameError("structure", "unknown '" + name + "'; expected one of: " + valid);
}

std::optional<AccelOptions> accel_options(const Structure& s, Interpolation interpolation,
                                          int threads) {
    AccelOptions o;
    o.interpolation = interpolation;
    o.threads = threads;
    std::visit(
        [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (kHasOctree<T>) {
                o.leaf_cells = v.octree.leaf_cells;
                o.initial_level = v.octree.initial_level;
                o.bidirectional = v.octree.bidirectional;
            }
            if constexpr (std::is_same_v<T, structure::Bitfield>) o.bitfield_bits = v.bits;
            if constexpr (std::is_same_v<T, structure::Distance> ||
                          std::is_same_v<T, structure::Chebyshev>)
                o.distance_block = v.block;
            if constexpr (std::is_same_v<T, structure::KdTree>) {
                o.kd_max_boxes = v.max_boxes;
                o.kd_delta = v.delta;
                o.kd_min_volume = v.min_volume;
                o.kd_min_gain = v.min_gain;
                o.kd_max_depth = v.max_depth;
            }
        },
        s);
    if (!registry::entry(s).ray) return std::nullopt;
    return o;
}

std::vector<Structure> all_structures() {
    std::vector<Structure> out;
    [&]<size_t... I>(std::index_sequence<I...>) {
        (out.push_back(std::variant_alternative_t<I, Structure>{}), ...);
    }
    (std::make_index_sequence<std::variant_size_v<Structure>>{});
    return out;
}

// ---- Capabilities -------------------------------------------------------------------------------
std::string to_string(Feature f) {
    switch (f) {
        case Feature::Shading:
            return "shading";
        case Feature::GradientOpacity:
            return "gradient_opacity";
        case Feature::Shadows:
            return "shadows";
        case Feature::ClipPlanes:
            return "clip_planes";
        case Feature::Crop:
            return "crop";
        case Feature::Blend:
            return "blend";
        case Feature::Jitter:
            return "jitter";
        case Feature::TwoTfs:
            return "two_tfs";
        case Feature::Nearest:
            return "nearest";
        case Feature::EarlyTermination:
            return "early_termination";
        case Feature::SampleCounts:
            return "sample_counts";
        case Feature::Occlusion:
            return "occlusion";
    }
    return "?";
}

std::vector<Feature> all_features() {
    return {Feature::Shading,      Feature::GradientOpacity,
            Feature::Shadows,      Feature::ClipPlanes,
            Feature::Crop,         Feature::Blend,
            Feature::Jitter,       Feature::TwoTfs,
            Feature::Nearest,      Feature::EarlyTermination,
            Feature::SampleCounts, Feature::Occlusion};
}

bool RendererCapabilities::takes(const Structure& s) const {
    const std::string n = structure_name(s);
    return std::find(structures.begin(), structures.end(), n) != structures.end();
}

bool RendererCapabilities::has(Feature f) const {
    return std::find(features.begin(), features.end(), f) != features.end();
}

// The table. Why each row is what it is:
//   ray marcher  the structures with a ray face (the cursor interface, src/accel/cursor.h) and
//                every feature of the feature kernel.
//   slicer       the structures with a box face (src/slice/box_sources.h); it composites TF colour
//                and opacity on planes, so no gradient features, clipping or other blend modes.
//   segments     the label octree, or (mask mode) any ray structure through set_accel: exact,
//                since the mask only lowers opacities. No features of the feature kernel.
const std::vector<RendererCapabilities>& capabilities() {
    static const std::vector<RendererCapabilities> table = [] {
        std::vector<std::string> ray, boxes, segments, intensity;
        for (const registry::Entry& e : registry::kStructures) {
            if (e.ray) ray.push_back(e.name);
            if (e.boxes()) boxes.push_back(e.name);
            if (e.ray && *e.ray != AccelKind::None) intensity.push_back(e.name);
            if (e.labels || e.ray) segments.push_back(e.name);
        }
        return std::vector<RendererCapabilities>{
            {Renderer::RayMarcher,
             ray,
             {Feature::Shading, Feature::GradientOpacity, Feature::Shadows, Feature::ClipPlanes,
              Feature::Crop, Feature::Blend, Feature::Jitter, Feature::TwoTfs, Feature::Nearest,
              Feature::EarlyTermination, Feature::SampleCounts},
             {}},
            {Renderer::Slicer,
             boxes,
             {Feature::Nearest, Feature::EarlyTermination, Feature::Occlusion},
             {}},
            {Renderer::Segments,
             segments,
             {Feature::Nearest, Feature::EarlyTermination, Feature::SampleCounts},
             intensity},
        };
    }();
    return table;
}

const RendererCapabilities& capabilities(Renderer r) {
    return capabilities()[size_t(r)];
}

// ---- A TF's rendering ---------------------------------------------------------------------------
void apply_tf_rendering(const TfRendering& r, FrameSpec& spec, const TfRenderingOverrides& given) {
    const RendererCapabilities& caps = capabilities(spec.renderer);
    FeatureOptions& f = spec.features;
    if (r.shading && caps.has(Feature::Shading)) {
        if (!given.shading) f.shading = ShadingModel::Phong;
        if (!given.phong)
            f.phong = {r.shading->ambient, r.shading->diffuse, r.shading->specular,
                       r.shading->specular_power};
    }
    const bool identity = std::all_of(r.gradient_opacity.begin(), r.gradient_opacity.end(),
                                      [](const OpacityPoint& p) { return p.a == 1.f; });
    if (!identity && !given.gradient_opacity && caps.has(Feature::GradientOpacity)) {
        f.gradient_opacity = {};
        f.gradient_opacity.enabled = true;
        for (const OpacityPoint& p : r.gradient_opacity)
            f.gradient_opacity.points.push_back({float(p.x), p.a});
    }
    if (r.blend && !given.blend && caps.has(Feature::Blend)) f.blend = *r.blend;
}

// ---- Validation ---------------------------------------------------------------------------------
namespace {

[[noreturn]] void fail(const std::string& field, const std::string& expected) {
    throw FrameError(field, expected);
}

bool finite(float v) {
    return std::isfinite(v);
}

// The features a spec uses, each with the field that switches it on.
std::vector<std::pair<Feature, const char*>> used_features(const FrameSpec& s) {
    std::vector<std::pair<Feature, const char*>> out;
    const FeatureOptions& f = s.features;
    if (f.shading != ShadingModel::None) out.push_back({Feature::Shading, "features.shading"});
    if (f.gradient_opacity.enabled)
        out.push_back({Feature::GradientOpacity, "features.gradient_opacity"});
    if (f.shadows.enabled) out.push_back({Feature::Shadows, "features.shadows"});
    if (!f.clip_planes.empty()) out.push_back({Feature::ClipPlanes, "features.clip_planes"});
    if (f.crop) out.push_back({Feature::Crop, "features.crop"});
    if (f.blend != BlendMode::Composite) out.push_back({Feature::Blend, "features.blend"});
    if (f.jitter) out.push_back({Feature::Jitter, "features.jitter"});
    if (s.two_tfs) out.push_back({Feature::TwoTfs, "two_tfs"});
    if (s.sampling.interpolation == Interpolation::Nearest)
        out.push_back({Feature::Nearest, "sampling.interpolation"});
    if (s.sampling.early_termination)
        out.push_back({Feature::EarlyTermination, "sampling.early_termination"});
    if (s.count_samples) out.push_back({Feature::SampleCounts, "count_samples"});
    if (s.slicer.occlusion) out.push_back({Feature::Occlusion, "slicer.occlusion"});
    return out;
}

void validate_structure(const Structure& st) {
    std::visit(
        [](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            auto leaf = [](int l, const char* field) {
                if (l < 2 || l > 64 || (l & (l - 1)) != 0)
                    fail(field, "expected a power of two in 2..64, got " + std::to_string(l));
            };
            auto bits = [](int b, const char* field) {
                if (b != 8 && b != 16 && b != 32 && b != 64 && b != 128)
                    fail(field, "expected 8, 16, 32, 64 or 128, got " + std::to_string(b));
            };
            if constexpr (kHasOctree<T>) leaf(v.octree.leaf_cells, "structure.octree.leaf_cells");
            if constexpr (std::is_same_v<T, structure::Bitfield>) bits(v.bits, "structure.bits");
            if constexpr (std::is_same_v<T, structure::LabelOctree>) {
                leaf(v.leaf_cells, "structure.leaf_cells");
                bits(v.bits, "structure.bits");
            }
            if constexpr (std::is_same_v<T, structure::Distance> ||
                          std::is_same_v<T, structure::Chebyshev>)
                if (v.block < 1 || v.block > 64) fail("structure.block", "expected 1..64 cells");
            if constexpr (std::is_same_v<T, structure::KdTree>) {  // kd_settings' ranges
                if (v.max_boxes < 0) fail("structure.max_boxes", "expected >= 0 (0 = every leaf)");
                if (v.delta < 0) fail("structure.delta", "expected >= 1 cells (0 = from the size)");
                if (!(v.min_volume >= 0.f && v.min_volume <= 1.f))
                    fail("structure.min_volume", "expected a fraction in 0..1");
                if (!(v.min_gain >= 0.f && v.min_gain <= 1.f))
                    fail("structure.min_gain", "expected a fraction in 0..1");
                if (v.max_depth < 0 || v.max_depth > 64)
                    fail("structure.max_depth", "expected 0..64");
            }
            if constexpr (std::is_same_v<T, structure::GrowingBoxes>) {  // validate(BoxesOptions)'s
                if (!(v.coalesce <= 1.f))
                    fail("structure.coalesce", "expected a share <= 1 (negative: off)");
                if (!(v.coalesce_edge > 0.f))
                    fail("structure.coalesce_edge", "expected a length > 0 (mm)");
            }
        },
        st);
}

}  // namespace

void validate(const FrameSpec& s) {
    // 1. The image and the camera.
    if (s.width < 1 || s.width > 16384) fail("width", "expected 1..16384 pixels");
    if (s.height < 1 || s.height > 16384) fail("height", "expected 1..16384 pixels");
    const OrbitParams& o = s.camera.orbit;
    if (!(o.zoom > 0.f && o.zoom <= 1000.f)) fail("camera.orbit.zoom", "expected 0 < zoom <= 1000");
    if (!(o.fov_y_deg > 0.f && o.fov_y_deg < 180.f))
        fail("camera.orbit.fov_y_deg", "expected 0 < degrees < 180");
    if (!finite(o.azimuth_deg) || !finite(o.elevation_deg))
        fail("camera.orbit", "expected finite azimuth and elevation degrees");
    if (!finite(s.camera.pan_x) || !finite(s.camera.pan_y))
        fail("camera.pan", "expected finite numbers");
    if (o.up != Vec3f{0, 0, 1}) {  // the superior default has its own fallback (Camera::orbit)
        const float n = length(o.up);
        if (!finite(o.up.x) || !finite(o.up.y) || !finite(o.up.z) || !(n > 0.f) || !finite(n))
            fail("camera.orbit.up", "expected a finite non-zero direction");
        // Camera::orbit's direction to the eye; up must leave a view plane component.
        const float az = o.azimuth_deg * float(M_PI) / 180.f,
                    el = o.elevation_deg * float(M_PI) / 180.f;
        const Vec3f to_eye{-std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)};
        if (std::abs(dot(o.up, to_eye)) > 0.999f * n)
            fail("camera.orbit.up", "expected a direction not parallel to the view direction");
    }
    for (float c : {s.background.x, s.background.y, s.background.z})
        if (!(c >= 0.f && c <= 1.f)) fail("background", "expected R, G, B in [0, 1]");
    // 2. Sampling.
    if (!(s.sampling.step > 0.f && s.sampling.step <= 64.f))
        fail("sampling.step", "expected 0 < step <= 64");
    if (s.sampling.early_termination &&
        !(*s.sampling.early_termination > 0.f && *s.sampling.early_termination < 1.f))
        fail("sampling.early_termination", "expected an opacity in (0, 1), or none (off)");
    // 3. The structure: taken by the renderer, its parameters in range.
    const RendererCapabilities& cap = capabilities(s.renderer);
    if (!cap.takes(s.structure)) {
        std::string names;
        for (const std::string& n : cap.structures) names += (names.empty() ? "" : ", ") + n;
        fail("structure", "the " + to_string(s.renderer) + " renderer takes " + names + ", not '" +
                              structure_name(s.structure) + "'");
    }
    if (s.renderer == Renderer::Segments && s.segments.mode == SegmentMode::Labels) {
        const auto& m = cap.masked_only_structures;
        if (std::find(m.begin(), m.end(), structure_name(s.structure)) != m.end())
            fail("structure", "the label volume alone takes none or label-octree, not '" +
                                  structure_name(s.structure) + "'");
    }
    validate_structure(s.structure);
    // 4. Features: each one the renderer has, in range.
    for (const auto& [feature, field] : used_features(s))
        if (!cap.has(feature))
            fail(field, "the " + to_string(s.renderer) + " renderer has no " + to_string(feature));
    if (s.two_tfs && s.features.clip_planes.empty())
        fail("two_tfs", "expected a clip plane to split the two TFs at");
    validate_features(s.features);  // its FrameErrors name "features.phong" ... itself
    // 5. The slicer's and the segments' own options.
    if (s.renderer == Renderer::Slicer) {
        if (!(s.slicer.occlusion_threshold > 0.f && s.slicer.occlusion_threshold <= 1.f))
            fail("slicer.occlusion_threshold", "expected 0 < T <= 1");
        if (s.slicer.occlusion_map < 1 || s.slicer.occlusion_map > 4096)
            fail("slicer.occlusion_map", "expected 1..4096 cells");
        if (s.slicer.occlusion_updates < 0)
            fail("slicer.occlusion_updates", "expected >= 0 map updates per frame");
    }
    if (s.renderer == Renderer::Segments && !(s.segments.tint >= 0.f && s.segments.tint <= 1.f))
        fail("segments.tint", "expected a number in [0,1]");
}

}  // namespace lacuna
