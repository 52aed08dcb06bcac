#include "session/session_file.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "lacuna/error.h"

namespace lacuna {

namespace {

using json = nlohmann::json;

// ---- Names of the enums, one table each, both directions ---------------------------------------
template <class E>
using Names = std::initializer_list<std::pair<E, const char*>>;

const Names<Renderer> kRenderers = {{Renderer::RayMarcher, "raymarcher"},
                                    {Renderer::Slicer, "slicer"},
                                    {Renderer::Segments, "segments"}};
const Names<SegmentMode> kSegmentModes = {{SegmentMode::Masked, "masked"},
                                          {SegmentMode::Labels, "labels"}};
const Names<Interpolation> kInterpolations = {{Interpolation::Trilinear, "trilinear"},
                                              {Interpolation::Nearest, "nearest"}};
const Names<ShadingModel> kShadings = {
    {ShadingModel::None, "none"}, {ShadingModel::Phong, "phong"}, {ShadingModel::Pbr, "pbr"}};
const Names<GradientSource> kGradients = {{GradientSource::OnTheFly, "on-the-fly"},
                                          {GradientSource::Precomputed, "precomputed"}};
const Names<LightKind> kLights = {
    {LightKind::Head, "head"}, {LightKind::Directional, "directional"}, {LightKind::Spot, "spot"}};
const Names<BlendMode> kBlends = {{BlendMode::Composite, "composite"},
                                  {BlendMode::Mip, "mip"},
                                  {BlendMode::MinIp, "minip"},
                                  {BlendMode::Average, "average"}};
const Names<Projection> kProjections = {{Projection::Perspective, "perspective"},
                                        {Projection::Orthographic, "orthographic"}};
const Names<OcclusionUse> kOcclusionUses = {{OcclusionUse::CullClip, "cull-clip"},
                                            {OcclusionUse::CullOnly, "cull-only"},
                                            {OcclusionUse::MapOnly, "map-only"}};

template <class E>
const char* name_of(const Names<E>& names, E e) {
    for (const auto& [v, n] : names)
        if (v == e) return n;
    return "?";
}

// ---- Writing ------------------------------------------------------------------------------------
json vec(const Vec3f& v) {
    return json::array({v.x, v.y, v.z});
}

json octree_json(const structure::Octree& o) {
    return {{"leaf_cells", o.leaf_cells},
            {"initial_level", o.initial_level},
            {"bidirectional", o.bidirectional}};
}

json structure_json(const Structure& s) {
    json j = std::visit(
        [](const auto& st) -> json {
            using T = std::decay_t<decltype(st)>;
            if constexpr (std::is_same_v<T, structure::MinMax> ||
                          std::is_same_v<T, structure::MinMaxInterval> ||
                          std::is_same_v<T, structure::Boolean>)
                return octree_json(st.octree);
            else if constexpr (std::is_same_v<T, structure::Bitfield>) {
                json o = octree_json(st.octree);
                o["bits"] = st.bits;
                return o;
            } else if constexpr (std::is_same_v<T, structure::Distance> ||
                                 std::is_same_v<T, structure::Chebyshev>)
                return {{"block", st.block}};
            else if constexpr (std::is_same_v<T, structure::KdTree>)
                return {{"max_boxes", st.max_boxes},
                        {"delta", st.delta},
                        {"min_volume", st.min_volume},
                        {"min_gain", st.min_gain},
                        {"max_depth", st.max_depth}};
            else if constexpr (std::is_same_v<T, structure::GrowingBoxes>)
                return {{"coalesce", st.coalesce}, {"coalesce_edge", st.coalesce_edge}};
            else if constexpr (std::is_same_v<T, structure::LabelOctree>)
                return {{"leaf_cells", st.leaf_cells}, {"bits", st.bits}};
            else
                return json::object();  // None, Grid: no parameters
        },
        s);
    j["name"] = structure_name(s);
    return j;
}

// The ramp as it always was ({"enabled", "lo", "hi"}: files without points keep their bytes);
// piecewise-linear factors add "points": [[x, a], ...].
json gradient_opacity_json(const GradientOpacity& g) {
    json j = {{"enabled", g.enabled}, {"lo", g.lo}, {"hi", g.hi}};
    if (!g.points.empty()) {
        json pts = json::array();
        for (const GradientOpacityPoint& p : g.points) pts.push_back(json::array({p.x, p.a}));
        j["points"] = pts;
    }
    return j;
}

json features_json(const FeatureOptions& f) {
    json planes = json::array();
    for (const ClipPlane& p : f.clip_planes)
        planes.push_back({{"normal", vec(p.normal)}, {"d", p.d}});
    return {
        {"shading", name_of(kShadings, f.shading)},
        {"phong",
         {{"ambient", f.phong.ambient},
          {"diffuse", f.phong.diffuse},
          {"specular", f.phong.specular},
          {"power", f.phong.power}}},
        {"pbr",
         {{"roughness", f.pbr.roughness},
          {"metallic", f.pbr.metallic},
          {"ambient", f.pbr.ambient}}},
        {"gradient", name_of(kGradients, f.gradient)},
        {"gradient_opacity", gradient_opacity_json(f.gradient_opacity)},
        {"light",
         {{"kind", name_of(kLights, f.light.kind)},
          {"direction", vec(f.light.direction)},
          {"position", vec(f.light.position)},
          {"target", vec(f.light.target)},
          {"cone_deg", f.light.cone_deg},
          {"intensity", f.light.intensity}}},
        {"shadows",
         {{"enabled", f.shadows.enabled},
          {"accelerate", f.shadows.accelerate},
          {"step", f.shadows.step},
          {"light_volume", f.shadows.light_volume},
          {"light_volume_stride", f.shadows.light_volume_stride}}},
        {"clip_planes", planes},
        {"crop", f.crop},
        {"crop_box", {{"lo", vec(f.crop_box.lo)}, {"hi", vec(f.crop_box.hi)}}},
        {"blend", name_of(kBlends, f.blend)},
        {"jitter", f.jitter},
        {"jitter_seed", f.jitter_seed},
    };
}

// The segment renderer's part of a frame (written for its frames only, so other sessions keep
// their bytes): mode, tint, and the label table when the frame carries one (null: the session's
// default table).
json segments_json(const SegmentsSpec& s) {
    json table(nullptr);
    if (s.labels) {
        table = json::array();
        for (const LabelStyle& l : s.labels->styles)
            table.push_back({{"name", l.name},
                             {"color", json::array({l.r, l.g, l.b})},
                             {"opacity", l.opacity},
                             {"visible", l.visible}});
    }
    return {{"mode", name_of(kSegmentModes, s.mode)}, {"tint", s.tint}, {"table", table}};
}

json frame_json(const FrameSpec& f) {
    const OrbitParams& o = f.camera.orbit;
    json j = {
        {"renderer", name_of(kRenderers, f.renderer)},
        {"structure", structure_json(f.structure)},
        {"sampling",
         {{"step", f.sampling.step},
          {"early_termination",
           f.sampling.early_termination ? json(*f.sampling.early_termination) : json(nullptr)},
          {"interpolation", name_of(kInterpolations, f.sampling.interpolation)}}},
        {"features", features_json(f.features)},
        {"two_tfs", f.two_tfs},
        {"slicer",
         {{"occlusion", f.slicer.occlusion},
          {"occlusion_threshold", f.slicer.occlusion_threshold},
          {"occlusion_map", f.slicer.occlusion_map},
          {"occlusion_use", name_of(kOcclusionUses, f.slicer.occlusion_use)},
          {"occlusion_updates", f.slicer.occlusion_updates},
          {"adaptive_updates", f.slicer.adaptive_updates}}},
        {"camera",
         {{"azimuth_deg", o.azimuth_deg},
          {"elevation_deg", o.elevation_deg},
          {"zoom", o.zoom},
          {"distance", o.distance},
          {"target", o.has_target ? vec(o.target) : json(nullptr)},
          {"up", vec(o.up)},
          {"fov_y_deg", o.fov_y_deg},
          {"projection", name_of(kProjections, o.projection)},
          {"pan_x", f.camera.pan_x},
          {"pan_y", f.camera.pan_y}}},
        {"width", f.width},
        {"height", f.height},
        {"background", vec(f.background)},
        {"count_samples", f.count_samples},
    };
    if (f.renderer == Renderer::Segments) j["segments"] = segments_json(f.segments);
    return j;
}

// ---- Reading: each value through one of these, which name the field on a mismatch ------------
class Reader {
  public:
    Reader(const json& j, std::string field, const std::string& where)
        : m_j(j), m_field(std::move(field)), m_where(where) {}

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw Error(m_where, field, what);
    }
    std::string sub(const std::string& key) const {
        return m_field.empty() ? key : m_field + "." + key;
    }

    // The object's keys must all be in `known`.
    void expect_object(std::initializer_list<const char*> known) const {
        if (!m_j.is_object())
            fail(m_field, std::string("expected an object, got ") + m_j.type_name());
        for (const auto& [k, v] : m_j.items()) {
            bool ok = false;
            for (const char* n : known) ok = ok || k == n;
            if (!ok) {
                std::string list;
                for (const char* n : known) list += (list.empty() ? "" : ", ") + std::string(n);
                fail(sub(k), "unknown key (expected one of: " + list + ")");
            }
        }
    }
    bool has(const char* key) const { return m_j.contains(key); }
    bool is_null(const char* key) const { return m_j.contains(key) && m_j.at(key).is_null(); }
    Reader at(const char* key) const {
        if (!m_j.contains(key)) fail(sub(key), "missing");
        return Reader(m_j.at(key), sub(key), m_where);
    }
    const json& value() const { return m_j; }
    const std::string& field() const { return m_field; }
    const std::string& where() const { return m_where; }

    // Each reads `key` into `v` when present (absent: `v` keeps its default).
    void get(const char* key, float& v) const {
        if (!has(key)) return;
        const json& x = m_j.at(key);
        if (!x.is_number()) fail(sub(key), std::string("expected a number, got ") + x.type_name());
        const double d = x.get<double>();
        if (!(d >= -3.4028234663852886e38 && d <= 3.4028234663852886e38))
            fail(sub(key), "expected a finite float");
        v = float(d);
    }
    void get(const char* key, int& v) const {
        if (!has(key)) return;
        const json& x = m_j.at(key);
        if (!x.is_number_integer() || x.get<int64_t>() < -2147483647 - 1 ||
            x.get<int64_t>() > 2147483647)
            fail(sub(key), std::string("expected an integer, got ") + x.dump());
        v = int(x.get<int64_t>());
    }
    void get(const char* key, uint32_t& v) const {
        if (!has(key)) return;
        const json& x = m_j.at(key);
        if (!x.is_number_integer() || x.get<int64_t>() < 0 || x.get<int64_t>() > 4294967295LL)
            fail(sub(key), std::string("expected an integer 0..4294967295, got ") + x.dump());
        v = uint32_t(x.get<int64_t>());
    }
    void get(const char* key, bool& v) const {
        if (!has(key)) return;
        const json& x = m_j.at(key);
        if (!x.is_boolean()) fail(sub(key), std::string("expected true or false, got ") + x.dump());
        v = x.get<bool>();
    }
    void get(const char* key, Vec3f& v) const {
        if (!has(key)) return;
        const Reader r = at(key);
        if (!r.value().is_array() || r.value().size() != 3)
            fail(r.field(), "expected an array of three numbers, got " + r.value().dump());
        for (int i = 0; i < 3; ++i) {
            const json& x = r.value()[size_t(i)];
            if (!x.is_number()) fail(r.field(), "expected numbers, got " + x.dump());
            v[i] = float(x.get<double>());
        }
    }
    std::string text(const char* key) const {
        const json& x = at(key).value();
        if (!x.is_string()) fail(sub(key), std::string("expected a string, got ") + x.dump());
        return x.get<std::string>();
    }
    template <class E>
    void get(const char* key, E& v, const Names<E>& names) const {
        if (!has(key)) return;
        const std::string s = text(key);
        std::string list;
        for (const auto& [e, n] : names) {
            if (s == n) {
                v = e;
                return;
            }
            list += (list.empty() ? "" : ", ") + std::string(n);
        }
        fail(sub(key), "expected one of " + list + ", got '" + s + "'");
    }

  private:
    const json& m_j;
    std::string m_field;
    const std::string& m_where;
};

void read_octree(const Reader& r, structure::Octree& o) {
    r.get("leaf_cells", o.leaf_cells);
    r.get("initial_level", o.initial_level);
    r.get("bidirectional", o.bidirectional);
}

Structure read_structure(const Reader& r, Renderer renderer) {
    if (!r.value().is_object()) r.expect_object({});
    const std::string name = r.text("name");
    Structure s;
    try {
        // Label octree and growing boxes are names parse_structure takes for their renderers.
        s = name == "label-octree" ? Structure{structure::LabelOctree{}}
                                   : parse_structure(name, renderer);
    } catch (const FrameError& e) {
        r.fail(r.sub("name"), e.expected());
    }
    std::visit(
        [&](auto& st) {
            using T = std::decay_t<decltype(st)>;
            if constexpr (std::is_same_v<T, structure::MinMax> ||
                          std::is_same_v<T, structure::MinMaxInterval> ||
                          std::is_same_v<T, structure::Boolean>) {
                r.expect_object({"name", "leaf_cells", "initial_level", "bidirectional"});
                read_octree(r, st.octree);
            } else if constexpr (std::is_same_v<T, structure::Bitfield>) {
                r.expect_object({"name", "leaf_cells", "initial_level", "bidirectional", "bits"});
                read_octree(r, st.octree);
                r.get("bits", st.bits);
            } else if constexpr (std::is_same_v<T, structure::Distance> ||
                                 std::is_same_v<T, structure::Chebyshev>) {
                r.expect_object({"name", "block"});
                r.get("block", st.block);
            } else if constexpr (std::is_same_v<T, structure::KdTree>) {
                r.expect_object(
                    {"name", "max_boxes", "delta", "min_volume", "min_gain", "max_depth"});
                r.get("max_boxes", st.max_boxes);
                r.get("delta", st.delta);
                r.get("min_volume", st.min_volume);
                r.get("min_gain", st.min_gain);
                r.get("max_depth", st.max_depth);
            } else if constexpr (std::is_same_v<T, structure::GrowingBoxes>) {
                r.expect_object({"name", "coalesce", "coalesce_edge"});
                r.get("coalesce", st.coalesce);
                r.get("coalesce_edge", st.coalesce_edge);
            } else if constexpr (std::is_same_v<T, structure::LabelOctree>) {
                r.expect_object({"name", "leaf_cells", "bits"});
                r.get("leaf_cells", st.leaf_cells);
                r.get("bits", st.bits);
            } else {
                r.expect_object({"name"});
            }
        },
        s);
    return s;
}

FeatureOptions read_features(const Reader& r) {
    r.expect_object({"shading", "phong", "pbr", "gradient", "gradient_opacity", "light", "shadows",
                     "clip_planes", "crop", "crop_box", "blend", "jitter", "jitter_seed"});
    FeatureOptions f;
    r.get("shading", f.shading, kShadings);
    if (r.has("phong")) {
        const Reader p = r.at("phong");
        p.expect_object({"ambient", "diffuse", "specular", "power"});
        p.get("ambient", f.phong.ambient);
        p.get("diffuse", f.phong.diffuse);
        p.get("specular", f.phong.specular);
        p.get("power", f.phong.power);
    }
    if (r.has("pbr")) {
        const Reader p = r.at("pbr");
        p.expect_object({"roughness", "metallic", "ambient"});
        p.get("roughness", f.pbr.roughness);
        p.get("metallic", f.pbr.metallic);
        p.get("ambient", f.pbr.ambient);
    }
    r.get("gradient", f.gradient, kGradients);
    if (r.has("gradient_opacity")) {
        const Reader g = r.at("gradient_opacity");
        g.expect_object({"enabled", "lo", "hi", "points"});
        g.get("enabled", f.gradient_opacity.enabled);
        g.get("lo", f.gradient_opacity.lo);
        g.get("hi", f.gradient_opacity.hi);
        if (g.has("points")) {
            // [[x, a], ...]; their order and ranges are validate()'s (features.gradient_opacity).
            const Reader p = g.at("points");
            const json& a = p.value();
            if (!a.is_array() || a.empty())
                p.fail(p.field(), "expected a non-empty array of [x, a] points, got " + a.dump());
            for (size_t i = 0; i < a.size(); ++i) {
                const json& q = a[i];
                const std::string field = p.field() + "[" + std::to_string(i) + "]";
                if (!q.is_array() || q.size() != 2 || !q[0].is_number() || !q[1].is_number())
                    p.fail(field, "expected [x, a] (two numbers), got " + q.dump());
                const double x = q[0].get<double>(), v = q[1].get<double>();
                if (!(std::abs(x) <= 3.4028234663852886e38 && std::abs(v) <= 3.4028234663852886e38))
                    p.fail(field, "expected finite floats, got " + q.dump());
                f.gradient_opacity.points.push_back({float(x), float(v)});
            }
        }
    }
    if (r.has("light")) {
        const Reader l = r.at("light");
        l.expect_object({"kind", "direction", "position", "target", "cone_deg", "intensity"});
        l.get("kind", f.light.kind, kLights);
        l.get("direction", f.light.direction);
        l.get("position", f.light.position);
        l.get("target", f.light.target);
        l.get("cone_deg", f.light.cone_deg);
        l.get("intensity", f.light.intensity);
    }
    if (r.has("shadows")) {
        const Reader s = r.at("shadows");
        s.expect_object({"enabled", "accelerate", "step", "light_volume", "light_volume_stride"});
        s.get("enabled", f.shadows.enabled);
        s.get("accelerate", f.shadows.accelerate);
        s.get("step", f.shadows.step);
        s.get("light_volume", f.shadows.light_volume);
        s.get("light_volume_stride", f.shadows.light_volume_stride);
    }
    if (r.has("clip_planes")) {
        const Reader c = r.at("clip_planes");
        if (!c.value().is_array()) c.fail(c.field(), "expected an array of planes");
        if (c.value().size() > 64) c.fail(c.field(), "expected at most 64 planes");
        for (size_t i = 0; i < c.value().size(); ++i) {
            const Reader pr(c.value()[i], c.field() + "[" + std::to_string(i) + "]", r.where());
            pr.expect_object({"normal", "d"});
            ClipPlane plane;
            pr.get("normal", plane.normal);
            pr.get("d", plane.d);
            f.clip_planes.push_back(plane);
        }
    }
    r.get("crop", f.crop);
    if (r.has("crop_box")) {
        const Reader b = r.at("crop_box");
        b.expect_object({"lo", "hi"});
        b.get("lo", f.crop_box.lo);
        b.get("hi", f.crop_box.hi);
    }
    r.get("blend", f.blend, kBlends);
    r.get("jitter", f.jitter);
    r.get("jitter_seed", f.jitter_seed);
    return f;
}

SegmentsSpec read_segments(const Reader& r) {
    r.expect_object({"mode", "tint", "table"});
    SegmentsSpec s;
    r.get("mode", s.mode, kSegmentModes);
    r.get("tint", s.tint);
    if (r.has("table") && !r.is_null("table")) {
        const Reader t = r.at("table");
        if (!t.value().is_array() || t.value().size() > size_t(kMaxLabel) + 1)
            r.fail(t.field(), "expected an array of at most " + std::to_string(kMaxLabel + 1) +
                                  " label styles");
        LabelTable table;
        for (size_t i = 0; i < t.value().size(); ++i) {
            const Reader e(t.value()[i], t.field() + "[" + std::to_string(i) + "]", r.where());
            e.expect_object({"name", "color", "opacity", "visible"});
            LabelStyle l;
            if (e.has("name")) l.name = e.text("name");
            Vec3f c{l.r, l.g, l.b};
            e.get("color", c);
            l.r = c.x, l.g = c.y, l.b = c.z;
            e.get("opacity", l.opacity);
            if (!(l.opacity >= 0.f)) e.fail(e.sub("opacity"), "expected a number >= 0");
            e.get("visible", l.visible);
            table.styles.push_back(std::move(l));
        }
        s.labels = std::move(table);
    }
    return s;
}

FrameSpec read_frame(const Reader& r) {
    r.expect_object({"renderer", "structure", "sampling", "features", "two_tfs", "slicer", "camera",
                     "width", "height", "background", "count_samples", "segments"});
    FrameSpec f;
    r.get("renderer", f.renderer, kRenderers);
    if (r.has("segments")) {
        if (f.renderer != Renderer::Segments)
            r.fail(r.sub("segments"), "given, but the renderer is not segments");
        f.segments = read_segments(r.at("segments"));
    }
    if (r.has("structure")) f.structure = read_structure(r.at("structure"), f.renderer);
    if (r.has("sampling")) {
        const Reader s = r.at("sampling");
        s.expect_object({"step", "early_termination", "interpolation"});
        s.get("step", f.sampling.step);
        if (s.is_null("early_termination")) {
            f.sampling.early_termination = std::nullopt;
        } else if (s.has("early_termination")) {
            float e = 0;
            s.get("early_termination", e);
            f.sampling.early_termination = e;
        }
        s.get("interpolation", f.sampling.interpolation, kInterpolations);
    }
    if (r.has("features")) f.features = read_features(r.at("features"));
    r.get("two_tfs", f.two_tfs);
    if (r.has("slicer")) {
        const Reader s = r.at("slicer");
        s.expect_object({"occlusion", "occlusion_threshold", "occlusion_map", "occlusion_use",
                         "occlusion_updates", "adaptive_updates"});
        s.get("occlusion", f.slicer.occlusion);
        s.get("occlusion_threshold", f.slicer.occlusion_threshold);
        s.get("occlusion_map", f.slicer.occlusion_map);
        s.get("occlusion_use", f.slicer.occlusion_use, kOcclusionUses);
        s.get("occlusion_updates", f.slicer.occlusion_updates);
        s.get("adaptive_updates", f.slicer.adaptive_updates);
    }
    if (r.has("camera")) {
        const Reader c = r.at("camera");
        c.expect_object({"azimuth_deg", "elevation_deg", "zoom", "distance", "target", "up",
                         "fov_y_deg", "projection", "pan_x", "pan_y"});
        OrbitParams& o = f.camera.orbit;
        c.get("azimuth_deg", o.azimuth_deg);
        c.get("elevation_deg", o.elevation_deg);
        c.get("zoom", o.zoom);
        c.get("distance", o.distance);
        o.has_target = c.has("target") && !c.is_null("target");
        if (o.has_target) c.get("target", o.target);
        c.get("up", o.up);
        c.get("fov_y_deg", o.fov_y_deg);
        c.get("projection", o.projection, kProjections);
        c.get("pan_x", f.camera.pan_x);
        c.get("pan_y", f.camera.pan_y);
    }
    r.get("width", f.width);
    r.get("height", f.height);
    r.get("background", f.background);
    r.get("count_samples", f.count_samples);
    return f;
}

SessionVolume read_volume_entry(const Reader& r) {
    r.expect_object({"path", "frame", "range", "raw"});
    SessionVolume v;
    v.path = r.text("path");
    if (v.path.empty()) r.fail(r.sub("path"), "expected a volume file name, got an empty string");
    if (r.has("frame")) {
        const json& x = r.at("frame").value();
        if (!x.is_number_integer() || x.get<int64_t>() < 0)
            r.fail(r.sub("frame"), "expected a volume index >= 0, got " + x.dump());
        v.frame = x.get<int64_t>();
    }
    if (r.has("range")) {
        const Reader g = r.at("range");
        const json& x = g.value();
        if (!x.is_array() || x.size() != 2 || !x[0].is_number() || !x[1].is_number())
            g.fail(g.field(), "expected [min, max], got " + x.dump());
        v.range = ValueRange{float(x[0].get<double>()), float(x[1].get<double>())};
    }
    if (r.has("raw")) {
        const Reader w = r.at("raw");
        w.expect_object({"dims", "type", "spacing", "big_endian"});
        RawSpec raw;
        const json& d = w.at("dims").value();
        if (!d.is_array() || d.size() != 3)
            w.fail(w.sub("dims"), "expected [x, y, z], got " + d.dump());
        for (int i = 0; i < 3; ++i) {
            if (!d[size_t(i)].is_number_integer() || d[size_t(i)].get<int64_t>() < 1 ||
                d[size_t(i)].get<int64_t>() > 1000000000)
                w.fail(w.sub("dims"), "expected three positive integers, got " + d.dump());
            raw.dims[i] = int(d[size_t(i)].get<int64_t>());
        }
        try {
            raw.type = parse_voxel_type(w.text("type"), w.sub("type"));
        } catch (const Error& e) {
            throw Error(r.where() + ": " + e.what());
        }
        if (w.has("spacing")) {
            const json& sp = w.at("spacing").value();
            if (!sp.is_array() || sp.size() != 3)
                w.fail(w.sub("spacing"), "expected [x, y, z] in mm, got " + sp.dump());
            for (int i = 0; i < 3; ++i) {
                if (!sp[size_t(i)].is_number() || !(sp[size_t(i)].get<double>() > 0))
                    w.fail(w.sub("spacing"), "expected three positive numbers, got " + sp.dump());
                raw.spacing[i] = sp[size_t(i)].get<double>();
            }
        }
        w.get("big_endian", raw.big_endian);
        v.raw = raw;
    }
    return v;
}

TransferFunction read_tf(const Reader& r) {
    // The lacuna TF JSON parser names its own fields; the session names where the TF sits.
    return parse_transfer_function(r.value().dump(), r.where() + ": " + r.field());
}

// Labels belong to (and are needed by) exactly the segment renderer's mask mode.
void check_labels(const SessionFile& s, const std::string& where) {
    const bool needs =
        s.frame.renderer == Renderer::Segments && s.frame.segments.mode == SegmentMode::Masked;
    if (needs && (!s.labels || s.labels->empty()))
        throw Error(where, "labels",
                    "missing (frame.renderer is segments in mask mode: the frame "
                    "needs the label volume's path)");
    if (!needs && s.labels)
        throw Error(where, "labels", "given, but only the segment renderer's mask mode reads one");
}

}  // namespace

std::string to_json(const SessionFile& s, const std::string& where) {
    check_labels(s, where);
    json vol = {{"path", s.volume.path}};
    if (s.volume.frame) vol["frame"] = *s.volume.frame;
    if (s.volume.range) vol["range"] = json::array({s.volume.range->min, s.volume.range->max});
    if (s.volume.raw) {
        const RawSpec& r = *s.volume.raw;
        vol["raw"] = {{"dims", json::array({r.dims.x, r.dims.y, r.dims.z})},
                      {"type", to_string(r.type)},
                      {"spacing", json::array({r.spacing.x, r.spacing.y, r.spacing.z})},
                      {"big_endian", r.big_endian}};
    }
    json j = {{"lacuna_session", kSessionFileVersion},
              {"volume", vol},
              {"tf", json::parse(to_json(s.tf))},
              {"frame", frame_json(s.frame)}};
    if (s.tf_back) j["tf_back"] = json::parse(to_json(*s.tf_back));
    if (s.labels) j["labels"] = {{"path", *s.labels}};
    return j.dump(2) + "\n";
}

SessionFile parse_session_file(const std::string& text, const std::string& where) {
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {  // parse_error, and out_of_range for a number past double
        throw Error(where, "json", std::string("not valid JSON: ") + e.what());
    }
    const Reader r(j, "", where);
    r.expect_object({"lacuna_session", "volume", "labels", "tf", "tf_back", "frame"});
    {
        const json& v = r.at("lacuna_session").value();
        if (!v.is_number_integer() || v.get<int64_t>() != kSessionFileVersion)
            r.fail("lacuna_session", "expected " + std::to_string(kSessionFileVersion) +
                                         " (this version's session files), got " + v.dump());
    }
    SessionFile s;
    s.volume = read_volume_entry(r.at("volume"));
    s.tf = read_tf(r.at("tf"));
    if (r.has("tf_back")) s.tf_back = read_tf(r.at("tf_back"));
    s.frame = read_frame(r.at("frame"));
    if (r.has("labels")) {
        const Reader l = r.at("labels");
        l.expect_object({"path"});
        s.labels = l.text("path");
        if (s.labels->empty())
            l.fail(l.sub("path"), "expected a label volume file name, got an empty string");
    }
    check_labels(s, where);
    if (s.frame.two_tfs && !s.tf_back)
        r.fail("tf_back", "missing (frame.two_tfs is true: the frame needs the back TF)");
    if (!s.frame.two_tfs && s.tf_back) r.fail("tf_back", "given, but frame.two_tfs is false");
    try {
        validate(s.frame);
    } catch (const FrameError& e) {
        throw Error(where, "frame." + e.field(), e.expected());
    }
    return s;
}

SessionFile load_session_file(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw Error(path, "session", "not a readable file");
    const auto size = fs::file_size(path, ec);
    if (ec || size > (16u << 20))
        throw Error(path, "session", "expected a JSON file of at most 16 MiB");
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    if (!in && !in.eof()) throw Error(path, "session", "cannot read the file");
    SessionFile s = parse_session_file(text.str(), path);
    const fs::path vp(s.volume.path);
    if (vp.is_relative())
        s.volume.path = (fs::path(path).parent_path() / vp).lexically_normal().string();
    if (s.labels && fs::path(*s.labels).is_relative())
        s.labels = (fs::path(path).parent_path() / *s.labels).lexically_normal().string();
    return s;
}

}  // namespace lacuna
