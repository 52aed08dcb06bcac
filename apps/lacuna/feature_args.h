// `lacuna render` flags for shading, lighting, clipping, blend modes and jitter: the strings of
// the command line become lacuna::FeatureOptions here (STYLE.md habit 3). docs/cli.md, "Shading".
#pragma once
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "lacuna/frame_spec.h"
#include "lacuna/renderer.h"

namespace lacuna::cli {

struct FeatureArgs {
    std::string shading = "none";
    std::string phong, pbr;  // "KA,KD,KS,POWER" / "ROUGHNESS,METALLIC[,AMBIENT]"
    bool gradient_volume = false;
    std::string gradient_opacity;  // "LO,HI", "X:A,X:A,..." or "none"
    std::string light = "head";    // head | dir:X,Y,Z | spot:PX,PY,PZ,TX,TY,TZ[,CONE]
    float light_intensity = 1.f;
    bool shadows = false, light_volume = false, unaccelerated_shadows = false;
    float shadow_step = 1.f;
    int light_volume_stride = 2;
    std::vector<std::string> clip;  // "NX,NY,NZ,D", repeatable
    std::string crop;               // "X0,X1,Y0,Y1,Z0,Z1"
    std::string tf_back;
    std::string blend = "composite";
    bool jitter = false;
    uint32_t jitter_seed = 0;
    // Which of the flags a TF's rendering defers to were on the command line (set by the
    // subcommand from CLI11's counts; apply_tf_rendering, lacuna/frame_spec.h).
    TfRenderingOverrides given;
};

void add_feature_args(CLI::App& cmd, FeatureArgs& a);
// Throws lacuna::Error (flag, field, what was expected) on malformed values.
FeatureOptions parse_features(const FeatureArgs& a);
// One line of what the options switch on ("" when everything is off).
std::string describe(const FeatureOptions& f);

}  // namespace lacuna::cli
