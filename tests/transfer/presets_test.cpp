// Built-in presets and the "--tf" resolver.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "lacuna/error.h"
#include "lacuna/transfer_function.h"
#include "transfer/transfer_test_util.h"

namespace lacuna {
namespace {

double entry_t(int e, int size) {
    return double(e) / double(size - 1);
}

using test::error_message;
using test::temp_path;

TEST(Presets, ListsAllRequiredNames) {
    const std::vector<std::string> names = preset_names();
    for (const char* required :
         {"ct-bone", "ct-skin", "ct-soft-tissue", "mr-default", "mr-skin", "mr-brain", "mr-gap"}) {
        EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
    }
}

// 3D Slicer's presets (capitalised names, value domain) are checked below; the rules of
// lacuna's own presets hold for the rest.
const char* const kSlicerNames[] = {"CT-AAA", "CT-Bone",    "CT-Lung",  "CT-Soft-Tissue",
                                    "CT-MIP", "MR-Default", "MR-Angio", "MR-MIP"};
bool is_slicer(const std::string& name) {
    return std::find(std::begin(kSlicerNames), std::end(kSlicerNames), name) !=
           std::end(kSlicerNames);
}
std::vector<std::string> lacuna_preset_names() {
    std::vector<std::string> out;
    for (const std::string& n : preset_names())
        if (!is_slicer(n)) out.push_back(n);
    return out;
}

TEST(Presets, EveryPresetIsAValidNormalizedTf) {
    for (const std::string& name : lacuna_preset_names()) {
        const TransferFunction tf = preset(name);
        EXPECT_EQ(tf.name, name);
        EXPECT_EQ(tf.domain, TfDomain::Normalized) << name;
        EXPECT_FALSE(tf.range.has_value()) << name;
        EXPECT_NO_THROW(discretise(tf, {0.f, 255.f})) << name;
        // The JSON reader runs the full validation.
        EXPECT_NO_THROW(parse_transfer_function(to_json(tf), name + ".json")) << name;
    }
}

TEST(Presets, EveryPresetIsTransparentOverLowestTenthOfRange) {
    const int size = kDefaultLutSize;
    for (const std::string& name : lacuna_preset_names()) {
        const TransferLut lut = discretise(preset(name), {0.f, 255.f}, size);
        for (int e = 0; e < size && entry_t(e, size) <= 0.1; ++e)
            EXPECT_EQ(lut.entries[e].a, 0.0f) << name << " entry " << e;
    }
}

TEST(Presets, EveryPresetIsVisibleWithModerateOpacity) {
    for (const std::string& name : lacuna_preset_names()) {
        const TransferLut lut = discretise(preset(name), {0.f, 1.f});
        float peak = 0.f;
        for (const Rgba& c : lut.entries) peak = std::max(peak, c.a);
        EXPECT_GT(peak, 0.05f) << name;
        EXPECT_LE(peak, 0.9f) << name;
    }
}

// The Slicer presets hold Slicer's numbers (presets.xml), read back through the same parser as a
// user's presets.xml: spot checks against the file's text, and the rendering of each.
TEST(Presets, SlicerPresetsHoldSlicersValues) {
    for (const char* name : kSlicerNames) {
        const TransferFunction tf = preset(name);
        EXPECT_EQ(tf.name, name);
        EXPECT_EQ(tf.domain, TfDomain::Value) << name;
        EXPECT_FALSE(tf.range) << name;
        EXPECT_EQ(parse_transfer_function(to_json(tf), "x.json"), tf) << name;
        // Slicer's gradient opacity of these eight: 1 for every magnitude.
        ASSERT_FALSE(tf.rendering.gradient_opacity.empty()) << name;
        for (const OpacityPoint& p : tf.rendering.gradient_opacity) EXPECT_EQ(p.a, 1.f) << name;
        EXPECT_EQ(tf.rendering.blend.has_value(), std::string(name).ends_with("-MIP")) << name;
        if (tf.rendering.blend) EXPECT_EQ(*tf.rendering.blend, BlendMode::Mip);
    }
    // CT-Bone: scalarOpacity="8 -3024 0 -16.4458 0 641.385 0.715686 3071 0.705882", shade 1,
    // ambient 0.1, diffuse 0.9, specular 0.2, specularPower 10.
    const TransferFunction bone = preset("CT-Bone");
    EXPECT_EQ(bone.opacity,
              (std::vector<OpacityPoint>{
                  {-3024, 0.f}, {-16.4458, 0.f}, {641.385, 0.715686f}, {3071, 0.705882f}}));
    EXPECT_EQ(bone.color.size(), 4u);
    EXPECT_EQ(bone.color[2], (ColorPoint{641.385, 0.905882f, 0.815686f, 0.552941f}));
    ASSERT_TRUE(bone.rendering.shading);
    EXPECT_EQ(*bone.rendering.shading, (TfShading{0.1f, 0.9f, 0.2f, 10.f}));
    // MR-Default: shade 1 with ambient 0.2, diffuse 1, specular 0, power 1.
    ASSERT_TRUE(preset("MR-Default").rendering.shading);
    EXPECT_EQ(*preset("MR-Default").rendering.shading, (TfShading{0.2f, 1.f, 0.f, 1.f}));
    EXPECT_EQ(preset("MR-Default").opacity.back(), (OpacityPoint{1024, 0.5f}));
    // shade="0" presets carry no shading.
    EXPECT_FALSE(preset("CT-Soft-Tissue").rendering.shading);
    EXPECT_FALSE(preset("MR-MIP").rendering.shading);
    // CT-Lung: the two steps of its opacity (-600/-599 and -400/-399).
    EXPECT_EQ(preset("CT-Lung").opacity.size(), 6u);
    EXPECT_EQ(preset("CT-Lung").opacity[2], (OpacityPoint{-599, 0.15f}));
    // Every Slicer preset is transparent at its lowest values (air, background): skippable.
    for (const char* name : kSlicerNames) {
        const TransferFunction tf = preset(name);
        const TransferLut lut = discretise(tf, {float(tf.opacity.front().x), 3071.f});
        EXPECT_EQ(lut.entries.front().a, 0.f) << name;
    }
}

TEST(Presets, MrGapHasExactZeroGapWithVisibleBandsOnBothSides) {
    const int size = kDefaultLutSize;
    const TransferLut lut = discretise(preset("mr-gap"), {0.f, 255.f}, size);
    bool visible_below = false, visible_above = false;
    for (int e = 0; e < size; ++e) {
        const double t = entry_t(e, size);
        if (t >= 0.35 && t <= 0.6) EXPECT_EQ(lut.entries[e].a, 0.0f) << "entry " << e;
        if (t < 0.35 && lut.entries[e].a > 0.f) visible_below = true;
        if (t > 0.6 && lut.entries[e].a > 0.f) visible_above = true;
    }
    EXPECT_TRUE(visible_below);
    EXPECT_TRUE(visible_above);
}

TEST(Presets, MrSkinIsAnOpaqueShellAboveSkinThreshold) {
    const int size = kDefaultLutSize;
    const TransferLut lut = discretise(preset("mr-skin"), {0.f, 255.f}, size);
    for (int e = 0; e < size; ++e) {
        const double t = entry_t(e, size);
        if (t <= 0.12) EXPECT_EQ(lut.entries[e].a, 0.0f) << "entry " << e;
        if (t >= 0.2) EXPECT_GE(lut.entries[e].a, 0.8f) << "entry " << e;
    }
}

TEST(Presets, CtPresetsFollowTheHounsfieldAssumption) {
    // Presets assume vis = -1024..3071 HU; read them through the LUT mapping like a renderer.
    const ValueRange hu{-1024.f, 3071.f};
    auto opacity_at = [&](const std::string& name, float v) {
        const TransferLut lut = discretise(preset(name), hu);
        return lut.entries[lut.map()(v)].a;
    };
    EXPECT_EQ(opacity_at("ct-bone", -1000.f), 0.f);  // air
    EXPECT_EQ(opacity_at("ct-bone", 40.f), 0.f);     // muscle
    EXPECT_GT(opacity_at("ct-bone", 1200.f), 0.8f);  // cortical bone
    EXPECT_EQ(opacity_at("ct-skin", -1000.f), 0.f);
    EXPECT_GT(opacity_at("ct-skin", 0.f), 0.7f);  // skin and everything behind it
    EXPECT_EQ(opacity_at("ct-soft-tissue", -1000.f), 0.f);
    EXPECT_GT(opacity_at("ct-soft-tissue", -100.f), 0.f);  // fat
    EXPECT_GT(opacity_at("ct-soft-tissue", 50.f), opacity_at("ct-soft-tissue", -100.f));
}

TEST(Presets, UnknownPresetListsValidNames) {
    const std::string msg = error_message([] { preset("ct-bones"); });
    EXPECT_NE(msg.find("'ct-bones'"), std::string::npos) << msg;
    for (const std::string& name : preset_names())
        EXPECT_NE(msg.find(name), std::string::npos) << msg;
}

TEST(Presets, ResolvesPresetNames) {
    EXPECT_EQ(resolve_transfer_function("mr-gap"), preset("mr-gap"));
}

TEST(Presets, ResolvesJsonFiles) {
    const std::string path = temp_path("custom.json");
    TransferFunction tf = preset("ct-bone");
    tf.name = "custom";
    std::ofstream(path) << to_json(tf);
    EXPECT_EQ(resolve_transfer_function(path), tf);
    std::filesystem::remove(path);
}

TEST(Presets, ResolveRejectsUnknownNameWithChoices) {
    const std::string msg = error_message([] { resolve_transfer_function("bone"); });
    EXPECT_EQ(msg.rfind("tf: preset: unknown preset 'bone'; expected one of: ", 0), 0u) << msg;
    EXPECT_NE(msg.find("mr-gap"), std::string::npos) << msg;
    EXPECT_NE(msg.find(".json"), std::string::npos) << msg;
}

TEST(Presets, ResolveReportsMissingJsonFile) {
    const std::string path = temp_path("missing.json");
    const std::string msg = error_message([&] { resolve_transfer_function(path); });
    EXPECT_EQ(msg.rfind(path + ": file: ", 0), 0u) << msg;
}

}  // namespace
}  // namespace lacuna
