#include "feature_args.h"

#include <cmath>
#include <cstdlib>

#include "lacuna/error.h"

namespace lacuna::cli {

namespace {

// Comma-separated finite floats; exactly `n` of them (or n..n_max).
std::vector<float> floats(const std::string& s, const char* flag, const char* what, size_t n,
                          size_t n_max = 0) {
    std::vector<float> out;
    size_t pos = 0;
    for (;;) {
        const size_t c = s.find(',', pos);
        const std::string tok = s.substr(pos, c == std::string::npos ? std::string::npos : c - pos);
        char* end = nullptr;
        const float v = std::strtof(tok.c_str(), &end);
        if (tok.empty() || end != tok.c_str() + tok.size() || !std::isfinite(v))
            throw Error(flag, what, "expected numbers separated by commas, got '" + s + "'");
        out.push_back(v);
        if (c == std::string::npos) break;
        pos = c + 1;
    }
    if (out.size() < n || out.size() > std::max(n, n_max))
        throw Error(flag, what,
                    "expected " + std::to_string(n) +
                        (n_max > n ? ".." + std::to_string(n_max) : std::string()) +
                        " numbers, got '" + s + "'");
    return out;
}

// --gradient-opacity X:A,X:A,...: the points of a piecewise-linear factor (validate_features
// checks their order and ranges).
std::vector<GradientOpacityPoint> gradient_points(const std::string& s) {
    std::vector<GradientOpacityPoint> out;
    size_t pos = 0;
    for (;;) {
        const size_t c = s.find(',', pos);
        const std::string tok = s.substr(pos, c == std::string::npos ? std::string::npos : c - pos);
        const size_t colon = tok.find(':');
        if (colon == std::string::npos)
            throw Error("--gradient-opacity", "points",
                        "expected X:A pairs separated by commas, got '" + s + "'");
        const auto x = floats(tok.substr(0, colon), "--gradient-opacity", "points", 1);
        const auto v = floats(tok.substr(colon + 1), "--gradient-opacity", "points", 1);
        out.push_back({x[0], v[0]});
        if (c == std::string::npos) break;
        pos = c + 1;
    }
    return out;
}

}  // namespace

void add_feature_args(CLI::App& cmd, FeatureArgs& a) {
    const char* g = "Shading and clipping";
    cmd.add_option("--shading", a.shading, "Shading model: none, phong, pbr")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--phong", a.phong,
                   "Blinn-Phong terms KA,KD,KS,POWER (default 0.25,0.7,0.35,24)")
        ->group(g);
    cmd.add_option("--pbr", a.pbr, "PBR ROUGHNESS,METALLIC[,AMBIENT] (default 0.45,0,0.2)")
        ->group(g);
    cmd.add_flag(
           "--gradient-volume", a.gradient_volume,
           "Precompute a gradient volume (12 bytes per voxel) instead of on-the-fly gradients")
        ->group(g);
    cmd.add_option(
           "--gradient-opacity", a.gradient_opacity,
           "Gradient-magnitude opacity (|grad| in values per mm): a ramp LO,HI (opacity x 0 "
           "below LO, x 1 above HI), points X:A,X:A,... (piecewise linear), or none")
        ->group(g);
    cmd.add_option(
           "--light", a.light,
           "Light: head, dir:X,Y,Z (toward the light), spot:PX,PY,PZ,TX,TY,TZ[,CONE] (world mm, "
           "cone half-angle in degrees, default 30)")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--light-intensity", a.light_intensity, "Light intensity")
        ->capture_default_str()
        ->group(g);
    cmd.add_flag("--shadows", a.shadows,
                 "Shadow rays toward the light through the skipping structure")
        ->group(g);
    cmd.add_option("--shadow-step", a.shadow_step,
                   "Shadow-ray sample distance (smallest voxel spacings)")
        ->capture_default_str()
        ->group(g);
    cmd.add_flag("--unaccelerated-shadows", a.unaccelerated_shadows,
                 "March every shadow-ray sample (the reference for --shadows)")
        ->group(g);
    cmd.add_flag("--light-volume", a.light_volume,
                 "With --shadows: precompute the transmittance toward the light on a voxel grid")
        ->group(g);
    cmd.add_option("--light-volume-stride", a.light_volume_stride, "Light volume: every N-th voxel")
        ->capture_default_str()
        ->group(g);
    cmd.add_option("--clip", a.clip,
                   "Clip plane NX,NY,NZ,D (world mm): keeps dot(n,p) >= D; repeatable")
        ->take_all()
        ->group(g);
    cmd.add_option("--crop", a.crop, "Crop box X0,X1,Y0,Y1,Z0,Z1 (world mm)")->group(g);
    cmd.add_option(
           "--tf-back", a.tf_back,
           "TF on the back side of the first --clip plane (which then splits instead of clipping)")
        ->group(g);
    cmd.add_option("--blend", a.blend, "Blend mode: composite, mip, minip, average")
        ->capture_default_str()
        ->group(g);
    cmd.add_flag("--jitter", a.jitter, "Jittered ray starts (deterministic per pixel)")->group(g);
    cmd.add_option("--jitter-seed", a.jitter_seed, "Seed of --jitter")
        ->capture_default_str()
        ->group(g);
}

FeatureOptions parse_features(const FeatureArgs& a) {
    FeatureOptions f;
    if (a.shading == "none")
        f.shading = ShadingModel::None;
    else if (a.shading == "phong")
        f.shading = ShadingModel::Phong;
    else if (a.shading == "pbr")
        f.shading = ShadingModel::Pbr;
    else
        throw Error("--shading", "model",
                    "unknown '" + a.shading + "'; expected one of: none, phong, pbr");
    if (!a.phong.empty()) {
        const auto v = floats(a.phong, "--phong", "terms", 4);
        f.phong = {v[0], v[1], v[2], v[3]};
    }
    if (!a.pbr.empty()) {
        const auto v = floats(a.pbr, "--pbr", "parameters", 2, 3);
        f.pbr.roughness = v[0];
        f.pbr.metallic = v[1];
        if (v.size() == 3) f.pbr.ambient = v[2];
    }
    f.gradient = a.gradient_volume ? GradientSource::Precomputed : GradientSource::OnTheFly;
    if (a.gradient_opacity == "none") {
        f.gradient_opacity = {};
    } else if (a.gradient_opacity.find(':') != std::string::npos) {
        f.gradient_opacity.enabled = true;
        f.gradient_opacity.points = gradient_points(a.gradient_opacity);
    } else if (!a.gradient_opacity.empty()) {
        const auto v = floats(a.gradient_opacity, "--gradient-opacity", "ramp", 2);
        f.gradient_opacity.enabled = true;
        f.gradient_opacity.lo = v[0];
        f.gradient_opacity.hi = v[1];
    }
    if (a.light == "head") {
        f.light.kind = LightKind::Head;
    } else if (a.light.rfind("dir:", 0) == 0) {
        const auto v = floats(a.light.substr(4), "--light", "direction", 3);
        f.light.kind = LightKind::Directional;
        f.light.direction = {v[0], v[1], v[2]};
    } else if (a.light.rfind("spot:", 0) == 0) {
        const auto v = floats(a.light.substr(5), "--light", "spot", 6, 7);
        f.light.kind = LightKind::Spot;
        f.light.position = {v[0], v[1], v[2]};
        f.light.target = {v[3], v[4], v[5]};
        if (v.size() == 7) f.light.cone_deg = v[6];
    } else {
        throw Error(
            "--light", "light",
            "unknown '" + a.light + "'; expected head, dir:X,Y,Z or spot:PX,PY,PZ,TX,TY,TZ[,CONE]");
    }
    f.light.intensity = a.light_intensity;
    f.shadows.enabled = a.shadows;
    f.shadows.accelerate = !a.unaccelerated_shadows;
    f.shadows.step = a.shadow_step;
    f.shadows.light_volume = a.light_volume;
    f.shadows.light_volume_stride = a.light_volume_stride;
    if ((a.light_volume || a.unaccelerated_shadows) && !a.shadows)
        throw Error(a.light_volume ? "--light-volume" : "--unaccelerated-shadows", "shadows",
                    "expected --shadows as well");
    for (const std::string& c : a.clip) {
        const auto v = floats(c, "--clip", "plane", 4);
        f.clip_planes.push_back({{v[0], v[1], v[2]}, v[3]});
    }
    if (!a.crop.empty()) {
        const auto v = floats(a.crop, "--crop", "box", 6);
        f.crop = true;
        f.crop_box = {{v[0], v[2], v[4]}, {v[1], v[3], v[5]}};
    }
    if (!a.tf_back.empty() && a.clip.empty())
        throw Error("--tf-back", "clip plane", "expected a --clip plane to split the two TFs at");
    if (a.blend == "composite")
        f.blend = BlendMode::Composite;
    else if (a.blend == "mip")
        f.blend = BlendMode::Mip;
    else if (a.blend == "minip")
        f.blend = BlendMode::MinIp;
    else if (a.blend == "average")
        f.blend = BlendMode::Average;
    else
        throw Error("--blend", "mode",
                    "unknown '" + a.blend + "'; expected one of: composite, mip, minip, average");
    f.jitter = a.jitter;
    f.jitter_seed = a.jitter_seed;
    validate_features(f);
    return f;
}

std::string describe(const FeatureOptions& f) {
    std::string s;
    auto add = [&](const std::string& x) { s += (s.empty() ? "" : ", ") + x; };
    if (f.shading != ShadingModel::None)
        add("shading " + to_string(f.shading) +
            (f.gradient == GradientSource::Precomputed ? " (gradient volume)"
                                                       : " (on-the-fly gradients)"));
    if (f.gradient_opacity.enabled) add("gradient opacity");
    if (f.shading != ShadingModel::None || f.shadows.enabled)
        add("light " + to_string(f.light.kind));
    if (f.shadows.enabled)
        add(std::string("shadows") + (f.shadows.light_volume ? " (light volume)" : "") +
            (f.shadows.accelerate ? "" : " (unaccelerated)"));
    if (!f.clip_planes.empty()) add(std::to_string(f.clip_planes.size()) + " clip plane(s)");
    if (f.crop) add("crop box");
    if (f.blend != BlendMode::Composite) add("blend " + to_string(f.blend));
    if (f.jitter) add("jitter");
    return s;
}

}  // namespace lacuna::cli
