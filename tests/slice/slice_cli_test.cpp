// `lacuna render --renderer slice` end to end: every box source writes the bytes of --accel none,
// occlusion at threshold 1 too; invalid combinations are one line and exit code 2; `bench li`
// runs on a tiny orbit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "apps/cli_run.h"

namespace fs = std::filesystem;

namespace {

using CliRun = lacuna::test::CliResult;
std::string slurp(const fs::path& p) {
    return lacuna::test::slurp_file(p);
}
using lacuna::test::expect_one_line_error;

fs::path temp_dir() {
    return lacuna::test::cli_temp_dir("slice-cli");
}

CliRun run(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
}

const fs::path& volume() {
    static fs::path p = [] {
        fs::path v = temp_dir() / "tree.nrrd";
        CliRun r = run("generate tree --dims 30x28x33 --out " + v.string());
        EXPECT_EQ(r.code, 0) << r.err;
        return v;
    }();
    return p;
}

TEST(SliceCli, EveryBoxSourceAndThresholdOneWriteTheBasicBytes) {
    const std::string v = volume().string();
    const fs::path ref = temp_dir() / "basic.png";
    CliRun r =
        run("render " + v + " --tf mr-default --size 40 --renderer slice --out " + ref.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("slice renderer"), std::string::npos) << r.out;
    for (const std::string extra :
         {"--accel kdtree", "--accel kdtree --occlusion --occlusion-threshold 1",
          "--accel kdtree --ortho --azimuth 100", "--threads 1", "--accel boxes",
          "--accel boxes --occlusion --occlusion-threshold 1"}) {
        const fs::path png = temp_dir() / "x.png";
        r = run("render " + v + " --tf mr-default --size 40 --renderer slice " + extra + " --out " +
                png.string());
        ASSERT_EQ(r.code, 0) << extra << ": " << r.err;
        if (extra.find("ortho") == std::string::npos) EXPECT_EQ(slurp(png), slurp(ref)) << extra;
    }
}

// Nearest samples: every box source (built from cell ranges, exact for nearest too) still writes
// the bytes of the slicer without boxes, and the picture differs from the trilinear one.
TEST(SliceCli, NearestSamplesAreExactForEveryBoxSource) {
    const std::string v = volume().string();
    const fs::path ref = temp_dir() / "basic-nearest.png", tri = temp_dir() / "basic-tri.png";
    CliRun r = run("render " + v +
                   " --tf mr-default --size 40 --renderer slice --interpolation nearest --out " +
                   ref.string());
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("render " + v + " --tf mr-default --size 40 --renderer slice --out " + tri.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(slurp(ref), slurp(tri));
    for (const std::string extra : {"--accel kdtree", "--accel boxes",
                                    "--accel kdtree --occlusion --occlusion-threshold 1"}) {
        const fs::path png = temp_dir() / "xn.png";
        r = run("render " + v +
                " --tf mr-default --size 40 --renderer slice --interpolation nearest " + extra +
                " --out " + png.string());
        ASSERT_EQ(r.code, 0) << extra << ": " << r.err;
        EXPECT_EQ(slurp(png), slurp(ref)) << extra;
    }
}

TEST(SliceCli, InvalidCombinationsAreOneLineExit2) {
    const std::string v = volume().string();
    const std::string base = "render " + v + " --tf mr-default --size 16 ";
    expect_one_line_error(run(base + "--renderer raytrace --out x.png"), "--renderer");
    expect_one_line_error(run(base + "--occlusion --out x.png"), "--renderer slice");
    expect_one_line_error(run(base + "--renderer slice --occlusion-threshold 0.9 --out x.png"),
                          "--occlusion");
    expect_one_line_error(
        run(base + "--renderer slice --occlusion --occlusion-threshold 1.5 --out x.png"),
        "--occlusion-threshold");
    expect_one_line_error(run(base + "--renderer slice --occlusion --occlusion-map 0 --out x.png"),
                          "--occlusion-map");
    expect_one_line_error(run(base + "--renderer slice --accel bitfield --out x.png"), "--accel");
    expect_one_line_error(run(base + "--renderer slice --heatmap h.png --out x.png"), "--heatmap");
    expect_one_line_error(run("bench li --ess octree"), "--ess");
    EXPECT_FALSE(fs::exists("x.png"));
}

}  // namespace
