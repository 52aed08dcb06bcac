// `lacuna render --renderer slice`: the object-order slice renderer (docs/slicer.md). Kept out of
// cmd_render.cpp so the ray-marcher path stays as it was.
#pragma once
#include <optional>
#include <string>

#include "cli_common.h"
#include "lacuna/frame_spec.h"
#include "lacuna/transfer_function.h"
#include "slice/growing_boxes.h"

namespace lacuna::cli {

struct SliceCliArgs {
    std::string renderer = "march";  // march | slice
    bool occlusion = false;
    float occlusion_threshold = 0.95f;
    int occlusion_map = 64;
    float coalesce = BoxesOptions{}.coalesce;
    float coalesce_edge = BoxesOptions{}.coalesce_edge;
    bool threshold_given = false, map_given = false, coalesce_given = false;
};
void add_slice_options(CLI::App& cmd, SliceCliArgs& a);
// Throws lacuna::Error for an unknown renderer or flags that do not fit it. `animate` and
// `heatmap`: whether --tf-animate / --heatmap were given (the slicer has neither).
void check_slice_options(const SliceCliArgs& a, bool animate, bool heatmap);

// One slicer frame through lacuna::Session: the spec (renderer Slicer) and what the report names.
struct SliceRenderJob {
    VolumeArgs volume;
    std::string tf, accel, out;  // accel: the --accel name, for the report
    int threads = 0;
    FrameSpec spec;
    std::optional<TransferFunction> tf_value;  // a session file's TF (instead of resolving `tf`)
};
void render_slice(const SliceRenderJob& job);

}  // namespace lacuna::cli
