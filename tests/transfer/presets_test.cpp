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

TEST(Presets, EveryPresetIsAValidNormalizedTf) {
    for (const std::string& name : preset_names()) {
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
    for (const std::string& name : preset_names()) {
        const TransferLut lut = discretise(preset(name), {0.f, 255.f}, size);
        for (int e = 0; e < size && entry_t(e, size) <= 0.1; ++e)
            EXPECT_EQ(lut.entries[e].a, 0.0f) << name << " entry " << e;
    }
}

TEST(Presets, EveryPresetIsVisibleWithModerateOpacity) {
    for (const std::string& name : preset_names()) {
        const TransferLut lut = discretise(preset(name), {0.f, 1.f});
        float peak = 0.f;
        for (const Rgba& c : lut.entries) peak = std::max(peak, c.a);
        EXPECT_GT(peak, 0.05f) << name;
        EXPECT_LE(peak, 0.9f) << name;
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
