// Issue 15, class 1 through the CLI: visualization ranges float cannot scale, float data wider
// than float, and data narrower than the LUT resolves (a NIfTI scl_slope of 1e-40) each give one
// line and exit 2, or a correct answer; never a crash.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "apps/cli_run.h"

namespace lacuna::test {
namespace {

namespace fs = std::filesystem;

fs::path dir() {
    static const fs::path d = cli_temp_dir("lut-range");
    return d;
}

// A 4x2x2 float32 raw volume, half `a`, half `b` (x < 2: a).
fs::path raw_float(const std::string& name, float a, float b) {
    std::vector<float> v(16);
    for (size_t i = 0; i < v.size(); ++i) v[i] = (i % 4) < 2 ? a : b;
    const fs::path p = dir() / name;
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
    return p;
}

const std::string kLayout = " --dims 4x2x2 --type float32";

TEST(CliLutRange, TooNarrowRangeIsOneLineExit2) {
    const fs::path v = raw_float("unit.raw", 0.f, 1.f), png = dir() / "narrow.png";
    const CliResult r =
        run_cli("render " + v.string() + kLayout +
                    " --range 0:1e-45 --tf mr-default --size 8 --out " + png.string(),
                dir());
    expect_one_line_error(r, "--range");
    EXPECT_FALSE(fs::exists(png));
}

TEST(CliLutRange, TfFileRangeTooNarrowIsOneLineExit2) {
    const fs::path v = raw_float("unit2.raw", 0.f, 1.f), png = dir() / "tf.png",
                   tf = dir() / "narrow-tf.json";
    std::ofstream(tf) << R"({"range": [0, 1e-40], "color": [[0, 1, 1, 1]], "opacity": [[0, 1]]})";
    const CliResult r = run_cli("render " + v.string() + kLayout + " --tf " + tf.string() +
                                    " --size 8 --out " + png.string(),
                                dir());
    expect_one_line_error(r, "range");
    EXPECT_FALSE(fs::exists(png));
}

TEST(CliLutRange, FloatDataWiderThanFloatIsOneLineExit2) {
    const fs::path v = raw_float("wide.raw", -3e38f, 3e38f);
    expect_one_line_error(run_cli("info " + v.string() + kLayout, dir()), "voxel values");
}

TEST(CliLutRange, DenormalDataHasAHistogramAndRenders) {
    // What a scl_slope of 1e-40 makes of 0 and 255: values 0 and ~2.6e-38.
    const fs::path v = raw_float("denormal.raw", 0.f, 2.6e-38f), png = dir() / "denormal.png";
    const CliResult info = run_cli("info " + v.string() + kLayout, dir());
    ASSERT_EQ(info.code, 0) << info.err;
    EXPECT_NE(info.out.find(" 50.0% "), std::string::npos) << info.out;
    const CliResult r = run_cli(
        "render " + v.string() + kLayout + " --tf mr-default --size 8 --out " + png.string(),
        dir());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(png));
}

TEST(CliLutRange, WideButFiniteDataRendersWithAWideRange) {
    const fs::path v = raw_float("wide-ok.raw", -1.5e38f, 1.5e38f), png = dir() / "wide.png";
    const CliResult r =
        run_cli("render " + v.string() + kLayout +
                    " --range=-3e38:3e38 --tf mr-default --size 8 --out " + png.string(),
                dir());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(png));
}

}  // namespace
}  // namespace lacuna::test
