// The transfer function JSON format: round trips, accepted forms, and one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "lacuna/error.h"
#include "lacuna/transfer_function.h"
#include "transfer/transfer_test_util.h"

namespace lacuna {
namespace {

using test::error_message;
using test::temp_path;

TEST(TransferJson, RoundTripsEveryPreset) {
    for (const std::string& name : preset_names()) {
        const TransferFunction tf = preset(name);
        EXPECT_EQ(parse_transfer_function(to_json(tf), name + ".json"), tf) << to_json(tf);
    }
}

TEST(TransferJson, RoundTripsTheRenderingKeys) {
    TransferFunction tf;
    tf.name = "shaded";
    tf.domain = TfDomain::Value;
    tf.color = {{-1024, 0, 0, 0}, {3071, 1, 1, 1}};
    tf.opacity = {{-1024, 0}, {200, 0}, {3071, 0.8f}};
    tf.rendering.shading = TfShading{0.1f, 0.9f, 0.2f, 10.f};
    tf.rendering.gradient_opacity = {{0, 0.f}, {12.5, 0.f}, {12.5, 0.25f}, {300, 1.f}};
    tf.rendering.blend = BlendMode::MinIp;
    const std::string text = to_json(tf);
    EXPECT_EQ(parse_transfer_function(text, "t.json"), tf) << text;
    EXPECT_NE(
        text.find(
            R"("shading": {"ambient": 0.1, "diffuse": 0.9, "specular": 0.2, "specular_power": 10})"),
        std::string::npos)
        << text;
    EXPECT_NE(text.find(R"("blend": "minip")"), std::string::npos) << text;
    // Each part alone, and none: a TF without them writes none of the keys.
    for (int part = 0; part < 4; ++part) {
        TransferFunction t = tf;
        if (part != 0) t.rendering.shading.reset();
        if (part != 1) t.rendering.gradient_opacity.clear();
        if (part != 2) t.rendering.blend.reset();
        const std::string s = to_json(t);
        EXPECT_EQ(parse_transfer_function(s, "t.json"), t) << s;
        EXPECT_EQ(s.find("shading") != std::string::npos, part == 0) << s;
        EXPECT_EQ(s.find("gradient_opacity") != std::string::npos, part == 1) << s;
        EXPECT_EQ(s.find("blend") != std::string::npos, part == 2) << s;
    }
    // The parts count for equality.
    TransferFunction other = tf;
    other.rendering.shading->specular_power = 11.f;
    EXPECT_FALSE(other == tf);
}

TEST(TransferJson, RoundTripsAwkwardFloatsAndValueDomain) {
    TransferFunction tf;
    tf.name = "awkward \"quoted\" name\twith tab";
    tf.domain = TfDomain::Value;
    tf.range = ValueRange{-1024.f, 3071.3f};
    tf.color = {{-1000.0 / 3.0, 0.1f, 1.f / 3.f, 2.f / 3.f}, {1e-7, 1e-30f, 0.7f, 0.9999999f}};
    tf.opacity = {{-5.0, 0.f}, {0.1, 0.3f}, {0.1, 1.f / 7.f}, {12345.678901234567, 1.f}};
    const std::string text = to_json(tf);
    EXPECT_EQ(parse_transfer_function(text, "awkward.json"), tf) << text;
}

TEST(TransferJson, RoundTripsManyRandomFloatsExactly) {
    // Shortest float text goes through the reader's double and back to float: check that
    // double rounding never changes a value (number_text.h falls back when it would).
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    std::uniform_real_distribution<double> wide(-1e6, 1e6);
    TransferFunction tf;
    tf.name = "random";
    tf.domain = TfDomain::Value;
    std::vector<double> xs(5000);
    for (double& x : xs) x = wide(rng);
    std::sort(xs.begin(), xs.end());
    for (double x : xs) {
        tf.opacity.push_back({x, unit(rng)});
        tf.color.push_back({x, unit(rng), unit(rng), std::ldexp(unit(rng), -20)});
    }
    tf.range = ValueRange{float(wide(rng)) - 2e6f, float(wide(rng)) + 2e6f};
    EXPECT_EQ(parse_transfer_function(to_json(tf), "random.json"), tf);
}

TEST(TransferJson, WritesOnePointPerLineInShortestForm) {
    TransferFunction tf;
    tf.name = "small";
    tf.color = {{0.0, 0.1f, 0.2f, 0.3f}};
    tf.opacity = {{0.0, 0.f}, {0.5, 0.25f}};
    EXPECT_EQ(to_json(tf),
              "{\n"
              "  \"name\": \"small\",\n"
              "  \"domain\": \"normalized\",\n"
              "  \"color\": [\n"
              "    [0, 0.1, 0.2, 0.3]\n"
              "  ],\n"
              "  \"opacity\": [\n"
              "    [0, 0],\n"
              "    [0.5, 0.25]\n"
              "  ]\n"
              "}\n");
}

TEST(TransferJson, ParsesArrayPointsAndDefaults) {
    const TransferFunction tf = parse_transfer_function(
        R"({"color": [[0, 1, 0.5, 0]], "opacity": [[0, 0], [1, 0.5]]})", "dir/my-tf.json");
    EXPECT_EQ(tf.name, "my-tf");  // file stem when "name" is absent
    EXPECT_EQ(tf.domain, TfDomain::Normalized);
    EXPECT_FALSE(tf.range.has_value());
    ASSERT_EQ(tf.color.size(), 1u);
    EXPECT_EQ(tf.color[0], (ColorPoint{0.0, 1.f, 0.5f, 0.f}));
    ASSERT_EQ(tf.opacity.size(), 2u);
    EXPECT_EQ(tf.opacity[1], (OpacityPoint{1.0, 0.5f}));
}

TEST(TransferJson, AcceptsObjectPointsCommentsStepsAndNullRange) {
    const TransferFunction tf = parse_transfer_function(R"({
        // a hand-written file
        "name": "objects", "description": "free text, not kept",
        "domain": "value", "range": null,
        "color": [{"x": -100, "r": 1, "g": 0.5, "b": 0}, {"b": 1, "g": 1, "r": 1, "x": 400}],
        /* a step at 200 */
        "opacity": [{"x": -100, "a": 0}, {"x": 200, "a": 0}, {"x": 200, "a": 0.4}]
    })",
                                                        "objects.json");
    EXPECT_EQ(tf.name, "objects");
    EXPECT_EQ(tf.domain, TfDomain::Value);
    EXPECT_FALSE(tf.range.has_value());
    EXPECT_EQ(tf.color[1], (ColorPoint{400.0, 1.f, 1.f, 1.f}));
    EXPECT_EQ(tf.opacity[2], (OpacityPoint{200.0, 0.4f}));
}

TEST(TransferJson, ReadsRange) {
    const TransferFunction tf = parse_transfer_function(
        R"({"range": [-1024, 3071], "color": [[0, 1, 1, 1]], "opacity": [[0, 0.1]]})", "r.json");
    ASSERT_TRUE(tf.range.has_value());
    EXPECT_EQ(tf.range->min, -1024.f);
    EXPECT_EQ(tf.range->max, 3071.f);
}

TEST(TransferJson, ReportsExactMessageForOutOfRangeOpacity) {
    const std::string msg = error_message([] {
        parse_transfer_function(
            R"({"color": [[0, 1, 1, 1]], "opacity": [[0, 0], [0.2, 0.5], [0.5, 1.7]]})", "tf.json");
    });
    EXPECT_EQ(msg, "tf.json: opacity[2]: expected [x, a] with a in [0,1], got [0.5, 1.7]");
}

TEST(TransferJson, RejectsEveryMalformedDocumentWithOneLineError) {
    // Valid color and opacity members to splice around the broken part.
    const std::string c = R"("color": [[0, 1, 1, 1]])";
    const std::string o = R"("opacity": [[0, 0], [1, 0.5]])";
    auto doc = [](const std::string& body) { return "{" + body + "}"; };
    const std::vector<std::pair<std::string, std::string>> cases = {
        // {document, field named in the error}
        {"{ \"color\": [[0, 1, 1, 1]],\n  \"opacity\": [[0, 0]]\n  oops }", "json"},
        {"", "json"},
        {doc(c + R"(, "opacity": [[0, NaN]])"), "json"},
        // a number past double: nlohmann's out_of_range.406, not a parse_error (fuzz_session_file)
        {doc(c + R"(, "opacity": [[0, 8888E8888]])"), "json"},
        {"[1, 2]", "json"},
        {doc(o), "color"},
        {doc(c), "opacity"},
        {doc(R"("color": [], )" + o), "color"},
        {doc(c + R"(, "opacity": [])"), "opacity"},
        {doc(R"("color": {"x": 0}, )" + o), "color"},
        {doc(c + R"(, "opacity": [[0, 0.5, 1]])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [[0, 0], [0.5]])"), "opacity[1]"},
        {doc(R"("color": [[0, 1, 1]], )" + o), "color[0]"},
        {doc(R"("color": [[0, 1, 1, 1, 1]], )" + o), "color[0]"},
        {doc(c + R"(, "opacity": [[0, "high"]])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [[0, true]])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [["0", 0.5]])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [[0, null]])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [0.5])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [[0, 1e999]])"), "json"},  // overflows double
        {doc(c + R"(, "opacity": [[1e999, 0]])"), "json"},
        {doc(c + R"(, "opacity": [[0, 1.7]])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [[0, -0.1]])"), "opacity[0]"},
        {doc(R"("color": [[0, 1.2, 0, 0]], )" + o), "color[0]"},
        {doc(R"("color": [[0, 0, 0, -1]], )" + o), "color[0]"},
        {doc(c + R"(, "opacity": [{"x": 0}])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [{"x": 0, "alpha": 1}])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [{"x": 0, "a": 1, "b": 2}])"), "opacity[0]"},
        {doc(c + R"(, "opacity": [[0.5, 0], [0.2, 1]])"), "opacity[1]"},
        {doc(c + R"(, "opacity": [[0, 0], [0.5, 0], [0.5, 1], [0.5, 0.2]])"), "opacity[3]"},
        {doc(R"("color": [[0.6, 1, 1, 1], [0.3, 0, 0, 0]], )" + o), "color[1]"},
        {doc(c + R"(, "opacity": [[0, 0], [1.5, 0.5]])"), "opacity[1]"},
        {doc(c + R"(, "opacity": [[-0.1, 0]])"), "opacity[0]"},
        {doc(R"("color": [[2, 1, 1, 1]], )" + o), "color[0]"},
        {doc(R"("range": [5, 5], )" + c + ", " + o), "range"},
        {doc(R"("range": [5, 1], )" + c + ", " + o), "range"},
        {doc(R"("range": [0], )" + c + ", " + o), "range"},
        {doc(R"("range": "0..1", )" + c + ", " + o), "range"},
        {doc(R"("range": [0, 1e300], )" + c + ", " + o), "range"},  // overflows float
        {doc(R"("domain": "log", )" + c + ", " + o), "domain"},
        {doc(R"("domain": 1, )" + c + ", " + o), "domain"},
        {doc(R"("name": 7, )" + c + ", " + o), "name"},
        {doc(R"("description": [], )" + c + ", " + o), "description"},
        {doc(R"("opactiy": [], )" + c + ", " + o), "\"opactiy\""},
        // The rendering keys (shading, gradient_opacity, blend).
        {doc(c + ", " + o + R"(, "shading": true)"), "shading"},
        {doc(c + ", " + o + R"(, "shading": {"ambient": 0.1, "diffuse": 1, "specular": 0})"),
         "shading.specular_power"},
        {doc(c + ", " + o +
             R"(, "shading": {"ambient": "a", "diffuse": 1, "specular": 0, "specular_power": 1})"),
         "shading.ambient"},
        {doc(c + ", " + o +
             R"(, "shading": {"ambient": 0, "diffuse": 1, "specular": 0, "specular_power": 1, "shine": 2})"),
         "shading.shine"},
        {doc(c + ", " + o +
             R"(, "shading": {"ambient": 1.5, "diffuse": 1, "specular": 0, "specular_power": 1})"),
         "shading"},
        {doc(c + ", " + o +
             R"(, "shading": {"ambient": 0, "diffuse": 1, "specular": 0, "specular_power": -1})"),
         "shading"},
        {doc(c + ", " + o + R"(, "gradient_opacity": [])"), "gradient_opacity"},
        {doc(c + ", " + o + R"(, "gradient_opacity": {"x": 0})"), "gradient_opacity"},
        {doc(c + ", " + o + R"(, "gradient_opacity": [[0, 1.5]])"), "gradient_opacity[0]"},
        {doc(c + ", " + o + R"(, "gradient_opacity": [[-1, 1]])"), "gradient_opacity[0]"},
        {doc(c + ", " + o + R"(, "gradient_opacity": [[5, 0], [1, 1]])"), "gradient_opacity[1]"},
        {doc(c + ", " + o + R"(, "blend": "maximum")"), "blend"},
        {doc(c + ", " + o + R"(, "blend": 1)"), "blend"},
    };
    for (const auto& kase : cases) {
        const std::string& text = kase.first;
        const std::string msg = error_message([&] { parse_transfer_function(text, "bad.json"); });
        // "<file>: <field>: <what>", on one line.
        EXPECT_EQ(msg.rfind("bad.json: " + kase.second + ": ", 0), 0u)
            << "document: " << text << "\nmessage: " << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "document: " << text;
    }
}

TEST(TransferJson, ParseErrorReportsLineAndColumn) {
    const std::string msg = error_message([] {
        parse_transfer_function("{\n  \"color\": [[0, 1, 1, 1]],\n  \"opacity\": [[0, 0.5]\n}",
                                "broken.json");
    });
    EXPECT_EQ(msg.rfind("broken.json: json: not valid JSON: ", 0), 0u) << msg;
    EXPECT_NE(msg.find("line 4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("column"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("json.exception"), std::string::npos) << msg;
}

TEST(TransferJson, ParseErrorHintsAtNaN) {
    const std::string msg = error_message([] {
        parse_transfer_function(R"({"color": [[0, 1, 1, 1]], "opacity": [[0, NaN]]})", "nan.json");
    });
    EXPECT_NE(msg.find("NaN and Infinity are not JSON numbers"), std::string::npos) << msg;
}

TEST(TransferJson, LoadReportsMissingFile) {
    const std::string path = temp_path("absent.json");
    const std::string msg = error_message([&] { load_transfer_function(path); });
    EXPECT_EQ(msg.rfind(path + ": file: cannot open", 0), 0u) << msg;
}

TEST(TransferJson, LoadReportsDirectory) {
    const std::string msg = error_message([] { load_transfer_function(testing::TempDir()); });
    EXPECT_NE(msg.find(": file: "), std::string::npos) << msg;
}

TEST(TransferJson, LoadNamesTheFileInContentErrors) {
    const std::string path = temp_path("bad.json");
    std::ofstream(path) << R"({"color": [[0, 1, 1, 1]], "opacity": [[0, 2]]})";
    const std::string msg = error_message([&] { load_transfer_function(path); });
    EXPECT_EQ(msg.rfind(path + ": opacity[0]: ", 0), 0u) << msg;
    std::filesystem::remove(path);
}

TEST(TransferJson, LoadRoundTripsThroughAFile) {
    const std::string path = temp_path("tf.json");
    const TransferFunction tf = preset("mr-gap");
    std::ofstream(path) << to_json(tf);
    EXPECT_EQ(load_transfer_function(path), tf);
    std::filesystem::remove(path);
}

TEST(TransferJson, ToJsonRejectsInvalidTf) {
    TransferFunction tf;
    tf.color = {{0.0, 1.f, 1.f, 1.f}};
    tf.opacity = {{0.0, NAN}};
    EXPECT_THROW(to_json(tf), Error);
}

}  // namespace
}  // namespace lacuna
