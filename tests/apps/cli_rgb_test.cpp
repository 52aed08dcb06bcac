// RGB NIfTI files through the CLI: `lacuna info` names the channels, `lacuna render` gives every
// structure the `none` image, --rgb-opacity picks the opacity scalar, and what RGB cannot do is one
// line, exit 2, nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "apps/cli_run.h"
#include "io/io_test_util.h"
#include "io/nifti_test_file.h"

namespace {

namespace fs = std::filesystem;
using lacuna::test::expect_one_line_error;

fs::path temp_dir() {
    static const fs::path dir = lacuna::test::cli_temp_dir("cli-rgb");
    return dir;
}
lacuna::test::CliResult run(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
}

// A 24^3 RGB24 file: a red ball, a green ring around it, black elsewhere.
fs::path rgb_file() {
    static const fs::path p = [] {
        const int n = 24;
        std::vector<uint8_t> v;
        for (int k = 0; k < n; ++k)
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    const double r = std::hypot(i - 11.5, j - 11.5, k - 11.5);
                    v.push_back(r < 6 ? 230 : 0);
                    v.push_back(r >= 7 && r < 10 ? 200 : 0);
                    v.push_back(uint8_t(4 * k));
                }
        lacuna::test::NiftiSpec s;
        s.dims = {n, n, n};
        s.datatype = 128;
        const fs::path path = temp_dir() / "rgb.nii";
        lacuna::test::write_bytes(path.string(), lacuna::test::nifti_bytes(s, v.data(), v.size()));
        return path;
    }();
    return p;
}

TEST(CliRgb, InfoNamesTheChannelsAndTheOpacityScalar) {
    const auto r = run("info " + rgb_file().string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("channels:    RGB (RGB24) (colour from the data; opacity scalar: "
                         "luminance, Rec. 709 float32)"),
              std::string::npos)
        << r.out;
    const auto g = run("info " + rgb_file().string() + " --rgb-opacity g");
    ASSERT_EQ(g.code, 0) << g.err;
    EXPECT_NE(g.out.find("opacity scalar: g, the channel, uint8"), std::string::npos) << g.out;
    EXPECT_NE(g.out.find("value range: 0 .. 200"), std::string::npos) << g.out;
}

TEST(CliRgb, EveryAccelRendersTheNoneImage) {
    const std::string base =
        "render " + rgb_file().string() + " --tf mr-default --size 48 --azimuth 35 ";
    const fs::path ref = temp_dir() / "none.png";
    ASSERT_EQ(run(base + "--accel none --out " + ref.string()).code, 0);
    for (const char* accel : {"grid", "bitfield", "minmax", "kdtree"}) {
        const fs::path out = temp_dir() / (std::string(accel) + ".png");
        const auto r = run(base + "--accel " + accel + " --out " + out.string());
        ASSERT_EQ(r.code, 0) << accel << ": " << r.err;
        EXPECT_EQ(lacuna::test::slurp_file(out), lacuna::test::slurp_file(ref)) << accel;
    }
    // The opacity channel changes the picture (red ball only, vs the green ring in front).
    const fs::path red = temp_dir() / "red.png";
    ASSERT_EQ(run(base + "--accel none --rgb-opacity r --out " + red.string()).code, 0);
    EXPECT_NE(lacuna::test::slurp_file(red), lacuna::test::slurp_file(ref));
}

TEST(CliRgb, WhatRgbCannotDoIsOneLine) {
    const fs::path out = temp_dir() / "bad.png";
    const std::string f = rgb_file().string();
    expect_one_line_error(
        run("render " + f + " --tf mr-default --rgb-opacity a --out " + out.string()),
        "rgb opacity: expected luminance, r, g or b: the file has no alpha channel (RGB24), got a");
    expect_one_line_error(
        run("render " + f + " --tf mr-default --rgb-opacity luma --out " + out.string()),
        "--rgb-opacity: rgb opacity: expected one of: luminance, r, g, b, a; got 'luma'");
    expect_one_line_error(
        run("render " + f + " --tf mr-default --shading phong --out " + out.string()),
        "for an RGB volume: its colour comes from the data");
    expect_one_line_error(
        run("render " + f + " --tf mr-default --renderer slice --out " + out.string()),
        "an RGB volume renders with the ray marcher only");
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
