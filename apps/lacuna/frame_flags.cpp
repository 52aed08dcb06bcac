#include "frame_flags.h"

#include <utility>

namespace lacuna::cli {

namespace {

// Field prefixes of FrameSpec and the flag that sets them.
constexpr std::pair<const char*, const char*> kFlags[] = {
    {"width", "--size"},
    {"height", "--size"},
    {"camera.orbit.zoom", "--zoom"},
    {"camera.orbit.fov_y_deg", "--fov"},
    {"camera.orbit", "--azimuth/--elevation"},
    {"background", "--background"},
    {"sampling.step", "--step"},
    {"sampling.early_termination", "--ert"},
    {"sampling.interpolation", "--interpolation"},
    {"structure.octree.leaf_cells", "--leaf"},
    {"structure.leaf_cells", "--leaf"},
    {"structure.bits", "--bits"},
    {"structure.max_boxes", "--max-boxes"},
    {"structure.delta", "--delta"},
    {"structure.min_volume", "--min-volume"},
    {"structure.min_gain", "--min-gain"},
    {"structure.max_depth", "--max-depth"},
    {"structure.threshold", "--threshold"},
    {"structure.spread", "--spread"},
    {"structure.min_uniform", "--min-box"},
    {"structure.gradient", "--gradient"},
    {"structure.gradient_waste", "--gradient-waste"},
    {"structure.other_cost", "--other-cost"},
    {"structure.thin", "--thin"},
    {"threads", "--threads"},
    {"structure.coalesce_edge", "--coalesce-edge"},
    {"structure.coalesce", "--coalesce"},
    {"structure", "--accel"},
    {"features.shading", "--shading"},
    {"features.phong", "--phong"},
    {"features.pbr", "--pbr"},
    {"features.gradient_opacity", "--gradient-opacity"},
    {"features.light.intensity", "--light-intensity"},
    {"features.light", "--light"},
    {"features.shadows.step", "--shadow-step"},
    {"features.shadows.light_volume_stride", "--light-volume-stride"},
    {"features.shadows", "--shadows"},
    {"features.clip_planes", "--clip"},
    {"features.crop_box", "--crop"},
    {"features.crop", "--crop"},
    {"features.blend", "--blend"},
    {"features.jitter", "--jitter"},
    {"features", "--shading/--light/--clip"},
    {"two_tfs", "--tf-back"},
    {"count_samples", "--heatmap"},
    {"slicer.occlusion_threshold", "--occlusion-threshold"},
    {"slicer.occlusion_map", "--occlusion-map"},
    {"slicer.occlusion", "--occlusion"},
    {"segments.tint", "--label-tint"},
    {"segments.mode", "--segments"},
    {"segments", "--segments"},
};

}  // namespace

std::string flag_of_field(const std::string& field) {
    size_t best = 0;
    std::string flag = "render";
    for (const auto& [prefix, f] : kFlags) {
        const std::string p = prefix;
        const bool match = field.compare(0, p.size(), p) == 0 &&
                           (field.size() == p.size() || field[p.size()] == '.');
        if (match && p.size() > best) best = p.size(), flag = f;
    }
    return flag;
}

std::string with_flag(const std::string& what) {
    constexpr std::pair<const char*, const char*> kWheres[] = {
        {"tf: ", "--tf"}, {"serve: host: ", "--host"}, {"serve: port: ", "--port"}};
    for (const auto& [prefix, flag] : kWheres)
        if (what.rfind(prefix, 0) == 0) return std::string(flag) + ": " + what;
    return what;
}

void validate_flags(const FrameSpec& spec) {
    try {
        validate(spec);
    } catch (const FrameError& e) {
        throw Error(flag_of_field(e.field()), e.field(), e.expected());
    }
}

}  // namespace lacuna::cli
