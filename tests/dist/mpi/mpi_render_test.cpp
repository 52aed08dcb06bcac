// `mpirun --oversubscribe -np N lacuna render ...` against the one-process `lacuna render` of the
// same flags with --ert 1 (distributed frames march every ray to its end, docs/distributed.md):
// within 1 of 255 on every channel and byte-identical on >= 99% of the pixels, for N = 1, 2, 3,
// 4, 7, several structures, both compositors, on a generated volume and on mricron's ch2.
// Registered only when CMake found MPI and its launcher (LACUNA_MPIEXEC).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "apps/cli_run.h"
#include "lacuna/image.h"

namespace lacuna::test {
namespace {

namespace fs = std::filesystem;

const fs::path& dir() {
    static const fs::path d = cli_temp_dir("mpi");
    return d;
}

// mpirun with what this machine needs: more ranks than cores, root in containers.
CliResult run_mpi(int ranks, const std::string& args) {
    const std::string root = ::geteuid() == 0 ? " --allow-run-as-root" : "";
    return run_command(std::string(LACUNA_MPIEXEC) + root + " --oversubscribe -np " +
                           std::to_string(ranks) + " " + LACUNA_CLI_PATH + " " + args,
                       dir());
}

// Within 1 of 255 everywhere, identical on >= 99% of the pixels; returns the differing pixels.
size_t expect_close(const fs::path& a, const fs::path& b, const std::string& what) {
    const Image x = read_png(a.string()), y = read_png(b.string());
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.height, y.height);
    if (x.rgba.size() != y.rgba.size()) return SIZE_MAX;
    size_t differ = 0;
    int worst = 0;
    for (size_t p = 0; p < x.rgba.size() / 4; ++p) {
        bool d = false;
        for (int c = 0; c < 4; ++c) {
            const int e = std::abs(int(x.rgba[p * 4 + c]) - int(y.rgba[p * 4 + c]));
            worst = std::max(worst, e);
            d = d || e != 0;
        }
        differ += d;
    }
    EXPECT_LE(worst, 1) << what;
    EXPECT_LE(double(differ), 0.01 * double(x.rgba.size() / 4))
        << what << ": " << differ << " pixels differ";
    return differ;
}

// Nested shells under a TF that keeps most of them half transparent: long front-to-back chains
// in most pixels, so compositing's float association gets every chance to show.
const fs::path& shells_volume() {
    static const fs::path v = [] {
        const fs::path p = dir() / "shells.nrrd";
        const CliResult r = run_cli(
            "generate sphere-shells --dims 45x38x52 --out " + p.string() + " --quiet", dir());
        EXPECT_EQ(r.code, 0) << r.err;
        return p;
    }();
    return v;
}

// The one-process reference and every rank count and compositor against it.
void check_frames(const std::string& volume, const std::string& frame, const std::string& tag,
                  const std::vector<int>& ranks, const std::vector<std::string>& composites) {
    const fs::path ref = dir() / (tag + "_ref.png");
    const CliResult r =
        run_cli("render " + volume + " " + frame + " --ert 1 --quiet --out " + ref.string(), dir());
    ASSERT_EQ(r.code, 0) << r.err;
    for (int n : ranks)
        for (const std::string& c : composites) {
            const fs::path out = dir() / (tag + "_" + std::to_string(n) + "_" + c + ".png");
            const CliResult m = run_mpi(n, "render " + volume + " " + frame + " --composite " + c +
                                               " --out " + out.string());
            ASSERT_EQ(m.code, 0) << m.err << m.out;
            EXPECT_NE(m.out.find(std::to_string(n) + " ranks"), std::string::npos) << m.out;
            expect_close(out, ref, tag + " on " + std::to_string(n) + " ranks, " + c);
        }
}

constexpr const char* kFrame = "--tf mr-default --size 64 --azimuth 40 --elevation 25 --zoom 1.6";

TEST(MpiRender, NoneOnEveryRankCount) {
    check_frames(shells_volume().string(), std::string(kFrame) + " --accel none", "none",
                 {1, 2, 3, 4, 7}, {"direct", "binary-swap", "radix-k"});
}

TEST(MpiRender, GridBitfieldKdtreeMatchOneProcess) {
    for (const char* accel : {"auto", "bitfield", "kdtree"})
        check_frames(shells_volume().string(), std::string(kFrame) + " --accel " + accel, accel,
                     {2, 3, 4, 7}, {accel[0] == 'b' ? "binary-swap" : "direct"});
}

TEST(MpiRender, VisibleBalanceOrthographicAndInside) {
    check_frames(shells_volume().string(), std::string(kFrame) + " --ortho --balance visible",
                 "ortho", {3, 4}, {"binary-swap", "radix-k"});
    check_frames(
        shells_volume().string(),
        "--tf mr-default --size 48 --azimuth 0 --elevation 0 --zoom 12 --fov 60 --accel grid",
        "inside", {2, 7}, {"binary-swap"});
}

TEST(MpiRender, Ch2HeadMatchesOneProcess) {
    const std::string ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
    if (!fs::exists(ch2)) GTEST_SKIP() << ch2 << " missing (mricron-data)";
    check_frames(ch2, "--tf mr-skin --size 64 --view anterior --balance visible", "ch2", {2, 4},
                 {"direct", "binary-swap"});
}

TEST(MpiRender, OnlyRankZeroWritesAndReports) {
    const fs::path out = dir() / "rank0.png";
    const CliResult m = run_mpi(3, "render " + shells_volume().string() + " " + kFrame +
                                       " --rank-times --out " + out.string());
    ASSERT_EQ(m.code, 0) << m.err;
    EXPECT_TRUE(fs::exists(out));
    // One report (rank 0's), with a line per rank.
    EXPECT_EQ(m.out.find("wrote"), m.out.rfind("wrote")) << m.out;
    EXPECT_NE(m.out.find("early ray termination: off"), std::string::npos) << m.out;
    for (int r = 0; r < 3; ++r)
        EXPECT_NE(m.out.find("\n   " + std::to_string(r) + " "), std::string::npos) << m.out;
}

// A raw file is read by offset: each rank reads its brick (the read% column of --rank-times),
// and the frame is the one-process frame, the visualization range agreed from the bricks'.
TEST(MpiRender, RawBricksAreReadByOffset) {
    const fs::path raw = dir() / "shells_45x38x52_uint8.raw";
    ASSERT_EQ(
        run_cli("generate sphere-shells --dims 45x38x52 --out " + raw.string() + " --quiet", dir())
            .code,
        0);
    for (int n : {2, 4}) {
        check_frames(raw.string(), std::string(kFrame) + " --accel bitfield",
                     "raw" + std::to_string(n), {n}, {"direct"});
        const CliResult m = run_mpi(n, "render " + raw.string() + " " + kFrame +
                                           " --rank-times --out " + (dir() / "raw.png").string());
        ASSERT_EQ(m.code, 0) << m.err;
        int rows = 0;
        for (size_t p = m.out.find("\n"); p != std::string::npos; p = m.out.find("\n", p + 1)) {
            int rank;
            double f[7], voxels, read;
            unsigned long long samples;
            if (std::sscanf(m.out.c_str() + p + 1, "%d %lf %lf %lf %lf %lf %llu %lf %lf", &rank,
                            &f[0], &f[1], &f[2], &f[3], &f[4], &samples, &voxels, &read) == 9) {
                ++rows;
                EXPECT_EQ(read, voxels) << m.out;  // the brick, not the file
                EXPECT_LT(read, 100.0 / n + 10.0) << m.out;
            }
        }
        EXPECT_EQ(rows, n) << m.out;
    }
}

// Every lattice sample once: the per-pixel counts summed over the ranks are the one-process
// counts of --accel none, so the heat maps are the same bytes.
TEST(MpiRender, HeatmapOfNoneIsTheOneProcessHeatmap) {
    const std::string frame = "render " + shells_volume().string() + " " + kFrame + " --accel none";
    const CliResult r = run_cli(frame + " --ert 1 --quiet --out " + (dir() / "h_ref.png").string() +
                                    " --heatmap " + (dir() / "h_ref_heat.png").string(),
                                dir());
    ASSERT_EQ(r.code, 0) << r.err;
    for (int n : {3, 4}) {
        const fs::path heat = dir() / ("h_" + std::to_string(n) + "_heat.png");
        const CliResult m = run_mpi(
            n, frame + " --out " + (dir() / "h.png").string() + " --heatmap " + heat.string());
        ASSERT_EQ(m.code, 0) << m.err;
        EXPECT_EQ(slurp_file(heat), slurp_file(dir() / "h_ref_heat.png")) << n << " ranks";
    }
}

TEST(MpiRender, RefusedFramesAreOneLineFromRankZero) {
    for (const char* flags : {"--shading phong", "--orbit 3", "--renderer slice"}) {
        const CliResult m = run_mpi(2, "render " + shells_volume().string() + " " + kFrame + " " +
                                           flags + " --out " + (dir() / "refused.png").string());
        EXPECT_NE(m.code, 0) << flags;
        size_t lines = 0;
        for (size_t p = m.err.find("lacuna:"); p != std::string::npos;
             p = m.err.find("lacuna:", p + 1))
            ++lines;
        EXPECT_EQ(lines, 1u) << flags << ": " << m.err;
        EXPECT_FALSE(fs::exists(dir() / "refused.png"));
    }
}

// A failure every rank meets while loading (a file that is not there, a raw file of the wrong
// size) is agreed on before any rank waits for another: one line, from rank 0, no abort.
TEST(MpiRender, LoadFailuresAreOneLineFromRankZero) {
    const fs::path bad = dir() / "short_45x38x52_uint8.raw";
    {
        std::ofstream f(bad, std::ios::binary);
        f << "too short";
    }
    for (const std::string& vol : {(dir() / "absent.nrrd").string(), bad.string()}) {
        const CliResult m = run_mpi(
            3, "render " + vol + " " + kFrame + " --out " + (dir() / "absent.png").string());
        EXPECT_EQ(m.code, 2) << vol << ": " << m.err;
        size_t lines = 0;
        for (size_t p = m.err.find("lacuna:"); p != std::string::npos;
             p = m.err.find("lacuna:", p + 1))
            ++lines;
        EXPECT_EQ(lines, 1u) << vol << ": " << m.err;
        EXPECT_EQ(m.err.find("MPI_ABORT"), std::string::npos) << m.err;
    }
}

}  // namespace
}  // namespace lacuna::test
