// Built-in transfer functions and the "--tf" resolver. One line per preset in
// docs/transfer-functions.md; keep the two in step.
//
// lacuna's own presets are in the normalized domain: x = 0 is the visualization range's minimum,
// x = 1 its maximum. Each has exactly zero opacity below x = 0.1 (background air), so empty-space
// skipping always has something to skip. Opacity is per unit sample distance (one voxel).
// 3D Slicer's (the capitalised names, below) are in the value domain, with Slicer's values.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "lacuna/error.h"
#include "lacuna/transfer_function.h"
#include "transfer/slicer_presets.h"

namespace lacuna {

namespace {

// CT presets assume the visualization range is -1024..3071 HU (12-bit CT with the usual
// rescale intercept of -1024). hu() places a Hounsfield value on that normalized axis, rounded
// to 4 decimals (< 0.5 HU) so the presets read cleanly as JSON ("0.2867", not 17 digits).
constexpr double kHuMin = -1024.0, kHuMax = 3071.0;
double hu(double v) {
    return std::round((v - kHuMin) / (kHuMax - kHuMin) * 1e4) / 1e4;
}

TransferFunction make(std::string name, std::vector<ColorPoint> color,
                      std::vector<OpacityPoint> opacity) {
    TransferFunction tf;
    tf.name = std::move(name);
    tf.domain = TfDomain::Normalized;
    tf.color = std::move(color);
    tf.opacity = std::move(opacity);
    return tf;
}

// Opaque above bone density: transparent up to 150 HU (soft tissue, contrast-enhanced blood),
// ramping through trabecular bone (~300 HU) to nearly opaque cortical bone (>= 1000 HU).
TransferFunction ct_bone() {
    return make("ct-bone",
                {{0.0, 0.55f, 0.25f, 0.15f},
                 {hu(150), 0.55f, 0.25f, 0.15f},
                 {hu(400), 0.9f, 0.82f, 0.68f},
                 {hu(1000), 1.0f, 0.97f, 0.9f},
                 {1.0, 1.0f, 1.0f, 1.0f}},
                {{0.0, 0.f}, {hu(150), 0.f}, {hu(400), 0.6f}, {hu(1000), 0.9f}, {1.0, 0.9f}});
}

// The skin/air boundary: air (-1000 HU) is transparent, everything denser than -400 HU is an
// opaque skin-coloured shell (lungs stay hidden behind it).
TransferFunction ct_skin() {
    return make("ct-skin",
                {{0.0, 0.7f, 0.45f, 0.35f},
                 {hu(-600), 0.7f, 0.45f, 0.35f},
                 {hu(-400), 0.93f, 0.72f, 0.6f},
                 {hu(200), 0.95f, 0.76f, 0.65f},
                 {hu(1000), 1.0f, 0.95f, 0.9f},
                 {1.0, 1.0f, 0.95f, 0.9f}},
                {{0.0, 0.f}, {hu(-600), 0.f}, {hu(-400), 0.8f}, {1.0, 0.85f}});
}

// Fat (~-100 HU, yellow, faint), a dip at water, muscle (~40..60 HU, red, moderate), and a
// moderate white for bone so the skeleton gives context without hiding the muscles.
TransferFunction ct_soft_tissue() {
    return make("ct-soft-tissue",
                {{0.0, 0.8f, 0.65f, 0.35f},
                 {hu(-250), 0.8f, 0.65f, 0.35f},
                 {hu(-100), 0.95f, 0.8f, 0.45f},
                 {hu(-20), 0.85f, 0.45f, 0.35f},
                 {hu(60), 0.78f, 0.25f, 0.2f},
                 {hu(200), 0.9f, 0.6f, 0.5f},
                 {hu(700), 1.0f, 0.95f, 0.9f},
                 {1.0, 1.0f, 1.0f, 1.0f}},
                {{0.0, 0.f},
                 {hu(-250), 0.f},
                 {hu(-100), 0.08f},
                 {hu(-20), 0.03f},
                 {hu(60), 0.3f},
                 {hu(200), 0.15f},
                 {hu(700), 0.5f},
                 {1.0, 0.5f}});
}

// MRI presets are tuned on a T1 head such as mricron's ch2 (uint8): background ~0-0.04,
// CSF dark, grey matter mid-range, white matter brighter, scalp and fat brightest.

// A generic grey ramp: zero up to 0.1, then linear to a moderate 0.35.
TransferFunction mr_default() {
    return make("mr-default",
                {{0.0, 0.25f, 0.25f, 0.28f}, {0.5, 0.7f, 0.7f, 0.7f}, {1.0, 1.0f, 0.98f, 0.95f}},
                {{0.0, 0.f}, {0.1, 0.f}, {1.0, 0.35f}});
}

// The head's outer surface as an opaque skin-coloured shell: transparent up to 0.12,
// ramping to nearly opaque by 0.2.
TransferFunction mr_skin() {
    return make("mr-skin",
                {{0.0, 0.55f, 0.3f, 0.25f},
                 {0.12, 0.75f, 0.5f, 0.4f},
                 {0.2, 0.93f, 0.72f, 0.6f},
                 {0.6, 0.98f, 0.8f, 0.7f},
                 {1.0, 1.0f, 0.9f, 0.82f}},
                {{0.0, 0.f}, {0.12, 0.f}, {0.2, 0.85f}, {1.0, 0.9f}});
}

// Skull-stripped brains (ch2bet, ch2better): background and CSF transparent, grey matter pink
// and translucent, white matter cream and denser.
TransferFunction mr_brain() {
    return make("mr-brain",
                {{0.0, 0.6f, 0.3f, 0.3f},
                 {0.3, 0.8f, 0.45f, 0.45f},
                 {0.45, 0.92f, 0.6f, 0.6f},
                 {0.65, 1.0f, 0.9f, 0.78f},
                 {1.0, 1.0f, 0.97f, 0.9f}},
                {{0.0, 0.f}, {0.15, 0.f}, {0.3, 0.05f}, {0.45, 0.15f}, {0.65, 0.3f}, {1.0, 0.45f}});
}

// An opacity gap like the vessel TF of the bitfield paper's Figure 3: a translucent low-mid
// band (0.12..0.34), exactly zero over [0.34, 0.61] (brain tissue switched off), and visible
// again at the top (bright vessels and fat). Exercises skipping across a TF with holes.
TransferFunction mr_gap() {
    return make("mr-gap",
                {{0.0, 0.6f, 0.5f, 0.45f},
                 {0.18, 0.9f, 0.75f, 0.6f},
                 {0.34, 0.9f, 0.75f, 0.6f},
                 {0.61, 0.9f, 0.2f, 0.15f},
                 {1.0, 1.0f, 0.5f, 0.4f}},
                {{0.0, 0.f},
                 {0.12, 0.f},
                 {0.18, 0.12f},
                 {0.3, 0.12f},
                 {0.34, 0.f},
                 {0.61, 0.f},
                 {0.7, 0.35f},
                 {1.0, 0.6f}});
}

// A band of atlas labels (label volumes such as mricron's aal.nii.gz, values 0..116): opacity
// steps up at 0.34 and down at 0.39 of the range (AAL labels 40..45), zero elsewhere. Under
// trilinear sampling every edge between labels either side of the band passes through it; with
// --interpolation nearest only those labels show, and value sets with holes skip the rest.
TransferFunction label_band() {
    return make("label-band",
                {{0.0, 0.2f, 0.4f, 1.0f},
                 {0.34, 0.9f, 0.3f, 0.2f},
                 {0.365, 0.95f, 0.85f, 0.3f},
                 {0.39, 0.3f, 0.8f, 0.4f},
                 {1.0, 0.5f, 0.5f, 1.0f}},
                {{0.0, 0.f}, {0.34, 0.f}, {0.34, 0.8f}, {0.39, 0.8f}, {0.39, 0.f}, {1.0, 0.f}});
}

// ---- 3D Slicer's presets ------------------------------------------------------------------------
// Eight of the presets 3D Slicer ships (Modules/Loadable/VolumeRendering/Resources/presets.xml,
// Slicer's BSD-style licence), their attributes copied as Slicer writes them and read by the
// same parser as any presets.xml (slicer_presets.h): value domain (CT in HU, MR in the scanner's
// units), shading and gradient opacity as the TF's rendering. Slicer keeps the blend mode in the
// view, not the preset; the two MIP presets are meant for MIP, so they carry blend "mip". Slicer's
// gradient opacity of these eight is 1 for every magnitude (no effect; apply_tf_rendering leaves
// the feature off), kept so the JSON says what Slicer says.
constexpr const char* kSlicerXml = R"(<MRML>
  <VolumeProperty name="CT-AAA" interpolation="1" shade="1" ambient="0.1" diffuse="0.9" specular="0.2" specularPower="10"
    scalarOpacity="12 -3024 0 143.556 0 166.222 0.686275 214.389 0.696078 419.736 0.833333 3071 0.803922"
    gradientOpacity="4 0 1 255 1"
    colorTransfer="24 -3024 0 0 0 143.556 0.615686 0.356863 0.184314 166.222 0.882353 0.603922 0.290196 214.389 1 1 1 419.736 1 0.937033 0.954531 3071 0.827451 0.658824 1"/>
  <VolumeProperty name="CT-Bone" interpolation="1" shade="1" ambient="0.1" diffuse="0.9" specular="0.2" specularPower="10"
    scalarOpacity="8 -3024 0 -16.4458 0 641.385 0.715686 3071 0.705882"
    gradientOpacity="4 0 1 255 1"
    colorTransfer="16 -3024 0 0 0 -16.4458 0.729412 0.254902 0.301961 641.385 0.905882 0.815686 0.552941 3071 1 1 1"/>
  <VolumeProperty name="CT-Lung" interpolation="1" shade="1" ambient="0.2" diffuse="1" specular="0" specularPower="1"
    scalarOpacity="12 -1000 0 -600 0 -599 0.15 -400 0.15 -399 0 2952 0"
    gradientOpacity="6 0 1 985.12 1 988 1"
    colorTransfer="24 -1000 0.3 0.3 1 -600 0 0 1 -530 0.134704 0.781726 0.0724558 -460 0.929244 1 0.109473 -400 0.888889 0.254949 0.0240258 2952 1 0.3 0.3"/>
  <VolumeProperty name="CT-Soft-Tissue" interpolation="1" shade="0" ambient="0.2" diffuse="1" specular="0" specularPower="1"
    scalarOpacity="10 -2048 0 -167.01 0 -160 1 240 1 3661 1"
    gradientOpacity="4 0 1 255 1"
    colorTransfer="20 -2048 0 0 0 -167.01 0 0 0 -160 0.0556356 0.0556356 0.0556356 240 1 1 1 3661 1 1 1"/>
  <VolumeProperty name="CT-MIP" interpolation="1" shade="1" ambient="0.1" diffuse="0.9" specular="0.2" specularPower="10"
    scalarOpacity="8 -3024 0 -637.62 0 700 1 3071 1"
    gradientOpacity="4 0 1 255 1"
    colorTransfer="16 -3024 0 0 0 -637.62 1 1 1 700 1 1 1 3071 1 1 1"/>
  <VolumeProperty name="MR-Default" interpolation="1" shade="1" ambient="0.2" diffuse="1" specular="0" specularPower="1"
    scalarOpacity="12 0 0 20 0 40 0.15 120 0.3 220 0.375 1024 0.5"
    gradientOpacity="4 0 1 255 1"
    colorTransfer="24 0 0 0 0 20 0.168627 0 0 40 0.403922 0.145098 0.0784314 120 0.780392 0.607843 0.380392 220 0.847059 0.835294 0.788235 1024 1 1 1"/>
  <VolumeProperty name="MR-Angio" interpolation="1" shade="1" ambient="0.2" diffuse="1" specular="0" specularPower="1"
    scalarOpacity="12 -2048 0 151.354 0 158.279 0.4375 190.112 0.580357 200.873 0.732143 3661 0.741071"
    gradientOpacity="4 0 1 255 1"
    colorTransfer="24 -2048 0 0 0 151.354 0 0 0 158.279 0.74902 0.376471 0 190.112 1 0.866667 0.733333 200.873 0.937255 0.937255 0.937255 3661 1 1 1"/>
  <VolumeProperty name="MR-MIP" interpolation="1" shade="0" ambient="0.2" diffuse="1" specular="0" specularPower="1"
    scalarOpacity="8 0 0 98.3725 0 416.637 1 2800 1"
    gradientOpacity="4 0 1 255 1"
    colorTransfer="16 0 1 1 1 98.3725 1 1 1 416.637 1 1 1 2800 1 1 1"/>
)</MRML>)";

TransferFunction slicer_builtin(const char* name) {
    static const std::vector<SlicerVolumeProperty> props =
        parse_slicer_presets_xml(kSlicerXml, "built-in Slicer presets");
    for (const SlicerVolumeProperty& p : props) {
        if (p.name != name) continue;
        TransferFunction tf = to_transfer_function(p);
        if (p.name.ends_with("-MIP")) tf.rendering.blend = BlendMode::Mip;
        return tf;
    }
    throw Error("built-in Slicer presets", name, "missing");  // a bug in the table below
}

struct PresetEntry {
    const char* name;
    TransferFunction (*make)();
};
constexpr PresetEntry kPresets[] = {
    {"ct-bone", ct_bone},
    {"ct-skin", ct_skin},
    {"ct-soft-tissue", ct_soft_tissue},
    {"mr-default", mr_default},
    {"mr-skin", mr_skin},
    {"mr-brain", mr_brain},
    {"mr-gap", mr_gap},
    {"label-band", label_band},
    {"CT-AAA", [] { return slicer_builtin("CT-AAA"); }},
    {"CT-Bone", [] { return slicer_builtin("CT-Bone"); }},
    {"CT-Lung", [] { return slicer_builtin("CT-Lung"); }},
    {"CT-Soft-Tissue", [] { return slicer_builtin("CT-Soft-Tissue"); }},
    {"CT-MIP", [] { return slicer_builtin("CT-MIP"); }},
    {"MR-Default", [] { return slicer_builtin("MR-Default"); }},
    {"MR-Angio", [] { return slicer_builtin("MR-Angio"); }},
    {"MR-MIP", [] { return slicer_builtin("MR-MIP"); }},
};

std::string joined_names() {
    std::string s;
    for (const PresetEntry& p : kPresets) s += (s.empty() ? "" : ", ") + std::string(p.name);
    return s;
}

const PresetEntry* find_preset(const std::string& name) {
    for (const PresetEntry& p : kPresets)
        if (name == p.name) return &p;
    return nullptr;
}

}  // namespace

std::vector<std::string> preset_names() {
    std::vector<std::string> names;
    for (const PresetEntry& p : kPresets) names.emplace_back(p.name);
    return names;
}

TransferFunction preset(const std::string& name) {
    if (const PresetEntry* p = find_preset(name)) return p->make();
    throw Error("transfer function", "preset",
                "unknown preset '" + name + "'; expected one of: " + joined_names());
}

TransferFunction resolve_transfer_function(const std::string& spec) {
    if (const PresetEntry* p = find_preset(spec)) return p->make();
    // 3D Slicer presets: slicer:FILE.xml#NAME, FILE.vp, FILE.vp.json (slicer_presets.h).
    if (is_slicer_spec(spec)) return to_transfer_function(resolve_slicer_preset(spec));
    std::string lower = spec;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    std::error_code ec;
    const bool json_name = lower.ends_with(".json");
    if (json_name || std::filesystem::is_regular_file(spec, ec))
        return load_transfer_function(spec);
    throw Error("tf", "preset",
                "unknown preset '" + spec + "'; expected one of: " + joined_names() +
                    " or a .json file (or slicer:FILE.xml#NAME, FILE.vp, FILE.vp.json)");
}

}  // namespace lacuna
