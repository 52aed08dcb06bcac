#include "transfer/slicer_presets.h"

#include <gtest/gtest.h>

#include <string>

#include "lacuna/error.h"
#include "lacuna/transfer_function.h"

namespace lacuna {
namespace {

const std::string kData = std::string(LACUNA_SOURCE_DIR) + "/tests/data/";

// The error message of f(), or "" when it does not throw lacuna::Error.
template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

std::string xml_with(const std::string& attrs) {
    return "<MRML>\n<VolumeProperty name=\"Bad\" " + attrs + "/>\n</MRML>\n";
}

TEST(SlicerPresets, ParsesPresetsXmlWithTheFilesNumbers) {
    const auto all = load_slicer_file(kData + "slicer-presets.xml");
    ASSERT_EQ(all.size(), 3u);
    const SlicerVolumeProperty& bone = all[0];
    EXPECT_EQ(bone.name, "Lacuna-CT-Bone");
    EXPECT_EQ(bone.interpolation, SlicerInterpolation::Linear);
    EXPECT_TRUE(bone.shading.shade);
    EXPECT_EQ(bone.shading.ambient, 0.15f);
    EXPECT_EQ(bone.shading.diffuse, 0.8f);
    EXPECT_EQ(bone.shading.specular, 0.3f);
    EXPECT_EQ(bone.shading.specular_power, 20.f);
    const std::vector<OpacityPoint> op{{-1024, 0.f}, {180, 0.f}, {500, 0.55f}, {3071, 0.85f}};
    EXPECT_EQ(bone.scalar_opacity, op);
    const std::vector<OpacityPoint> grad{{0, 1.f}, {900, 1.f}};
    EXPECT_EQ(bone.gradient_opacity, grad);
    const std::vector<ColorPoint> col{{-1024, 0.5f, 0.2f, 0.1f},
                                      {180, 0.6f, 0.3f, 0.2f},
                                      {500, 0.92f, 0.85f, 0.7f},
                                      {3071, 1.f, 1.f, 0.95f}};
    EXPECT_EQ(bone.color, col);
    ASSERT_TRUE(bone.effective_range);
    EXPECT_EQ(bone.effective_range->min, -1024.f);
    EXPECT_EQ(bone.effective_range->max, 3071.f);

    const SlicerVolumeProperty& mr = all[1];
    EXPECT_FALSE(mr.effective_range);
    EXPECT_FALSE(mr.shading.shade);
    EXPECT_EQ(mr.shading.ambient, 0.2f);
    EXPECT_EQ(mr.scalar_opacity.size(), 5u);
    EXPECT_EQ(mr.scalar_opacity[2], (OpacityPoint{90, 0.12f}));
    EXPECT_EQ(mr.gradient_opacity.size(), 3u);
    EXPECT_EQ(mr.color[1], (ColorPoint{90, 0.85f, 0.55f, 0.5f}));
}

TEST(SlicerPresets, FollowsVtkForDuplicateAndUnsortedPoints) {
    const auto all = load_slicer_file(kData + "slicer-presets.xml");
    const SlicerVolumeProperty& step = all[2];
    EXPECT_EQ(step.interpolation, SlicerInterpolation::Nearest);
    // "0 0, 100 0.2, 100 0.4, 255 0.4": the later point at 100 replaces the earlier one.
    const std::vector<OpacityPoint> op{{0, 0.f}, {100, 0.4f}, {255, 0.4f}};
    EXPECT_EQ(step.scalar_opacity, op);
    // Colour points given as 255 then 0: sorted.
    const std::vector<ColorPoint> col{{0, 0.f, 0.f, 0.f}, {255, 1.f, 1.f, 1.f}};
    EXPECT_EQ(step.color, col);
    // Schema defaults where the entry says nothing.
    EXPECT_EQ(step.shading.diffuse, 0.7f);
    EXPECT_TRUE(step.gradient_opacity.empty());
}

TEST(SlicerPresets, VpAndVpJsonCarryTheSameFields) {
    const SlicerVolumeProperty vp = resolve_slicer_preset(kData + "lacuna-mr.vp");
    EXPECT_EQ(vp.name, "lacuna-mr");
    EXPECT_TRUE(vp.shading.shade);
    EXPECT_EQ(vp.shading.diffuse, 0.9f);
    EXPECT_EQ(vp.shading.ambient, 0.1f);
    EXPECT_EQ(vp.shading.specular, 0.2f);
    EXPECT_EQ(vp.shading.specular_power, 10.f);
    const std::vector<OpacityPoint> op{{0, 0.f}, {30, 0.f}, {80, 0.2f}, {150, 0.35f}, {255, 0.5f}};
    EXPECT_EQ(vp.scalar_opacity, op);
    EXPECT_EQ(vp.gradient_opacity.size(), 2u);
    EXPECT_EQ(vp.color.size(), 3u);
    EXPECT_EQ(vp.color[1], (ColorPoint{80, 0.8f, 0.5f, 0.45f}));

    // The .vp.json holds the numbers of Lacuna-CT-Bone in presets.xml.
    const SlicerVolumeProperty js = resolve_slicer_preset("slicer:" + kData + "lacuna-ct.vp.json");
    const SlicerVolumeProperty xml =
        resolve_slicer_preset("slicer:" + kData + "slicer-presets.xml#Lacuna-CT-Bone");
    EXPECT_EQ(js.name, "0");
    EXPECT_EQ(js.scalar_opacity, xml.scalar_opacity);
    EXPECT_EQ(js.gradient_opacity, xml.gradient_opacity);
    EXPECT_EQ(js.color, xml.color);
    EXPECT_EQ(js.shading, xml.shading);
    ASSERT_TRUE(js.effective_range);
    EXPECT_EQ(js.effective_range->min, xml.effective_range->min);
    EXPECT_EQ(js.effective_range->max, xml.effective_range->max);
    EXPECT_EQ(resolve_slicer_preset(kData + "lacuna-ct.vp.json#0").scalar_opacity,
              js.scalar_opacity);
}

TEST(SlicerPresets, ConvertsToTheSameTfAsOurJson) {
    const TransferFunction ours = load_transfer_function(kData + "lacuna-ct-bone-value.json");
    const TransferFunction slicer =
        resolve_transfer_function("slicer:" + kData + "slicer-presets.xml#Lacuna-CT-Bone");
    EXPECT_EQ(slicer, ours);  // with the rendering: our JSON writes the shading terms too
    EXPECT_EQ(slicer.domain, TfDomain::Value);
    // shade="1": the rendering holds the four terms as the file has them; the gradient
    // opacity (1 at 0 and 900) is kept as written.
    ASSERT_TRUE(slicer.rendering.shading);
    EXPECT_EQ(*slicer.rendering.shading, (TfShading{0.15f, 0.8f, 0.3f, 20.f}));
    EXPECT_EQ(slicer.rendering.gradient_opacity, (std::vector<OpacityPoint>{{0, 1.f}, {900, 1.f}}));
    EXPECT_FALSE(slicer.rendering.blend);
    // The effective range wins over the volume's range, so both LUTs agree entry for entry.
    const TransferLut a = discretise(slicer, {0.f, 255.f}), b = discretise(ours, {0.f, 255.f});
    ASSERT_EQ(a.entries.size(), b.entries.size());
    for (size_t e = 0; e < a.entries.size(); ++e) ASSERT_EQ(a.entries[e], b.entries[e]) << e;
    EXPECT_EQ(a.vis.min, -1024.f);
    EXPECT_EQ(a.vis.max, 3071.f);
    // Below 180 HU the imported opacity is exactly zero (skippable), as in the file.
    const int e180 = a.map()(180.f);
    for (int e = 0; e < e180; ++e) EXPECT_EQ(a.entries[size_t(e)].a, 0.f) << e;
    EXPECT_GT(a.entries.back().a, 0.8f);
    // Without an effective range, the volume's range is used.
    const TransferFunction mr =
        resolve_transfer_function("slicer:" + kData + "slicer-presets.xml#Lacuna-MR-Brain");
    EXPECT_FALSE(mr.range);
    EXPECT_EQ(discretise(mr, {0.f, 255.f}).vis.max, 255.f);
    // shade="0": no shading; its gradient opacity (0.5 at 0, 1 from 20 on) is kept.
    EXPECT_FALSE(mr.rendering.shading);
    EXPECT_EQ(mr.rendering.gradient_opacity,
              (std::vector<OpacityPoint>{{0, 0.5f}, {20, 1.f}, {255, 1.f}}));
    // .vp.json's disableGradientOpacity drops it.
    SlicerVolumeProperty off =
        resolve_slicer_preset("slicer:" + kData + "slicer-presets.xml#Lacuna-MR-Brain");
    off.gradient_opacity_enabled = false;
    EXPECT_TRUE(to_transfer_function(off).rendering.gradient_opacity.empty());
}

TEST(SlicerPresets, MalformedEntriesNameFileEntryAndField) {
    struct Case {
        std::string xml, needle;
    };
    const std::string ok_color = "colorTransfer=\"8 0 0 0 0 255 1 1 1\"";
    const std::string ok_op = "scalarOpacity=\"4 0 0 255 1\"";
    const Case cases[] = {
        {xml_with(ok_color), "VolumeProperty \"Bad\" (line 2): scalarOpacity: missing"},
        {xml_with(ok_op), "colorTransfer: missing"},
        {xml_with("scalarOpacity=\"6 0 0 255 1\" " + ok_color),
         "scalarOpacity: expected 6 numbers after the count, got 4"},
        {xml_with("scalarOpacity=\"3 0 0 255\" " + ok_color),
         "scalarOpacity: expected a count N that is a positive multiple of 2"},
        {xml_with("scalarOpacity=\"4 0 0 255 1.5\" " + ok_color),
         "scalarOpacity[1]: expected opacity in [0,1], got 1.5"},
        {xml_with("scalarOpacity=\"4 0 0 abc 1\" " + ok_color),
         "scalarOpacity: expected finite numbers, got 'abc'"},
        {xml_with(ok_op + " colorTransfer=\"8 0 0 0 0 255 1 2 1\""),
         "colorTransfer[1]: expected g in [0,1], got 2"},
        {xml_with(ok_op + " " + ok_color + " effectiveRange=\"5 1\""),
         "effectiveRange: expected two finite numbers lo < hi, got '5 1'"},
        {xml_with(ok_op + " " + ok_color + " effectiveRange=\"5\""),
         "effectiveRange: expected two numbers"},
        {xml_with(ok_op + " " + ok_color + " shade=\"yes\""), "shade: expected 0 or 1, got 'yes'"},
        {xml_with(ok_op + " " + ok_color + " ambient=\"1.5\""),
         "ambient: expected ambient in [0,1], got 1.5"},
        {xml_with(ok_op + " " + ok_color + " interpolation=\"2\""),
         "interpolation: expected 0 (nearest) or 1 (linear), got '2'"},
        {"<MRML><VolumeProperty " + ok_op + "/></MRML>", "expected a non-empty name attribute"},
        {"<MRML><VolumeProperty name=\"a\" " + ok_op + "></MRML>",
         "xml: not well-formed XML at line 1"},
        {"<MRML></MRML>", "VolumeProperty: expected at least one <VolumeProperty> element"},
    };
    for (const Case& c : cases) {
        const std::string e = error_of([&] { parse_slicer_presets_xml(c.xml, "p.xml"); });
        EXPECT_NE(e.find(c.needle), std::string::npos) << "got: " << e << "\nwanted: " << c.needle;
        EXPECT_EQ(e.rfind("p.xml: ", 0), 0u) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

TEST(SlicerPresets, MalformedVpAndVpJson) {
    const std::string good =
        "1\n1\n0.9\n0.1\n0.2\n10\n4 0 0 255 1\n4 0 1 255 1\n8 0 0 0 0 255 1 1 1\n";
    EXPECT_EQ(parse_slicer_vp(good, "x.vp").scalar_opacity.size(), 2u);
    EXPECT_NE(error_of([&] {
                  parse_slicer_vp("1\n1\n0.9\n", "x.vp");
              }).find("x.vp: lines: expected 9 lines"),
              std::string::npos);
    std::string bad = good;
    bad.replace(bad.find("4 0 0 255 1"), 11, "4 0 0 255");
    EXPECT_NE(error_of([&] {
                  parse_slicer_vp(bad, "x.vp");
              }).find("x.vp: line 7 (scalar opacity): expected 4 numbers after the count, got 3"),
              std::string::npos);

    auto json_error = [](const std::string& component) {
        return error_of([&] {
            parse_slicer_vp_json("{\"volumeProperties\": [{\"components\": [" + component + "]}]}",
                                 "x.vp.json");
        });
    };
    const std::string op =
        "\"scalarOpacity\": {\"points\": [{\"x\": 0, \"y\": 0, \"midpoint\": 0.5, \"sharpness\": "
        "0}]}";
    const std::string col =
        "\"rgbTransferFunction\": {\"points\": [{\"x\": 0, \"color\": [1, 1, 1], \"midpoint\": "
        "0.5, \"sharpness\": 0}]}";
    EXPECT_EQ(json_error("{" + op + ", " + col + "}"), "");
    EXPECT_NE(json_error("{" + col + "}")
                  .find("x.vp.json: volumeProperties[0].components[0].scalarOpacity: missing"),
              std::string::npos);
    EXPECT_NE(
        json_error("{\"scalarOpacity\": {\"points\": [{\"x\": 0, \"y\": 0, \"midpoint\": 0.3, "
                   "\"sharpness\": 0}]}, " +
                   col + "}")
            .find("scalarOpacity.points[0]: expected midpoint 0.5 and sharpness 0"),
        std::string::npos);
    EXPECT_NE(json_error("{" + op +
                         ", \"rgbTransferFunction\": {\"points\": [{\"x\": 0, \"color\": "
                         "[1, 1], \"midpoint\": 0.5, \"sharpness\": 0}]}}")
                  .find("rgbTransferFunction.points[0].color: expected [r, g, b]"),
              std::string::npos);
    EXPECT_NE(json_error("{" + op + ", " + col + ", \"lighting\": {\"ambient\": 0.1}}")
                  .find("lighting.diffuse: missing"),
              std::string::npos);
    EXPECT_NE(error_of([] {
                  parse_slicer_vp_json("{\"volumeProperties\": [{\"components\": []}]}",
                                       "x.vp.json");
              }).find("components: expected exactly one component"),
              std::string::npos);
    EXPECT_NE(error_of([] {
                  parse_slicer_vp_json("{", "x.vp.json");
              }).find("x.vp.json: json: not valid JSON"),
              std::string::npos);
}

TEST(SlicerPresets, SpecsSelectEntriesAndListNames) {
    EXPECT_TRUE(is_slicer_spec("slicer:a.xml#b"));
    EXPECT_TRUE(is_slicer_spec("a.vp"));
    EXPECT_TRUE(is_slicer_spec("a.VP.json#2"));
    EXPECT_FALSE(is_slicer_spec("a.json"));
    EXPECT_FALSE(is_slicer_spec("ct-bone"));
    const std::string file = kData + "slicer-presets.xml";
    EXPECT_NE(error_of([&] { resolve_slicer_preset("slicer:" + file + "#CT-Bonez"); })
                  .find("preset: unknown 'CT-Bonez'; expected one of: Lacuna-CT-Bone, "
                        "Lacuna-MR-Brain, Lacuna-Step"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  resolve_slicer_preset("slicer:" + file);
              }).find("expected a preset name after '#'"),
              std::string::npos);
    EXPECT_NE(error_of([] {
                  resolve_slicer_preset("slicer:/nonexistent/p.xml#a");
              }).find("/nonexistent/p.xml: file: cannot open"),
              std::string::npos);
    EXPECT_NE(error_of([] {
                  resolve_slicer_preset("slicer:notes.txt#a");
              }).find("expected a Slicer preset file ending in .xml, .vp or .vp.json"),
              std::string::npos);
}

}  // namespace
}  // namespace lacuna
