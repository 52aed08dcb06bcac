// `lacuna render --labels/--segments` end to end: the octree and the unskipped render write the
// same PNG; bad label inputs give one line, exit code 2 and no output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "apps/cli_run.h"

namespace fs = std::filesystem;

namespace {

using lacuna::test::CliResult;

CliResult lacuna(const std::string& args) {
    return lacuna::test::run_cli(args, lacuna::test::cli_temp_dir("seg"));
}

std::string bytes(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

TEST(SegmentsCli, OctreeAndUnskippedRendersWriteTheSamePngAndBadInputExits2) {
    const fs::path d = fs::temp_directory_path() / ("lacuna-segcli-" + std::to_string(::getpid()));
    fs::create_directories(d);
    const std::string vol = (d / "v.nrrd").string(), lab = (d / "l.nrrd").string(),
                      other = (d / "o.nrrd").string(), fl = (d / "f.nrrd").string();
    ASSERT_EQ(lacuna("generate noise-blobs --dims 21x18x15 --out " + vol).code, 0);
    ASSERT_EQ(lacuna("generate sphere-shells --dims 21x18x15 --out " + lab).code, 0);
    ASSERT_EQ(lacuna("generate sphere-shells --dims 20x18x15 --out " + other).code, 0);
    ASSERT_EQ(lacuna("generate sphere-shells --dims 21x18x15 --type float32 --out " + fl).code, 0);
    for (const std::string& mode :
         std::vector<std::string>{"--labels " + lab + " --tf mr-default", "--segments labels"}) {
        const std::string base = (mode[2] == 's' ? lab : vol) + " " + mode +
                                 " --hide 1-40 --size 40 --azimuth 70 --out ";
        const CliResult a = lacuna("render " + base + (d / "a.png").string() + " --accel none");
        const CliResult b = lacuna("render " + base + (d / "b.png").string() + " --accel bitfield");
        ASSERT_EQ(a.code, 0) << a.err;
        ASSERT_EQ(b.code, 0) << b.err;
        EXPECT_NE(b.out.find("label octree: build"), std::string::npos) << b.out;
        EXPECT_EQ(bytes(d / "a.png"), bytes(d / "b.png")) << mode;
    }
    const std::pair<std::string, std::string> bad[] = {
        {"render " + vol + " --labels " + other + " --tf mr-default", "dims"},
        {"render " + vol + " --labels " + fl + " --tf mr-default", "float32"},
        {"render " + vol + " --labels " + lab + " --tf mr-default --show 3-x", "--show"},
        {"render " + lab + " --segments labels --accel minmax", "--accel"},
        {"render " + vol + " --labels " + lab + " --tf mr-default --accel quadtree", "--accel"},
        {"render " + vol + " --segments blend --tf mr-default", "--segments"},
        {"render " + vol + " --segments mask --tf mr-default", "--labels"},
        {"render " + vol + " --labels " + lab + " --tf mr-default --label-tint 2", "tint"},
        {"render " + vol + " --labels " + lab + " --tf mr-default --label-style " + vol,
         "label style"},
    };
    for (const auto& [args, needle] : bad) {
        const fs::path out = d / "bad.png";
        const CliResult r = lacuna(args + " --size 16 --out " + out.string());
        EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
        EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(fs::exists(out)) << args;
    }
    fs::remove_all(d);
}

}  // namespace
