// `lacuna render --labels ...`: segment visibility flags (include/lacuna/segments.h). Kept apart
// from cmd_render.cpp so the render command only forwards to it.
#pragma once
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "cli_common.h"
#include "lacuna/frame_spec.h"
#include "lacuna/transfer_function.h"

namespace lacuna::cli {

struct SegmentArgs {
    std::string labels;  // label volume (mask mode); empty with --segments labels: the volume
    std::string mode;    // "mask" | "labels" (default: mask when --labels is given)
    std::string style;   // .json label table or MRIcron .lut
    std::vector<std::string> show, hide;  // applied in order: show then hide
    float tint = 0.f;
    bool active() const { return !labels.empty() || !mode.empty(); }
};
void add_segment_args(CLI::App& cmd, SegmentArgs& a);

// Everything the segments frame needs besides the segment flags: the spec (renderer Segments,
// its mode, structure and tint already set) and what the report names.
struct SegmentFrame {
    const VolumeArgs& volume;
    const std::string& tf;  // mask mode
    std::string accel;      // the --accel name, for the report
    int threads = 0;
    FrameSpec spec;
    std::string out, heatmap;
    std::optional<TransferFunction>
        tf_value;  // the TF itself (a session file's), else `tf` resolved
};
void render_segments(const SegmentArgs& a, const SegmentFrame& f);

}  // namespace lacuna::cli
