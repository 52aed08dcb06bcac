// `lacuna render --renderer slice` end to end: every box source writes the bytes of --accel none,
// occlusion at threshold 1 too; invalid combinations are one line and exit code 2; `bench li`
// runs on a tiny orbit.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

struct CliRun {
    int code = -1;
    std::string out, err;
};

fs::path temp_dir() {
    static fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("lacuna-slice-cli-" + std::to_string(::getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

CliRun run(const std::string& args) {
    const fs::path out = temp_dir() / "stdout.txt", err = temp_dir() / "stderr.txt";
    const std::string cmd = std::string(LACUNA_CLI_PATH) + " " + args + " >" + out.string() +
                            " 2>" + err.string() + " </dev/null";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

void expect_one_line_error(const CliRun& r, const std::string& needle) {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
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
    CliRun r = run("render " + v + " --tf mr-default --size 40 --renderer slice --out " + ref.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("slice renderer"), std::string::npos) << r.out;
    for (const std::string extra : {"--accel kdtree", "--accel kdtree --occlusion --occlusion-threshold 1",
                                    "--accel kdtree --ortho --azimuth 100", "--threads 1"}) {
        const fs::path png = temp_dir() / "x.png";
        r = run("render " + v + " --tf mr-default --size 40 --renderer slice " + extra + " --out " +
                png.string());
        ASSERT_EQ(r.code, 0) << extra << ": " << r.err;
        if (extra.find("ortho") == std::string::npos) EXPECT_EQ(slurp(png), slurp(ref)) << extra;
    }
}

TEST(SliceCli, InvalidCombinationsAreOneLineExit2) {
    const std::string v = volume().string();
    const std::string base = "render " + v + " --tf mr-default --size 16 ";
    expect_one_line_error(run(base + "--renderer raytrace --out x.png"), "--renderer");
    expect_one_line_error(run(base + "--occlusion --out x.png"), "--renderer slice");
    expect_one_line_error(run(base + "--renderer slice --occlusion-threshold 0.9 --out x.png"),
                          "--occlusion");
    expect_one_line_error(run(base + "--renderer slice --occlusion --occlusion-threshold 1.5 --out x.png"),
                          "--occlusion-threshold");
    expect_one_line_error(run(base + "--renderer slice --occlusion --occlusion-map 0 --out x.png"),
                          "--occlusion-map");
    expect_one_line_error(run(base + "--renderer slice --accel bitfield --out x.png"), "--accel");
    expect_one_line_error(run(base + "--renderer slice --heatmap h.png --out x.png"), "--heatmap");
    expect_one_line_error(run("bench li --ess octree"), "--ess");
    EXPECT_FALSE(fs::exists("x.png"));
}

}  // namespace
