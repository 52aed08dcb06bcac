// Inputs the fuzz harnesses (fuzz/, docs/reliability.md) found crashing the TF, preset and label
// parsers, reduced to their essence: each is now one lacuna::Error naming file and field.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "lacuna/error.h"
#include "transfer/slicer_presets.h"

namespace lacuna {
namespace {

// The message of the lacuna::Error `f` throws; fails the test if it throws nothing (any other
// exception escapes and fails it too).
std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    ADD_FAILURE() << "accepted";
    return "";
}

TEST(ParserFuzzRegression, SlicerCountBeyondIntegersIsAnError) {
    // fuzz_slicer_xml, fuzz_slicer_vp: a point count of 4.34e39 was converted to int64_t (UB).
    const std::string vp =
        "1\n1\n0.9\n0.1\n0.2\n10\n4.34e39 0 0 255 1\n4 0 1 255 1\n8 0 0 0 0 255 1 1 1\n";
    EXPECT_NE(error_of([&] {
                  parse_slicer_vp(vp, "x.vp");
              }).find("x.vp: line 7 (scalar opacity): expected 4.34e+39 numbers after the count"),
              std::string::npos);
    const std::string xml = R"(<MRML><VolumeProperty name="A" interpolation="1" shade="0"
        scalarOpacity="1e300 0 0" gradientOpacity="4 0 1 255 1"
        colorTransfer="8 0 0 0 0 1 1 1 1"/></MRML>)";
    EXPECT_NE(error_of([&] { parse_slicer_presets_xml(xml, "p.xml"); }).find("scalarOpacity"),
              std::string::npos);
}

TEST(ParserFuzzRegression, SlicerVpJsonNumberBeyondDoubleIsAnError) {
    // fuzz_slicer_vp_json: nlohmann's out_of_range.406 (1e999) escaped as std::terminate.
    EXPECT_NE(error_of([] {
                  parse_slicer_vp_json("{\"volumeProperties\": [1e999]}", "x.vp.json");
              }).find("x.vp.json: json: not valid JSON"),
              std::string::npos);
}

}  // namespace
}  // namespace lacuna
