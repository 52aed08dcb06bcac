// `lacuna render` with the shading, lighting, clipping and blend flags (docs/cli.md, "Shading"):
// good runs write a PNG that is the same for every --accel; malformed values give one line
// naming the flag, exit code 2, and no output file.
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

fs::path temp_dir() {
    return lacuna::test::cli_temp_dir("shading-cli");
}

CliRun run(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
}

const fs::path& volume() {
    static fs::path p = [] {
        fs::path v = temp_dir() / "shells.nrrd";
        CliRun r = run("generate sphere-shells --dims 30x28x26 --out " + v.string());
        EXPECT_EQ(r.code, 0) << r.err;
        return v;
    }();
    return p;
}

TEST(ShadingCli, EveryFeatureFlagRendersTheSameBytesForEveryAccel) {
    const std::string sets[] = {
        "--shading phong --phong 0.2,0.7,0.4,16 --gradient-volume",
        "--shading pbr --pbr 0.5,0.2 --light dir:1,1,1 --shadows",
        "--shading phong --light spot:-10,40,60,15,14,13,35 --shadows --light-volume",
        "--gradient-opacity 5,50 --clip 1,0,0,8 --clip 0,1,1,20 --crop 0,25,2,27,0,25",
        "--tf-back mr-skin --clip 1,0.2,0,14 --shading phong",
        "--blend mip",
        "--blend minip --jitter --jitter-seed 4",
        "--blend average --crop 3,20,3,20,3,20",
    };
    for (const std::string& set : sets) {
        std::string first;
        for (const char* accel : {"none", "bitfield", "minmax", "distance", "kdtree"}) {
            const fs::path png = temp_dir() / (std::string("f-") + accel + ".png");
            const CliRun r =
                run("render " + volume().string() + " --tf mr-default --size 40 --accel " + accel +
                    " --out " + png.string() + " " + set);
            ASSERT_EQ(r.code, 0) << set << ": " << r.err;
            EXPECT_NE(r.out.find("features:"), std::string::npos) << r.out;
            const std::string bytes = slurp(png);
            if (first.empty())
                first = bytes;
            else
                EXPECT_EQ(bytes, first) << set << " accel " << accel;
        }
    }
}

TEST(ShadingCli, ReportsGradientAndLightVolumes) {
    const fs::path png = temp_dir() / "volumes.png";
    const CliRun r =
        run("render " + volume().string() + " --tf mr-default --size 32 --out " + png.string() +
            " --shading pbr --gradient-volume --shadows --light-volume --light dir:0,1,0");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("gradient volume: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("light volume: "), std::string::npos) << r.out;
}

TEST(ShadingCli, MalformedFeatureFlagsAreOneLineExit2) {
    const std::pair<std::string, std::string> bad[] = {
        {"--shading toon", "--shading"},
        {"--phong 1,2,3", "--phong"},
        {"--pbr 0,0", "--pbr"},
        {"--light dir:0,0,0 --shading phong", "--light"},
        {"--light spot:1,2,3", "--light"},
        {"--light lamp", "--light"},
        {"--clip 1,0,0", "--clip"},
        {"--clip 0,0,0,1", "--clip"},
        {"--crop 5,1,0,1,0,1", "--crop"},
        {"--crop a,b,c,d,e,f", "--crop"},
        {"--tf-back mr-skin", "--tf-back"},
        {"--tf-back no-such-preset --clip 1,0,0,3", "no-such-preset"},
        {"--blend max", "--blend"},
        {"--light-volume", "--light-volume"},
        {"--gradient-opacity 5", "--gradient-opacity"},
        {"--shadows --shadow-step 0", "--shadow-step"},
    };
    for (const auto& [args, needle] : bad) {
        const fs::path png = temp_dir() / "bad.png";
        fs::remove(png);
        const CliRun r = run("render " + volume().string() + " --tf mr-default --size 16 --out " +
                             png.string() + " " + args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
        EXPECT_NE(r.err.find(needle), std::string::npos) << args << ": " << r.err;
        EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << args << ": more than one line: " << r.err;
        EXPECT_FALSE(fs::exists(png)) << args;
    }
}

}  // namespace
