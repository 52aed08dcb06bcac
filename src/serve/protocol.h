// The viewer's WebSocket protocol (docs/viewer.md): JSON text messages from the page, JSON text
// and binary frame messages from the server. Strings become typed values here (STYLE.md 3):
// below this file the server sees only ViewRequest.
//
// Page -> server (text, one JSON object, at most Limits::max_message_bytes):
//   {"type":"render", "id":N, "width":W, "height":H, "preview":bool,
//    "camera":{"azimuth":deg, "elevation":deg, "zoom":f, "pan":[x,y]},
//      or "camera":{"view":"left", "zoom":f, "pan":[x,y]}: a named view of `lacuna render --view`
//      (anterior, posterior, left, right, superior, inferior; lacuna/views.h) instead of angles,
//    "renderer":"march", "accel":"bitfield", "ert":bool, "step":f,
//    ["shading":bool, "clip":bool, "segments":bool, "hide":"1,2,37-42",
//     "clip_planes":[[nx,ny,nz,d], ...]]  (optional, off when absent; planes are `--clip`: world
//                                          patient RAS mm, keeping dot(n, p) >= d)
//    "tf":{...the transfer-function JSON of docs/transfer-functions.md...}}
//   Every request carries the whole view state, so the server can drop all but the latest.
//   {"type":"slice", "id":N, "plane":"axial|coronal|sagittal", "point":[x,y,z] (RAS mm),
//    "window":W (> 0), "level":L, "interpolation":"trilinear|nearest",
//    ["overlay_opacity":[0,1] (the label overlay; needs `serve --labels`), "max_size":N]}
//   {"type":"probe", "id":N, "point":[x,y,z], ["interpolation":...]}
//   Slices and probes are answered in order, never dropped (lacuna/mpr.h: one slice <= 30 ms).
//   {"type":"screenshot", ...every key of "render" but "preview"...}: that view rendered at
//    width x height on the render thread, never reduced (no preview, no render budget) and never
//    dropped for a newer render; answered as PNG bytes (lacuna::png_bytes: `lacuna render`'s
//    encoder, so the bytes of `lacuna render --session` of the same state). One at a time per tab.
//   {"type":"session", ...the same keys...}: the session file of that view (session/session_file.h,
//    what `lacuna render --session FILE` reads): the server's volume path and read options, the
//    TF, the FrameSpec the frame would be rendered with.
//   {"type":"tf_export", "id":N, "format":"lacuna|slicer", "tf":{...}}: the TF as a file's text
//    (lacuna TF JSON or Slicer .vp.json, serve/tf_files.h).
//   {"type":"tf_import", "id":N, "name":"file name", "text":"..."}: an uploaded TF file (lacuna
//    JSON, Slicer .vp.json or .vp), answered with the TF as lacuna TF JSON.
//   {"type":"volume_frame", "id":N, "frame":K}: show volume K (0-based) of the server's 4D NIfTI
//    file (hello's "frames" > 1): the server reads it, renders every later request from it and
//    answers every tab with the new volume's info; the session files it writes name the frame.
//   {"type":"session_import", "id":N, "name":"...", "text":"..."}: a session file to open: answered
//    with the view state that renders its frame exactly, or an error naming the first field the
//    viewer cannot reproduce (another volume, a feature the page has no control for).
//   Unknown types, unknown or missing keys, wrong types and out-of-range values are rejected
//   with an "error" message naming the field; the connection stays open.
// Server -> page:
//   text   {"type":"hello", ...}    once, on connect: volume, histogram, presets, accels,
//                                    renderers, capabilities, limits, "messages" (the
//                                    types the server answers: render, slice, probe,
//                                    screenshot, session, tf_export, tf_import,
//                                    session_import, volume_frame), "frames" and
//                                    "frame" (the 4D file's volumes, the one shown), "session"
//                                    (true when the server can write session files) and
//                                    "slice_views" {"planes", "interpolations"}
//          "capabilities": {"march": {"accels": [...], "features": [...]}, "slice": {...},
//                           "segments": {"renderer": "march", "accels": [...], "features": [...]}}
//          is lacuna::capabilities() (lacuna/frame_spec.h) in the page's words: which of the
//          "accels" each renderer (and the segments toggle, drawn with "renderer") takes, and its
//          features by lacuna::to_string(Feature) ("shading", "clip_planes" for both "clip" and
//          "clip_planes", ...). The page decides nothing else about what combines with what.
//   text   {"type":"error", "id":N|null, "message":"..."}
//   binary [u32 little-endian n][n bytes of JSON header {"type":"frame", ...}][JPEG bytes]
//   binary [u32 LE n][{"type":"slice", "id", "plane", "width", "height", "origin":[mm],
//           "u":[mm], "v":[mm], "pixel_mm", ...}][JPEG]: pixel (c, r) (column c from the left,
//           row r from the top) is at origin + c u + r v, RAS mm, so a click maps to the world
//   text   {"type":"probe", "id", "point", "inside", "index":[continuous], "voxel":[i,j,k]|null,
//           "value"|null, "voxel_value"|null, "label"|null, "label_name"}
//   binary [u32 LE n][{"type":"screenshot", "id", "width", "height", "frame_ms", "encode_ms"}][PNG]
//   text   {"type":"session", "id", "text":"...the session file..."}
//   text   {"type":"tf_export", "id", "format", "text":"...the file..."}
//   text   {"type":"tf_import", "id", "tf":{...lacuna TF JSON...}}
//   text   {"type":"session_import", "id", "view":{"width", "height", "camera", "renderer", ...}}
//   text   {"type":"volume_frame", "id", "frame", "frames", "volume":{...}, "histogram":[...]}
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/frame_spec.h"
#include "lacuna/mpr.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::serve {

inline constexpr int kProtocolVersion = 1;

// Renderers the viewer can drive: the ray marcher and the object-order slicer (docs/slicer.md;
// it takes the structures `none` (Basic) and `kdtree` (the kd-tree's boxes)).
enum class RendererKind { March, Slice };
std::string to_string(RendererKind k);
std::vector<std::string> renderer_names();

struct Limits {
    size_t max_message_bytes = 64 * 1024;  // a WebSocket message from the page
    int max_side = 4096;                   // requested image width/height
    int max_tf_points = 512;               // colour + opacity points of one TF
    int max_clip_planes = 6;               // "clip_planes" of one request
};

struct ViewCamera {
    float azimuth = 30.f, elevation = 15.f;  // degrees
    float zoom = 1.f;                        // (0.05, 50]
    float pan_x = 0.f, pan_y = 0.f;          // along the view's right/up, in bounding radii
    // A named view sets azimuth and elevation from lacuna/views.h (superior and inferior are
    // exactly +-90, which free angles may not reach: they stop at +-89.9).
    friend bool operator==(const ViewCamera&, const ViewCamera&) = default;
};

struct ViewRequest {
    uint64_t id = 0;
    int width = 0, height = 0;
    bool preview = false;  // the page is interacting: render at reduced resolution
    ViewCamera camera;
    RendererKind renderer = RendererKind::March;
    AccelKind accel = AccelKind::None;
    bool ert = true;       // early ray termination at 0.99 (false: off)
    float step = 0.5f;     // sample distance in smallest voxel spacings, [0.1, 8]
    bool shading = false;  // optional "shading": Phong with a headlight (docs/shading.md)
    bool clip = false;     // optional "clip": keep x <= the volume's centre (a cut-away)
    // optional "clip_planes": world (patient RAS mm) planes, `lacuna render --clip NX,NY,NZ,D`
    std::vector<ClipPlane> clip_planes;
    bool segments = false;  // optional "segments": mask by the server's label volume (--labels)
    std::string hide;       // optional "hide": labels to hide, "1,2,37-42" (docs/segments.md)
    TransferFunction tf;
};

// A slice pane's request (docs/viewer.md, lacuna/mpr.h).
struct SliceRequest {
    uint64_t id = 0;
    SlicePlane plane = SlicePlane::Axial;
    Vec3d point;  // RAS mm
    double window = 1, level = 0;
    Interpolation interpolation = Interpolation::Trilinear;
    float overlay_opacity = 0;  // 0: no label overlay
    int max_size = 0;           // 0: the slice's own size (bounded by Limits::max_side)
};
struct ProbeRequest {
    uint64_t id = 0;
    Vec3d point;
    Interpolation interpolation = Interpolation::Trilinear;
};

// The kinds of message the page sends, by "type".
enum class MessageKind {
    Render,
    Slice,
    Probe,
    Screenshot,
    Session,
    TfExport,
    TfImport,
    SessionImport,
    VolumeFrame
};
// The message's "type" (throws lacuna::Error("message", "type"/"json"/..., ...) like
// parse_request for a type not in message_names()).
MessageKind message_kind(std::string_view text, const Limits& limits = {});
SliceRequest parse_slice_request(std::string_view text, const Limits& limits = {});
ProbeRequest parse_probe_request(std::string_view text, const Limits& limits = {});
// The message kinds the hello lists under "messages".
std::vector<std::string> message_names();

// The FrameSpec renderer and structure a request's "renderer", "segments" and "accel" name: the
// segments toggle is the segment renderer (drawn on the ray marcher's lattice), whose "bitfield"
// is the label bitfield octree; every other accel is the structure of that name, its parameters
// from `o` (`lacuna serve --leaf/--bits`).
Renderer frame_renderer(RendererKind renderer, bool segments);
Structure frame_structure(AccelKind accel, bool segments, const AccelOptions& o = {});

// Parses one message from the page. Throws lacuna::Error("message", field, expectation) for
// anything malformed, oversized or out of range; never anything else.
ViewRequest parse_request(std::string_view text, const Limits& limits = {});
// A "screenshot" or "session" message: the view state of a render message, parsed by the same
// code (every key of render but "preview"; the result has preview = false). `kind` is the type
// the message must have.
ViewRequest parse_view_request(std::string_view text, MessageKind kind, const Limits& limits = {});

enum class TfFileFormat { Lacuna, Slicer };  // lacuna TF JSON, Slicer .vp.json
std::string to_string(TfFileFormat f);
struct TfExportRequest {
    uint64_t id = 0;
    TfFileFormat format = TfFileFormat::Lacuna;
    TransferFunction tf;
};
struct TfImportRequest {
    uint64_t id = 0;
    std::string name;  // the file's name (picks the reader: .vp.json, .vp, else lacuna JSON)
    std::string text;  // its contents
};
TfExportRequest parse_tf_export_request(std::string_view text, const Limits& limits = {});
TfImportRequest parse_tf_import_request(std::string_view text, const Limits& limits = {});
// "session_import": a session file to open in the page ({"type", "id", "name", "text"}, the
// fields of tf_import).
TfImportRequest parse_session_import_request(std::string_view text, const Limits& limits = {});

// "volume_frame": {"type", "id", "frame": K}, the volume K of the server's 4D file to show
// (the range is the server's to check: the parser only bounds it to 0..2^31-1).
struct VolumeFrameRequest {
    uint64_t id = 0;
    int64_t frame = 0;
};
VolumeFrameRequest parse_volume_frame_request(std::string_view text, const Limits& limits = {});

// Best effort: the "id" of a rejected message, to echo in the error (nullopt if none).
std::optional<uint64_t> request_id(std::string_view text, const Limits& limits = {});

struct HelloInfo {
    std::string volume_name;
    const Volume* volume = nullptr;
    std::vector<uint64_t> histogram;  // bins over the visualization range
    TransferFunction initial_tf;      // the TF the page starts with
    std::vector<std::string> accels, renderers;
    int labels = 0;        // label values of the server's label volume (0: none loaded)
    bool session = false;  // the server knows its volume's file (session messages can be answered)
    int64_t frames = 1, frame = 0;  // volumes in the server's file (4D NIfTI), the one shown
    Limits limits;
};
std::string hello_message(const HelloInfo& h);
// The answer to volume_frame, sent to every tab (they all show the server's one volume):
// {"type":"volume_frame", "id", "frame", "frames", "volume":{...as in hello}, "histogram"}.
std::string volume_frame_message(uint64_t id, const HelloInfo& h);

// What the page shows in its overlay, sent with every frame.
struct FrameInfo {
    uint64_t id = 0;
    int width = 0, height = 0;  // of the JPEG (reduced when preview)
    bool preview = false;
    int reduced = 1;  // the render budget divided each side by this (1: not reduced)
    std::string renderer, accel;
    double frame_ms = 0;   // the render alone
    double encode_ms = 0;  // JPEG
    double samples_per_ray = 0;
    double skipped = 0;             // fraction of the box's lattice samples not taken
    bool tf_changed = false;        // this frame applied a new TF
    double tf_update_ms = 0;        // TF change -> ready to render (LUT + structure update)
    double tf_latency_ms = 0;       // TF message received -> ready to render (includes waiting)
    double accel_build_ms = 0;      // when this frame built the structure first
    double accel_tf_update_ms = 0;  // the structure's own last TF update (AccelStats)
};
std::string frame_header(const FrameInfo& f);
// [u32 LE header length][header][jpeg]
std::string frame_message(const FrameInfo& f, std::string_view jpeg);

// The slice's binary message: [u32 LE header length][header][jpeg].
struct SliceInfo {
    uint64_t id = 0;
    SliceGeometry geometry;
    Interpolation interpolation = Interpolation::Trilinear;
    bool overlay = false;
    double slice_ms = 0, encode_ms = 0;
};
std::string slice_header(const SliceInfo& s);
std::string slice_message(const SliceInfo& s, std::string_view jpeg);
std::string probe_message(uint64_t id, const ProbeResult& p);

// The screenshot's binary message: [u32 LE header length][header][PNG bytes].
struct ScreenshotInfo {
    uint64_t id = 0;
    int width = 0, height = 0;
    double frame_ms = 0, encode_ms = 0;
};
std::string screenshot_message(const ScreenshotInfo& s, std::string_view png);
std::string session_message(uint64_t id, const std::string& session_text);
std::string tf_export_message(uint64_t id, TfFileFormat format, const std::string& file_text);
std::string tf_import_message(uint64_t id, const TransferFunction& tf);
// The answer to session_import: the view state (the keys of a render message but type, id and
// preview; the camera by "view" name when its angles are a named view's) the page takes over.
std::string session_import_message(uint64_t id, const ViewRequest& view);

std::string error_message(const std::string& message, std::optional<uint64_t> id);

}  // namespace lacuna::serve
