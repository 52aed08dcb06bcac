#include "serve/protocol.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "lacuna/segments.h"
#include "lacuna/views.h"

namespace lacuna::serve {

namespace {

using nlohmann::json;

constexpr int kMaxDepth = 16;  // the deepest a valid request nests is 4

[[noreturn]] void reject(const std::string& field, const std::string& what) {
    throw Error("message", field, what);
}

// Rejects over-long or over-deep text before the JSON parser sees it (a deep document would
// otherwise cost stack and time for nothing).
void check_shape(std::string_view text, const Limits& limits) {
    if (text.size() > limits.max_message_bytes)
        reject("size", std::to_string(text.size()) + " bytes; expected at most " +
                           std::to_string(limits.max_message_bytes));
    int depth = 0;
    bool in_string = false, escaped = false;
    for (char c : text) {
        if (in_string) {
            if (escaped)
                escaped = false;
            else if (c == '\\')
                escaped = true;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '{' || c == '[') {
            if (++depth > kMaxDepth) reject("nesting", "deeper than " + std::to_string(kMaxDepth));
        } else if (c == '}' || c == ']') {
            --depth;
        }
    }
}

json parse_json(std::string_view text, const Limits& limits) {
    check_shape(text, limits);
    json j = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) reject("json", "not valid JSON");
    if (!j.is_object()) reject("json", "expected an object");
    return j;
}

// Every key of `j` must be in `known` (comma-separated list for the message).
void only_keys(const json& j, std::initializer_list<const char*> known, const std::string& where) {
    for (const auto& [key, value] : j.items()) {
        bool ok = false;
        for (const char* k : known) ok = ok || key == k;
        if (!ok) {
            std::string list;
            for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
            reject(where + key, "unknown key; expected one of: " + list);
        }
    }
}

const json& need(const json& j, const char* key, const std::string& where) {
    auto it = j.find(key);
    if (it == j.end()) reject(where + key, "missing");
    return *it;
}

double number(const json& j, const char* key, double lo, double hi, const std::string& where) {
    const json& v = need(j, key, where);
    if (!v.is_number()) reject(where + key, "expected a number");
    const double x = v.get<double>();
    if (!std::isfinite(x) || x < lo || x > hi)
        reject(where + key, "expected a number in [" + json(lo).dump() + ", " + json(hi).dump() +
                                "], got " + v.dump());
    return x;
}

int integer(const json& j, const char* key, int lo, int hi, const std::string& where) {
    const json& v = need(j, key, where);
    if (!v.is_number_integer() || v.get<int64_t>() < lo || v.get<int64_t>() > hi)
        reject(where + key, "expected an integer in [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "], got " + v.dump());
    return int(v.get<int64_t>());
}

bool boolean(const json& j, const char* key, const std::string& where) {
    const json& v = need(j, key, where);
    if (!v.is_boolean()) reject(where + key, "expected true or false");
    return v.get<bool>();
}

std::string text_of(const json& j, const char* key, const std::string& where) {
    const json& v = need(j, key, where);
    if (!v.is_string()) reject(where + key, "expected a string");
    return v.get<std::string>();
}

uint64_t id_of(const json& j) {
    const json& v = need(j, "id", "");
    // Integers up to 2^53 survive a JavaScript number.
    if (!v.is_number_unsigned() || v.get<uint64_t>() > (uint64_t(1) << 53))
        reject("id", "expected an integer in [0, 2^53]");
    return v.get<uint64_t>();
}

// "point": [x, y, z], finite RAS mm within 1e9.
Vec3d point_of(const json& j, const std::string& where) {
    const json& p = need(j, "point", where);
    bool ok = p.is_array() && p.size() == 3;
    for (size_t i = 0; ok && i < 3; ++i)
        ok = p[i].is_number() && std::isfinite(p[i].get<double>()) &&
             std::abs(p[i].get<double>()) <= 1e9;
    if (!ok)
        reject(where + "point",
               "expected [x, y, z]: finite numbers (RAS mm), got " + p.dump().substr(0, 80));
    return {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()};
}

Interpolation interpolation_of(const json& j, const std::string& where) {
    const std::string name = text_of(j, "interpolation", where);
    if (name == "trilinear") return Interpolation::Trilinear;
    if (name == "nearest") return Interpolation::Nearest;
    reject(where + "interpolation",
           "unknown '" + name.substr(0, 40) + "'; expected trilinear or nearest");
}

json vec_json(Vec3d v) {
    return json::array({v.x, v.y, v.z});
}

// A message's "tf": bounded in points, then validated by the library's own reader (shape,
// ranges, sorting), which throws lacuna::Error naming the field.
TransferFunction tf_of(const json& j, const Limits& limits) {
    const json& tf = need(j, "tf", "");
    if (!tf.is_object()) reject("tf", "expected a transfer-function object");
    size_t points = 0;
    for (const char* key : {"color", "opacity", "gradient_opacity"})
        if (auto it = tf.find(key); it != tf.end() && it->is_array()) points += it->size();
    if (points > size_t(limits.max_tf_points))
        reject("tf", std::to_string(points) + " points; expected at most " +
                         std::to_string(limits.max_tf_points));
    return parse_transfer_function(tf.dump(), "tf");
}

}  // namespace

// The message types by kind, in message_names()'s order.
constexpr std::pair<MessageKind, const char*> kMessageNames[] = {
    {MessageKind::Render, "render"},
    {MessageKind::Slice, "slice"},
    {MessageKind::Probe, "probe"},
    {MessageKind::Screenshot, "screenshot"},
    {MessageKind::Session, "session"},
    {MessageKind::TfExport, "tf_export"},
    {MessageKind::TfImport, "tf_import"},
    {MessageKind::SessionImport, "session_import"},
    {MessageKind::VolumeFrame, "volume_frame"}};

const char* message_name(MessageKind k) {
    for (const auto& [kind, name] : kMessageNames)
        if (kind == k) return name;
    return "?";
}

MessageKind message_kind(std::string_view text, const Limits& limits) {
    const json j = parse_json(text, limits);
    const std::string type = text_of(j, "type", "");
    for (const auto& [kind, name] : kMessageNames)
        if (type == name) return kind;
    std::string list;
    for (const auto& [kind, name] : kMessageNames)
        list += (list.empty() ? "" : ", ") + std::string(name);
    reject("type", "unknown message type '" + type.substr(0, 40) + "'; expected one of: " + list);
}

std::vector<std::string> message_names() {
    std::vector<std::string> out;
    for (const auto& [kind, name] : kMessageNames) out.push_back(name);
    return out;
}

SliceRequest parse_slice_request(std::string_view text, const Limits& limits) {
    const json j = parse_json(text, limits);
    if (text_of(j, "type", "") != "slice") reject("type", "expected slice");
    only_keys(j,
              {"type", "id", "plane", "point", "window", "level", "interpolation",
               "overlay_opacity", "max_size"},
              "");
    SliceRequest r;
    r.id = id_of(j);
    r.plane = parse_slice_plane(text_of(j, "plane", ""), "message");  // "message: plane: ..."
    r.point = point_of(j, "");
    const json& w = need(j, "window", "");
    if (!w.is_number() || !std::isfinite(w.get<double>()) || w.get<double>() <= 0 ||
        w.get<double>() > 1e12)
        reject("window",
               "expected a positive number (at most 1e12), got " + w.dump().substr(0, 40));
    r.window = w.get<double>();
    r.level = number(j, "level", -1e12, 1e12, "");
    r.interpolation = interpolation_of(j, "");
    if (j.contains("overlay_opacity"))
        r.overlay_opacity = float(number(j, "overlay_opacity", 0, 1, ""));
    if (j.contains("max_size")) r.max_size = integer(j, "max_size", 1, limits.max_side, "");
    return r;
}

ProbeRequest parse_probe_request(std::string_view text, const Limits& limits) {
    const json j = parse_json(text, limits);
    if (text_of(j, "type", "") != "probe") reject("type", "expected probe");
    only_keys(j, {"type", "id", "point", "interpolation"}, "");
    ProbeRequest r;
    r.id = id_of(j);
    r.point = point_of(j, "");
    if (j.contains("interpolation")) r.interpolation = interpolation_of(j, "");
    return r;
}

std::string slice_header(const SliceInfo& s) {
    const SliceGeometry& g = s.geometry;
    json j{{"type", "slice"},
           {"id", s.id},
           {"plane", to_string(g.plane)},
           {"width", g.width},
           {"height", g.height},
           {"origin", vec_json(g.origin)},
           {"u", vec_json(g.u)},
           {"v", vec_json(g.v)},
           {"pixel_mm", g.pixel_mm},
           {"interpolation", to_string(s.interpolation)},
           {"overlay", s.overlay},
           {"slice_ms", s.slice_ms},
           {"encode_ms", s.encode_ms}};
    return j.dump();
}

std::string slice_message(const SliceInfo& s, std::string_view jpeg) {
    const std::string header = slice_header(s);
    std::string out(4, '\0');
    const uint32_t n = uint32_t(header.size());
    for (int b = 0; b < 4; ++b) out[size_t(b)] = char((n >> (8 * b)) & 0xff);
    out += header;
    out.append(jpeg.data(), jpeg.size());
    return out;
}

std::string probe_message(uint64_t id, const ProbeResult& p) {
    json j{{"type", "probe"},
           {"id", id},
           {"point", vec_json(p.world)},
           {"inside", p.inside},
           {"index", vec_json(p.index)}};
    j["voxel"] = p.inside ? json::array({p.voxel.x, p.voxel.y, p.voxel.z}) : json(nullptr);
    j["value"] = p.inside ? json(p.value) : json(nullptr);
    j["voxel_value"] = p.inside ? json(p.voxel_value) : json(nullptr);
    j["label"] = p.label ? json(*p.label) : json(nullptr);
    j["label_name"] = p.label_name;
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string screenshot_message(const ScreenshotInfo& s, std::string_view png) {
    const std::string header = json{{"type", "screenshot"},   {"id", s.id},
                                    {"width", s.width},       {"height", s.height},
                                    {"frame_ms", s.frame_ms}, {"encode_ms", s.encode_ms}}
                                   .dump();
    std::string out(4, '\0');
    const uint32_t n = uint32_t(header.size());
    for (int b = 0; b < 4; ++b) out[size_t(b)] = char((n >> (8 * b)) & 0xff);
    out += header;
    out.append(png.data(), png.size());
    return out;
}

std::string session_message(uint64_t id, const std::string& session_text) {
    return json{{"type", "session"}, {"id", id}, {"text", session_text}}.dump(
        -1, ' ', false, json::error_handler_t::replace);
}

std::string tf_export_message(uint64_t id, TfFileFormat format, const std::string& file_text) {
    return json{
        {"type", "tf_export"}, {"id", id}, {"format", to_string(format)}, {"text", file_text}}
        .dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string tf_import_message(uint64_t id, const TransferFunction& tf) {
    return json{{"type", "tf_import"}, {"id", id}, {"tf", json::parse(to_json(tf))}}.dump(
        -1, ' ', false, json::error_handler_t::replace);
}

std::string to_string(RendererKind k) {
    switch (k) {
        case RendererKind::March:
            return "march";
        case RendererKind::Slice:
            return "slice";
    }
    return "?";
}

std::vector<std::string> renderer_names() {
    return {"march", "slice"};
}

namespace {

// The view state of render, screenshot and session messages (screenshots and sessions have no
// "preview": they are the full-resolution frame).
ViewRequest parse_view(const json& j, MessageKind kind, const Limits& limits) {
    const std::string type = text_of(j, "type", "");
    if (type != message_name(kind))
        reject("type",
               "unknown message type '" + type.substr(0, 40) + "'; expected " + message_name(kind));
    if (kind == MessageKind::Render)
        only_keys(j,
                  {"type", "id", "width", "height", "preview", "camera", "renderer", "accel", "ert",
                   "step", "tf", "shading", "clip", "clip_planes", "segments", "hide"},
                  "");
    else
        only_keys(j,
                  {"type", "id", "width", "height", "camera", "renderer", "accel", "ert", "step",
                   "tf", "shading", "clip", "clip_planes", "segments", "hide"},
                  "");
    ViewRequest r;
    r.id = id_of(j);
    r.width = integer(j, "width", 1, limits.max_side, "");
    r.height = integer(j, "height", 1, limits.max_side, "");
    r.preview = kind == MessageKind::Render && boolean(j, "preview", "");
    const json& cam = need(j, "camera", "");
    if (!cam.is_object()) reject("camera", "expected an object");
    only_keys(cam, {"view", "azimuth", "elevation", "zoom", "pan"}, "camera.");
    if (cam.contains("view")) {
        // The named views of `lacuna render --view`, from the same table.
        const std::string view = text_of(cam, "view", "camera.");
        if (cam.contains("azimuth") || cam.contains("elevation"))
            reject("camera.view", "sets azimuth and elevation; send either the view or the angles");
        if (!named_view(view, r.camera.azimuth, r.camera.elevation))
            reject("camera.view", "unknown '" + view.substr(0, 40) + "'; expected " + kViewNames);
    } else {
        r.camera.azimuth = float(number(cam, "azimuth", -1e6, 1e6, "camera."));
        r.camera.elevation = float(number(cam, "elevation", -89.9, 89.9, "camera."));
    }
    r.camera.zoom = float(number(cam, "zoom", 0.05, 50, "camera."));
    const json& pan = need(cam, "pan", "camera.");
    if (!pan.is_array() || pan.size() != 2 || !pan[0].is_number() || !pan[1].is_number())
        reject("camera.pan", "expected [x, y]");
    const double px = pan[0].get<double>(), py = pan[1].get<double>();
    if (!std::isfinite(px) || !std::isfinite(py) || std::abs(px) > 100 || std::abs(py) > 100)
        reject("camera.pan", "expected numbers in [-100, 100]");
    r.camera.pan_x = float(px);
    r.camera.pan_y = float(py);

    const std::string renderer = text_of(j, "renderer", "");
    bool found = false;
    for (const auto& n : renderer_names()) found = found || n == renderer;
    if (!found) reject("renderer", "unknown '" + renderer + "'; expected march or slice");
    r.renderer = renderer == "slice" ? RendererKind::Slice : RendererKind::March;
    try {
        r.accel = parse_accel(text_of(j, "accel", ""));
    } catch (const FrameError& e) {  // the page's field is "accel"
        reject("accel", e.expected());
    }
    r.ert = boolean(j, "ert", "");
    // Optional toggles (absent = off): Phong shading with a headlight, and a clip plane through
    // the volume's centre that removes the half with x > centre (a cut-away of a head).
    if (j.contains("shading")) r.shading = boolean(j, "shading", "");
    if (j.contains("clip")) r.clip = boolean(j, "clip", "");
    if (j.contains("clip_planes")) {
        // World planes in patient RAS mm, as `lacuna render --clip NX,NY,NZ,D`.
        const json& planes = need(j, "clip_planes", "");
        if (!planes.is_array() || planes.size() > size_t(limits.max_clip_planes))
            reject("clip_planes", "expected an array of at most " +
                                      std::to_string(limits.max_clip_planes) +
                                      " planes [nx, ny, nz, d]");
        for (const json& p : planes) {
            bool ok = p.is_array() && p.size() == 4;
            for (size_t i = 0; ok && i < 4; ++i)
                ok = p[i].is_number() && std::isfinite(p[i].get<double>()) &&
                     std::abs(p[i].get<double>()) <= 1e9;
            if (ok)
                ok = p[0].get<double>() != 0 || p[1].get<double>() != 0 || p[2].get<double>() != 0;
            if (!ok)
                reject("clip_planes",
                       "expected [nx, ny, nz, d]: finite numbers (RAS mm), a non-zero "
                       "normal; got " +
                           p.dump().substr(0, 80));
            r.clip_planes.push_back(ClipPlane{
                {p[0].get<float>(), p[1].get<float>(), p[2].get<float>()}, p[3].get<float>()});
        }
    }
    if (j.contains("segments")) r.segments = boolean(j, "segments", "");
    if (j.contains("hide")) {
        r.hide = text_of(j, "hide", "");
        if (r.hide.size() > 256) reject("hide", "expected at most 256 characters");
        if (!r.hide.empty()) {
            LabelTable check;
            try {
                set_label_visibility(check, r.hide, false, "hide");
            } catch (const Error& e) {
                reject("hide", e.what());
            }
        }
    }
    // What combines with what is the capabilities table's (lacuna/frame_spec.h), as the page
    // receives it in the hello message.
    const bool clipped = r.clip || !r.clip_planes.empty();
    if (r.segments && r.renderer != RendererKind::March)
        reject("segments",
               "segments are drawn with the ray marcher's lattice ('renderer': 'march')");
    const Renderer target = frame_renderer(r.renderer, r.segments);
    const RendererCapabilities& cap = capabilities(target);
    // The field blamed: the toggle that asked for a renderer without the feature.
    const char* asked = r.segments ? "segments" : "renderer";
    if (!cap.takes(frame_structure(r.accel, r.segments))) {
        std::string names;
        for (const std::string& n : accel_names())
            if (cap.takes(frame_structure(parse_accel(n), r.segments)))
                names += (names.empty() ? "" : ", ") + n;
        reject("accel", "the " + to_string(target) + " renderer takes " + names + ", not '" +
                            to_string(r.accel) + "'");
    }
    if ((r.shading && !cap.has(Feature::Shading)) || (clipped && !cap.has(Feature::ClipPlanes)))
        reject(asked, "the " + to_string(target) + " renderer has no shading or clipping");
    r.step = float(number(j, "step", 0.1, 8, ""));
    r.tf = tf_of(j, limits);
    return r;
}

}  // namespace

ViewRequest parse_request(std::string_view text, const Limits& limits) {
    return parse_view(parse_json(text, limits), MessageKind::Render, limits);
}

ViewRequest parse_view_request(std::string_view text, MessageKind kind, const Limits& limits) {
    if (kind != MessageKind::Render && kind != MessageKind::Screenshot &&
        kind != MessageKind::Session)
        reject("type",
               std::string("expected render, screenshot or session, not ") + message_name(kind));
    return parse_view(parse_json(text, limits), kind, limits);
}

std::string to_string(TfFileFormat f) {
    return f == TfFileFormat::Slicer ? "slicer" : "lacuna";
}

TfExportRequest parse_tf_export_request(std::string_view text, const Limits& limits) {
    const json j = parse_json(text, limits);
    if (text_of(j, "type", "") != "tf_export") reject("type", "expected tf_export");
    only_keys(j, {"type", "id", "format", "tf"}, "");
    TfExportRequest r;
    r.id = id_of(j);
    const std::string format = text_of(j, "format", "");
    if (format == "lacuna")
        r.format = TfFileFormat::Lacuna;
    else if (format == "slicer")
        r.format = TfFileFormat::Slicer;
    else
        reject("format", "unknown '" + format.substr(0, 40) + "'; expected lacuna or slicer");
    r.tf = tf_of(j, limits);
    return r;
}

namespace {

// tf_import and session_import: a file's name and text.
TfImportRequest parse_file_request(std::string_view text, const Limits& limits, const char* type) {
    const json j = parse_json(text, limits);
    if (text_of(j, "type", "") != type) reject("type", std::string("expected ") + type);
    only_keys(j, {"type", "id", "name", "text"}, "");
    TfImportRequest r;
    r.id = id_of(j);
    r.name = text_of(j, "name", "");
    if (r.name.size() > 255) reject("name", "expected a file name of at most 255 characters");
    for (char c : r.name)
        if (static_cast<unsigned char>(c) < 0x20)
            reject("name", "expected a file name without control characters");
    r.text = text_of(j, "text", "");
    // The file is JSON (but for a Slicer .vp): bounded in nesting as a message is.
    check_shape(r.text, limits);
    return r;
}

}  // namespace

TfImportRequest parse_tf_import_request(std::string_view text, const Limits& limits) {
    return parse_file_request(text, limits, "tf_import");
}

TfImportRequest parse_session_import_request(std::string_view text, const Limits& limits) {
    return parse_file_request(text, limits, "session_import");
}

VolumeFrameRequest parse_volume_frame_request(std::string_view text, const Limits& limits) {
    const json j = parse_json(text, limits);
    if (text_of(j, "type", "") != "volume_frame") reject("type", "expected volume_frame");
    only_keys(j, {"type", "id", "frame"}, "");
    VolumeFrameRequest r;
    r.id = id_of(j);
    r.frame = integer(j, "frame", 0, std::numeric_limits<int>::max(), "");
    return r;
}

std::string session_import_message(uint64_t id, const ViewRequest& v) {
    json camera{{"zoom", v.camera.zoom}, {"pan", {v.camera.pan_x, v.camera.pan_y}}};
    // A named view's angles go by name (superior and inferior are +-90, beyond free angles).
    std::string view;
    for (const char* name : {"anterior", "posterior", "left", "right", "superior", "inferior"}) {
        float az = 0, el = 0;
        if (view.empty() && named_view(name, az, el) && az == v.camera.azimuth &&
            el == v.camera.elevation)
            view = name;
    }
    if (!view.empty()) {
        camera["view"] = view;
    } else {
        camera["azimuth"] = v.camera.azimuth;
        camera["elevation"] = v.camera.elevation;
    }
    json planes = json::array();
    for (const ClipPlane& p : v.clip_planes)
        planes.push_back({p.normal.x, p.normal.y, p.normal.z, p.d});
    json state{{"width", v.width},
               {"height", v.height},
               {"camera", camera},
               {"renderer", to_string(v.renderer)},
               {"accel", to_string(v.accel)},
               {"ert", v.ert},
               {"step", v.step},
               {"shading", v.shading},
               {"clip", v.clip},
               {"clip_planes", planes},
               {"tf", json::parse(to_json(v.tf))}};
    return json{{"type", "session_import"}, {"id", id}, {"view", state}}.dump(
        -1, ' ', false, json::error_handler_t::replace);
}

Renderer frame_renderer(RendererKind renderer, bool segments) {
    if (renderer == RendererKind::Slice) return Renderer::Slicer;
    return segments ? Renderer::Segments : Renderer::RayMarcher;
}

Structure frame_structure(AccelKind accel, bool segments, const AccelOptions& o) {
    return parse_structure(to_string(accel), segments ? Renderer::Segments : Renderer::RayMarcher,
                           o);
}

std::optional<uint64_t> request_id(std::string_view text, const Limits& limits) {
    try {
        return id_of(parse_json(text, limits));
    } catch (const Error&) {
        return std::nullopt;
    }
}

namespace {

// The hello's "volume" object.
json volume_json(const HelloInfo& h) {
    const Volume& v = *h.volume;
    json out = {{"name", h.volume_name},
                {"dims", {v.dims().x, v.dims().y, v.dims().z}},
                {"type", to_string(v.type())},
                {"spacing", {v.spacing.x, v.spacing.y, v.spacing.z}},
                {"data_range", {v.data_range().min, v.data_range().max}},
                {"vis_range", {v.vis_range().min, v.vis_range().max}}};
    // Where the volume is in the world (patient RAS mm): the slice panes start their crosshair at
    // the centre of this box (lacuna/orientation.h world_bounds, the sampled box [0, dims-1]).
    const Box3f b = world_bounds(v);
    out["world_bounds"] = {{"lo", {b.lo.x, b.lo.y, b.lo.z}}, {"hi", {b.hi.x, b.hi.y, b.hi.z}}};
    out["orientation"] = orientation_code(v);
    return out;
}

}  // namespace

std::string volume_frame_message(uint64_t id, const HelloInfo& h) {
    const json j{{"type", "volume_frame"},   {"id", id},
                 {"frame", h.frame},         {"frames", h.frames},
                 {"volume", volume_json(h)}, {"histogram", h.histogram}};
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string hello_message(const HelloInfo& h) {
    json j;
    j["type"] = "hello";
    j["version"] = kProtocolVersion;
    j["volume"] = volume_json(h);
    j["histogram"] = h.histogram;
    j["frames"] = h.frames;
    j["frame"] = h.frame;
    json presets = json::object();
    for (const auto& name : preset_names()) presets[name] = json::parse(to_json(preset(name)));
    j["presets"] = presets;
    j["tf"] = json::parse(to_json(h.initial_tf));
    j["accels"] = h.accels;
    j["renderers"] = h.renderers;
    // The capabilities table in the page's words (see protocol.h).
    json caps = json::object();
    const std::pair<const char*, bool> rows[] = {
        {"march", false}, {"slice", false}, {"segments", true}};
    for (const auto& [name, segments] : rows) {
        const RendererKind kind =
            std::string(name) == "slice" ? RendererKind::Slice : RendererKind::March;
        const RendererCapabilities& cap = capabilities(frame_renderer(kind, segments));
        json accels = json::array(), features = json::array();
        for (const std::string& a : h.accels)
            if (cap.takes(frame_structure(parse_accel(a), segments))) accels.push_back(a);
        for (Feature f : cap.features) features.push_back(to_string(f));
        caps[name] = {{"accels", accels}, {"features", features}};
        if (segments) caps[name]["renderer"] = "march";
    }
    j["capabilities"] = caps;
    j["labels"] = h.labels;
    j["messages"] = message_names();
    j["session"] = h.session;
    j["slice_views"] = {{"planes", {"axial", "coronal", "sagittal"}},
                        {"interpolations", {"trilinear", "nearest"}}};
    j["limits"] = {{"max_message_bytes", h.limits.max_message_bytes},
                   {"max_side", h.limits.max_side},
                   {"max_tf_points", h.limits.max_tf_points}};
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string frame_header(const FrameInfo& f) {
    json j{{"type", "frame"},
           {"id", f.id},
           {"width", f.width},
           {"height", f.height},
           {"preview", f.preview},
           {"reduced", f.reduced},
           {"renderer", f.renderer},
           {"accel", f.accel},
           {"frame_ms", f.frame_ms},
           {"encode_ms", f.encode_ms},
           {"samples_per_ray", f.samples_per_ray},
           {"skipped", f.skipped},
           {"tf_changed", f.tf_changed},
           {"tf_update_ms", f.tf_update_ms},
           {"tf_latency_ms", f.tf_latency_ms},
           {"accel_build_ms", f.accel_build_ms},
           {"accel_tf_update_ms", f.accel_tf_update_ms}};
    return j.dump();
}

std::string frame_message(const FrameInfo& f, std::string_view jpeg) {
    const std::string header = frame_header(f);
    std::string out(4, '\0');
    const uint32_t n = uint32_t(header.size());
    for (int b = 0; b < 4; ++b) out[size_t(b)] = char((n >> (8 * b)) & 0xff);
    out += header;
    out.append(jpeg.data(), jpeg.size());
    return out;
}

std::string error_message(const std::string& message, std::optional<uint64_t> id) {
    json j{{"type", "error"}, {"message", message}};
    j["id"] = id ? json(*id) : json(nullptr);
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace lacuna::serve
