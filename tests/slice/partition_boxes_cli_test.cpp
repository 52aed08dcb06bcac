// `lacuna partition --method boxes` end to end: stats lines, JSON, the Figure 2 picture, and one
// line with exit code 2 (nothing written) for bad options.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/cli_run.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

using CliRun = lacuna::test::CliResult;
std::string slurp(const fs::path& p) {
    return lacuna::test::slurp_file(p);
}

fs::path temp_dir() {
    static const fs::path dir = lacuna::test::cli_temp_dir("boxes");
    return dir;
}

CliRun run_cli(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
}

const fs::path& volume() {
    static fs::path v = [] {
        fs::path p = temp_dir() / "shells.nrrd";
        EXPECT_EQ(run_cli("generate sphere-shells --dims 33x30x27 --out " + p.string()).code, 0);
        return p;
    }();
    return v;
}

TEST(PartitionBoxesCli, WritesStatsJsonAndFigure2) {
    const fs::path json = temp_dir() / "boxes.json", png = temp_dir() / "fig2.png";
    const CliRun r = run_cli("partition " + volume().string() +
                             " --tf mr-default --method boxes --size 64 --json " + json.string() +
                             " --out " + png.string());
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* line : {"boxes grown:", "after BSP splits:", "after merges:",
                             "empty under TF:", "TF classification"})
        EXPECT_NE(r.out.find(line), std::string::npos) << line << " missing from " << r.out;
    const nlohmann::json j = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(j["method"], "boxes");
    const auto& c = j["counts"];
    EXPECT_EQ(j["boxes"].size(), c["after_merge"].get<size_t>());
    EXPECT_EQ(j["grown_boxes"].size(), c["grown"].get<size_t>());
    EXPECT_GE(c["after_split"].get<size_t>(), c["grown"].get<size_t>());
    EXPECT_LE(c["after_merge"].get<size_t>(), c["after_split"].get<size_t>());
    // The listed boxes tile the grid.
    int64_t cells = 0;
    for (const auto& b : j["boxes"]) cells += b["cells"].get<int64_t>();
    EXPECT_EQ(cells, 32 * 29 * 26);
    EXPECT_EQ(slurp(png).substr(1, 3), "PNG");
    // Without merging, the leaves are the split boxes.
    const CliRun n = run_cli("partition " + volume().string() +
                             " --tf mr-default --method boxes --no-merge --json " + json.string());
    ASSERT_EQ(n.code, 0) << n.err;
    const nlohmann::json k = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(k["counts"]["after_merge"], k["counts"]["after_split"]);
}

TEST(PartitionBoxesCli, BadOptionsAreOneLineExit2AndWriteNothing) {
    const fs::path json = temp_dir() / "bad.json";
    for (const std::string& opt :
         {std::string("--spread -3"), std::string("--min-box 0"), std::string("--gradient 2"),
          std::string("--gradient-waste -0.5"), std::string("--other-cost -1"),
          std::string("--thin -2"), std::string("--slice 999"), std::string("--repeat 0")}) {
        const CliRun r =
            run_cli("partition " + volume().string() + " --tf mr-default --method boxes " + opt +
                    " --json " + json.string());
        EXPECT_EQ(r.code, 2) << opt << ": " << r.err;
        const std::string flag = opt.substr(0, opt.find(' '));
        EXPECT_NE(r.err.find(flag), std::string::npos) << opt << ": " << r.err;
        ASSERT_FALSE(r.err.empty());
        EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << opt << ": " << r.err;
        EXPECT_FALSE(fs::exists(json)) << opt;
    }
}

}  // namespace
}  // namespace lacuna
