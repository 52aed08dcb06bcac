// The CLI end to end: good runs produce files and timing lines; every bad input gives one line
// naming the file and the problem, exit code 2, and leaves no output file behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "apps/cli_run.h"
#include "io/io_test_util.h"
#include "io/nifti_test_file.h"

namespace fs = std::filesystem;

namespace {

using CliRun = lacuna::test::CliResult;
using lacuna::test::expect_one_line_error;
std::string slurp(const fs::path& p) {
    return lacuna::test::slurp_file(p);
}

fs::path temp_dir() {
    static const fs::path dir = lacuna::test::cli_temp_dir("cli");
    return dir;
}

CliRun run(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
}

const fs::path& small_volume() {
    static fs::path p = [] {
        fs::path v = temp_dir() / "shells.nrrd";
        CliRun r = run("generate sphere-shells --dims 33x30x27 --out " + v.string());
        EXPECT_EQ(r.code, 0) << r.err;
        return v;
    }();
    return p;
}

TEST(Cli, RendersAGeneratedVolumeAndReportsTiming) {
    const fs::path png = temp_dir() / "shells.png", heat = temp_dir() / "shells-heat.png";
    CliRun r = run("render " + small_volume().string() + " --tf mr-default --size 64 --out " +
                   png.string() + " --heatmap " + heat.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("render time"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("samples/ray"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Msamples/s"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(png));
    EXPECT_TRUE(fs::exists(heat));
    EXPECT_EQ(slurp(png).substr(1, 3), "PNG");
}

// --repeat N renders the frame N times and reports the median of the warm ones; --no-refine
// renders without the grid's visible-cell mask. Neither changes a byte of the picture (shaded,
// where the mask is used). Bad counts: one line, exit 2, no file.
TEST(Cli, RepeatAndNoRefineKeepThePictureAndReportTimes) {
    const std::string base = "render " + small_volume().string() +
                             " --tf mr-default --size 48 --shading phong --accel grid --out ";
    const fs::path a = temp_dir() / "rep-a.png", b = temp_dir() / "rep-b.png",
                   c = temp_dir() / "rep-c.png";
    CliRun r1 = run(base + a.string());
    ASSERT_EQ(r1.code, 0) << r1.err;
    EXPECT_NE(r1.out.find(", CPU "), std::string::npos) << r1.out;
    EXPECT_NE(r1.out.find("refine "), std::string::npos) << r1.out;
    CliRun r2 = run(base + b.string() + " --repeat 3");
    ASSERT_EQ(r2.code, 0) << r2.err;
    EXPECT_NE(r2.out.find("3 frames: first"), std::string::npos) << r2.out;
    CliRun r3 = run(base + c.string() + " --no-refine");
    ASSERT_EQ(r3.code, 0) << r3.err;
    EXPECT_NE(r3.out.find("refine 0.000 ms"), std::string::npos) << r3.out;
    EXPECT_EQ(slurp(a), slurp(b));
    EXPECT_EQ(slurp(a), slurp(c));
    const fs::path bad = temp_dir() / "rep-bad.png";
    expect_one_line_error(run(base + bad.string() + " --repeat 0"), "--repeat");
    EXPECT_FALSE(fs::exists(bad));
}

TEST(Cli, TfAnimationWritesFramesAndReportsTfChangeTime) {
    const fs::path png = temp_dir() / "anim.png";
    CliRun r = run("render " + small_volume().string() +
                   " --tf-animate mr-default mr-gap --frames 3 --accel bitfield --size 24 --out " +
                   png.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("TF change"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("bitfield"), std::string::npos) << r.out;
    for (const char* f : {"anim_0000.png", "anim_0001.png", "anim_0002.png"})
        EXPECT_TRUE(fs::exists(temp_dir() / f)) << f;
    EXPECT_FALSE(fs::exists(temp_dir() / "anim_0003.png"));
    CliRun all = run("render " + small_volume().string() +
                     " --tf-animate mr-default mr-gap --frames 2 --accel all --size 16 --out " +
                     (temp_dir() / "all.png").string());
    ASSERT_EQ(all.code, 0) << all.err;
    for (const char* name : {"none", "distance", "chebyshev", "boolean", "minmax", "bitfield"})
        EXPECT_NE(all.out.find(name), std::string::npos) << name << "\n" << all.out;
}

TEST(Cli, EveryAccelRendersTheSameBytes) {
    std::string ref;
    for (const char* accel : {"none", "distance", "chebyshev", "boolean", "minmax", "bitfield"}) {
        const fs::path png = temp_dir() / (std::string("same-") + accel + ".png");
        CliRun r = run("render " + small_volume().string() + " --tf mr-gap --size 40 --accel " +
                       accel + " --out " + png.string());
        ASSERT_EQ(r.code, 0) << r.err;
        if (ref.empty())
            ref = slurp(png);
        else
            EXPECT_EQ(slurp(png), ref) << accel;
    }
}

TEST(Cli, InfoDescribesTheCh2Head) {
    CliRun r = run("info /usr/share/mricron/templates/ch2.nii.gz");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("181 x 217 x 181"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("uint8"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("histogram"), std::string::npos) << r.out;
}

TEST(Cli, MissingVolumeIsOneLineExit2) {
    const fs::path png = temp_dir() / "never.png";
    CliRun r = run("render /nonexistent/head.nii.gz --tf mr-skin --out " + png.string());
    expect_one_line_error(r, "/nonexistent/head.nii.gz");
    EXPECT_FALSE(fs::exists(png));
}

TEST(Cli, UnknownPresetIsOneLineExit2) {
    const fs::path png = temp_dir() / "never.png";
    CliRun r =
        run("render " + small_volume().string() + " --tf no-such-preset --out " + png.string());
    expect_one_line_error(r, "no-such-preset");
    EXPECT_FALSE(fs::exists(png));
}

TEST(Cli, MalformedTfJsonIsOneLineExit2) {
    const fs::path tf = temp_dir() / "broken.json", png = temp_dir() / "never.png";
    std::ofstream(tf) << "{\"color\": [[0, 1, 1, 1]], \"opacity\": [[0, 0.5], [0.5,";
    CliRun r = run("render " + small_volume().string() + " --tf " + tf.string() + " --out " +
                   png.string());
    expect_one_line_error(r, "broken.json");
    EXPECT_FALSE(fs::exists(png));
}

TEST(Cli, UnwritableOutputIsOneLineExit2) {
    CliRun r = run("render " + small_volume().string() +
                   " --tf mr-default --size 16 --out /nonexistent-dir/out.png");
    expect_one_line_error(r, "/nonexistent-dir/out.png");
    fs::path ro = temp_dir() / "readonly";
    fs::create_directories(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    // root ignores permission bits; the check only means something for other users.
    if (::geteuid() != 0) {
        CliRun r2 = run("render " + small_volume().string() + " --tf mr-default --size 16 --out " +
                        (ro / "out.png").string());
        expect_one_line_error(r2, "out.png");
    }
    fs::permissions(ro, fs::perms::owner_all);
}

TEST(Cli, BadOptionsAreOneLineExit2) {
    const std::string v = small_volume().string();
    expect_one_line_error(run("render " + v + " --tf mr-skin --accel octopus --out x.png"),
                          "octopus");
    expect_one_line_error(run("render " + v + " --tf mr-skin --step -1 --out x.png"), "--step");
    expect_one_line_error(run("render " + v + " --tf mr-skin --size 0 --out x.png"), "--size");
    expect_one_line_error(run("render " + v + " --tf mr-skin --out x.jpg"), "x.jpg");
    expect_one_line_error(run("generate tree --dims 12x12 --out x.nrrd"), "--dims");
    expect_one_line_error(run("generate tree --dims 100000x100000x100000 --out x.nrrd"), "dims");
    expect_one_line_error(run("generate teapot --out x.nrrd"), "teapot");
    expect_one_line_error(run("render --frobnicate"), "frobnicate");
    expect_one_line_error(run("rendr " + v), "did you mean 'render'");
    expect_one_line_error(run("render " + v + " --tf mr-skin --zoom -1 --out x.png"), "--zoom");
    expect_one_line_error(run("render " + v + " --tf mr-skin --zoom 0 --out x.png"), "--zoom");
    expect_one_line_error(run("render " + v + " --tf mr-skin --fov 180 --out x.png"), "--fov");
    expect_one_line_error(run("render " + v + " --tf mr-skin --interpolation cubic --out x.png"),
                          "--interpolation");

    EXPECT_FALSE(fs::exists("x.png"));
    EXPECT_FALSE(fs::exists("x.nrrd"));
}

TEST(Cli, TruncatedVolumeIsOneLineExit2AndInputUntouched) {
    const std::string full = slurp("/usr/share/mricron/templates/ch2.nii.gz");
    const fs::path cut = temp_dir() / "cut.nii.gz", png = temp_dir() / "never.png";
    std::ofstream(cut, std::ios::binary) << full.substr(0, full.size() / 2);
    const std::string before = slurp(cut);
    CliRun r = run("render " + cut.string() + " --tf mr-skin --size 16 --out " + png.string());
    expect_one_line_error(r, "cut.nii.gz");
    EXPECT_EQ(slurp(cut), before);
    EXPECT_FALSE(fs::exists(png));
}

TEST(Cli, RawVolumeWithExplicitLayout) {
    const fs::path raw = temp_dir() / "ramp.raw", png = temp_dir() / "ramp.png";
    std::string bytes(12 * 10 * 8, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i % 200);
    std::ofstream(raw, std::ios::binary) << bytes;
    CliRun ok = run("render " + raw.string() +
                    " --dims 12x10x8 --type uint8 --tf mr-default --size 16 --out " + png.string());
    EXPECT_EQ(ok.code, 0) << ok.err;
    CliRun bad = run("info " + raw.string() + " --dims 12x10x9 --type uint8");
    expect_one_line_error(bad, "ramp.raw");
    // --spacing completes a raw layout, given by flags or by the file's name; nothing else.
    CliRun spaced =
        run("info " + raw.string() + " --dims 12x10x8 --type uint8 --spacing 0.5,2,1.25");
    EXPECT_EQ(spaced.code, 0) << spaced.err;
    EXPECT_NE(spaced.out.find("spacing:     0.5 x 2 x 1.25 mm"), std::string::npos) << spaced.out;
    const fs::path named = temp_dir() / "ramp_12x10x8_uint8.raw";
    fs::copy_file(raw, named, fs::copy_options::overwrite_existing);
    spaced = run("info " + named.string() + " --spacing 3,1,1");
    EXPECT_NE(spaced.out.find("spacing:     3 x 1 x 1 mm"), std::string::npos)
        << spaced.out + spaced.err;
    for (const char* s : {"0,1,1", "1,1", "1,1,1,1", "a,1,1", "nan,1,1", "1,-2,1"})
        expect_one_line_error(run("info " + named.string() + " --spacing " + s), "--spacing");
    expect_one_line_error(run("info " + small_volume().string() + " --spacing 1,1,1"),
                          "--spacing: spacing: applies to .raw files");
}

// A 4D NIfTI file (three volumes) is read volume by volume with --frame; without it, one line
// says how many it holds.
TEST(Cli, FourDimensionalNiftiTakesAFrame) {
    lacuna::test::NiftiSpec spec;
    spec.ndim = 4;
    spec.dims = {6, 5, 4};
    spec.dim4 = 3;
    std::vector<uint8_t> vox(6 * 5 * 4 * 3);
    for (size_t i = 0; i < vox.size(); ++i) vox[i] = uint8_t(100 * (i / 120) + i % 120 / 12);
    const fs::path file = temp_dir() / "series.nii";
    lacuna::test::write_bytes(file.string(),
                              lacuna::test::nifti_bytes(spec, vox.data(), vox.size()));
    for (int f = 0; f < 3; ++f) {
        CliRun r = run("info " + file.string() + " --frame " + std::to_string(f));
        EXPECT_EQ(r.code, 0) << r.err;
        const std::string range = std::to_string(100 * f) + " .. " + std::to_string(100 * f + 9);
        EXPECT_NE(r.out.find("value range: " + range), std::string::npos) << r.out;
    }
    expect_one_line_error(
        run("info " + file.string()),
        "series.nii: frame: the file holds 3 volumes along dim[4]; choose one (0..2)");
    expect_one_line_error(run("info " + file.string() + " --frame 3"),
                          "frame: expected 0..2, got 3");
    const fs::path png = temp_dir() / "series.png";
    CliRun r = run("render " + file.string() + " --frame 2 --tf mr-default --size 16 --out " +
                   png.string());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(png));
}

}  // namespace
