// A session file: everything a frame needs, as one JSON document (docs/cli.md, "Session files"),
// so `lacuna render --session FILE` reproduces a frame byte for byte and the viewer can save and
// reopen its state with the same (de)serializer.
//
// Why it reproduces the bytes. A frame is a pure function of (volume, its read options, the TF,
// the back TF, the FrameSpec): the renderers are deterministic, the thread count does not change
// a byte and every structure gives the `none` image (invariant 1). The file holds each of these
// exactly: the TF inline as lacuna TF JSON (whose round trip is exact, transfer_function.h), and
// every float of the FrameSpec as the double it widens to, which nlohmann/json prints in the
// shortest form that reads back to the same double, hence the same float.
//
// What it does not hold: the volume's voxels (a path, resolved against the session file's
// folder when relative). A frame of the segment renderer (the viewer's segments toggle, `render
// --labels`) holds its mode, tint and label table (every label's colour, opacity and visibility)
// in the frame, and in mask mode the label volume's path beside the volume's ("labels").
//
// Errors name the JSON field (invariant 3): "s.json: frame.sampling.step: expected a number, got
// a string"; unknown keys are errors too (a misspelt key would silently be a default).
#pragma once
#include <optional>
#include <string>

#include "lacuna/frame_spec.h"
#include "lacuna/io.h"
#include "lacuna/transfer_function.h"

namespace lacuna {

struct SessionVolume {
    std::string path;                 // as stored (relative paths: to the session file's folder)
    std::optional<int64_t> frame;     // of a 4D NIfTI file (ReadOptions::frame)
    std::optional<ValueRange> range;  // visualization range override (Volume::set_vis_range)
    std::optional<RawSpec> raw;       // a .raw file's layout (ReadOptions::raw)
};

struct SessionFile {
    SessionVolume volume;
    TransferFunction tf;
    std::optional<TransferFunction> tf_back;  // the back TF of frames with two_tfs
    FrameSpec frame;
    // The label volume of a segment-renderer frame in mask mode (as stored; relative paths: to
    // the session file's folder). Required there, refused elsewhere (labels mode reads the
    // volume itself as its label map).
    std::optional<std::string> labels;
};

inline constexpr int kSessionFileVersion = 1;

// The document (pretty-printed JSON, "lacuna_session": 1). Throws lacuna::Error(where, field,
// ...) for a file that would not read back (labels missing or given where they do not belong).
std::string to_json(const SessionFile& s, const std::string& where = "session");
// Parses and validates a document (lacuna::validate on the frame; its FrameError comes back as
// lacuna::Error(where, "frame.<field>", expected)). `where` names the file in errors.
SessionFile parse_session_file(const std::string& json_text, const std::string& where);
// Reads a file (at most 16 MiB) and parses it; a relative volume (or labels) path becomes
// relative to the file's folder.
SessionFile load_session_file(const std::string& path);

}  // namespace lacuna
