// `lacuna render --labels ...`: segment visibility flags (include/lacuna/segments.h). Kept apart
// from cmd_render.cpp so the render command only forwards to it.
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "cli_common.h"
#include "lacuna/renderer.h"

namespace lacuna::cli {

struct SegmentArgs {
    std::string labels;       // label volume (mask mode); empty with --segments labels: the volume
    std::string mode;         // "mask" | "labels" (default: mask when --labels is given)
    std::string style;        // .json label table or MRIcron .lut
    std::vector<std::string> show, hide;  // applied in order: show then hide
    float tint = 0.f;
    bool active() const { return !labels.empty() || !mode.empty(); }
};
void add_segment_args(CLI::App& cmd, SegmentArgs& a);

// Everything render_one needs besides the segment flags.
struct SegmentFrame {
    const VolumeArgs& volume;
    const std::string& tf;       // mask mode
    const std::string& accel;    // "none" or "bitfield"
    int leaf = 8, bits = 64;
    RenderOptions ro;
    OrbitParams op;
    int w = 0, h = 0;
    std::string out, heatmap;
};
void render_segments(const SegmentArgs& a, const SegmentFrame& f);

}  // namespace lacuna::cli
