// `mpirun --oversubscribe -np N lacuna render ...` against the one-process `lacuna render` of the
// same flags with --ert 1 (distributed frames march every ray to its end, docs/distributed.md):
// within 1 of 255 on every channel and byte-identical on >= 99% of the pixels, for N = 1, 2, 3,
// 4, 7, several structures, both compositors, on a generated volume and on mricron's ch2.
// Registered only when CMake found MPI and its launcher (LACUNA_MPIEXEC).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "apps/cli_run.h"
#include "dist/mpi/mpirun.h"
#include "lacuna/image.h"

namespace lacuna::test {
namespace {

namespace fs = std::filesystem;

const fs::path& dir() {
    static const fs::path d = cli_temp_dir("mpi");
    return d;
}

// mpirun (mpirun.h) with N ranks of the CLI.
CliResult run_mpi(int ranks, const std::string& args) {
    return run_command(
        mpirun_command() + " -np " + std::to_string(ranks) + " " + LACUNA_CLI_PATH + " " + args,
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

// The registry's other structures under mpirun (every structure: the in-process
// DistributedFrame tests take each on 1, 2, 3, 4 and 7 bricks).
TEST(MpiRender, EveryOtherStructureMatchesOneProcess) {
    for (const char* accel : {"minmax", "minmax-interval", "boolean", "distance", "chebyshev"})
        check_frames(shells_volume().string(), std::string(kFrame) + " --accel " + accel,
                     std::string("every_") + accel, {3}, {"radix-k"});
}

TEST(MpiRender, VisibleBalanceOrthographicAndInside) {
    check_frames(shells_volume().string(), std::string(kFrame) + " --ortho --balance visible",
                 "ortho", {3, 4}, {"binary-swap", "radix-k"});
    check_frames(
        shells_volume().string(),
        "--tf mr-default --size 48 --azimuth 0 --elevation 0 --zoom 12 --fov 60 --accel grid",
        "inside", {2, 7}, {"binary-swap"});
}

// Features of one sample at a time under mpirun: Phong shading (the ghost layer gives every
// brick the whole volume's gradients), a clip plane and jitter.
TEST(MpiRender, ShadedClippedJitteredFramesMatchOneProcess) {
    check_frames(shells_volume().string(),
                 std::string(kFrame) + " --accel bitfield --shading phong --clip 0.6,-0.8,0,-4",
                 "shaded", {2, 3, 7}, {"binary-swap"});
    check_frames(shells_volume().string(),
                 std::string(kFrame) + " --shading phong --gradient-volume --jitter", "jittered",
                 {4}, {"direct", "radix-k"});
}

// --orbit and --repeat under mpirun: the bricks and structures made once, every frame the
// one-process frame of its azimuth; --repeat reports the median of the warm frames.
TEST(MpiRender, OrbitAndRepeatMatchOneProcess) {
    const std::string vol = shells_volume().string();
    const std::string frame = std::string(kFrame) + " --accel grid --orbit 3";
    const CliResult r = run_cli("render " + vol + " " + frame + " --ert 1 --quiet --out " +
                                    (dir() / "orbit_ref.png").string(),
                                dir());
    ASSERT_EQ(r.code, 0) << r.err;
    const CliResult m =
        run_mpi(3, "render " + vol + " " + frame + " --composite binary-swap --out " +
                       (dir() / "orbit.png").string());
    ASSERT_EQ(m.code, 0) << m.err << m.out;
    EXPECT_NE(m.out.find("orbit of 3 frames"), std::string::npos) << m.out;
    for (const char* i : {"0000", "0001", "0002"})
        expect_close(dir() / ("orbit_" + std::string(i) + ".png"),
                     dir() / ("orbit_ref_" + std::string(i) + ".png"), std::string("orbit ") + i);
    check_frames(vol, std::string(kFrame) + " --accel bitfield --repeat 3", "repeat", {2},
                 {"direct"});
    const CliResult rep = run_mpi(2, "render " + vol + " " + kFrame + " --repeat 3 --out " +
                                         (dir() / "repeat_report.png").string());
    ASSERT_EQ(rep.code, 0) << rep.err;
    EXPECT_NE(rep.out.find("3 frames; the median of the 2 after the first"), std::string::npos)
        << rep.out;
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

// The --rank-times rows: rank, voxels% and read% of each.
struct RankRow {
    int rank;
    double voxels, read;
};
std::vector<RankRow> rank_rows(const std::string& out) {
    std::vector<RankRow> rows;
    for (size_t p = out.find("\n"); p != std::string::npos; p = out.find("\n", p + 1)) {
        RankRow r;
        double f[5];
        unsigned long long samples;
        if (std::sscanf(out.c_str() + p + 1, "%d %lf %lf %lf %lf %lf %llu %lf %lf", &r.rank, &f[0],
                        &f[1], &f[2], &f[3], &f[4], &samples, &r.voxels, &r.read) == 9)
            rows.push_back(r);
    }
    return rows;
}

// A file whose voxels lie at an offset is read by offset: each rank reads its brick (the read%
// column of --rank-times is its voxels%), and the frame is the one-process frame, the range
// agreed from the bricks'. With --balance visible a rank reads its slab of the voxel tree first,
// then its brick of the visible tree (read% = the two shares, or one when they are the same box).
void check_by_offset(const fs::path& volume, const std::string& tag, int n,
                     const std::string& balance) {
    const std::string frame = std::string(kFrame) + " --accel bitfield --balance " + balance;
    check_frames(volume.string(), frame, tag + "_" + balance, {n}, {"direct"});
    const CliResult m = run_mpi(n, "render " + volume.string() + " " + frame +
                                       " --rank-times --out " + (dir() / "offset.png").string());
    ASSERT_EQ(m.code, 0) << m.err;
    const std::vector<RankRow> rows = rank_rows(m.out);
    EXPECT_EQ(int(rows.size()), n) << m.out;
    for (const RankRow& r : rows) {
        if (balance == "voxels") {
            EXPECT_EQ(r.read, r.voxels) << tag << m.out;  // the brick, not the file
            EXPECT_LT(r.read, 100.0 / n + 10.0) << tag << m.out;
        } else {
            EXPECT_GE(r.read, r.voxels) << tag << m.out;
            EXPECT_LT(r.read - r.voxels, 100.0 / n + 10.0) << tag << m.out;  // the slab
            EXPECT_LT(r.read, 100.0) << tag << m.out;
        }
    }
}

TEST(MpiRender, RawBricksAreReadByOffset) {
    const fs::path raw = dir() / "shells_45x38x52_uint8.raw";
    ASSERT_EQ(
        run_cli("generate sphere-shells --dims 45x38x52 --out " + raw.string() + " --quiet", dir())
            .code,
        0);
    for (int n : {2, 4}) check_by_offset(raw, "raw" + std::to_string(n), n, "voxels");
    check_by_offset(raw, "raw3", 3, "visible");
}

// Every format with voxels at an offset, each in another voxel type: NRRD attached and
// detached, MetaImage .mha and .mhd, NIfTI, float and big-endian raw.
TEST(MpiRender, EveryOffsetFormatIsReadByOffset) {
    const std::pair<const char*, const char*> files[] = {
        {"shells.nrrd", "uint16"}, {"shells.nhdr", "int16"},
        {"shells.mha", "float32"}, {"shells.mhd", "uint8"},
        {"shells.nii", "int16"},   {"shells_45x38x52_float32.raw", "float32"}};
    for (const auto& [name, type] : files) {
        const fs::path p = dir() / ("fmt_" + std::string(name));
        ASSERT_EQ(run_cli("generate sphere-shells --dims 45x38x52 --type " + std::string(type) +
                              " --out " + p.string() + " --quiet",
                          dir())
                      .code,
                  0)
            << name;
        check_by_offset(p, name, 3, "voxels");
        check_by_offset(p, name, 4, "visible");
    }
    // Big-endian: the uint16 raw file's bytes swapped, named _be.
    const fs::path le = dir() / "be_45x38x52_uint16.raw", be = dir() / "be_45x38x52_uint16_be.raw";
    ASSERT_EQ(run_cli("generate sphere-shells --dims 45x38x52 --type uint16 --out " + le.string() +
                          " --quiet",
                      dir())
                  .code,
              0);
    std::string bytes = slurp_file(le);
    for (size_t i = 0; i + 1 < bytes.size(); i += 2) std::swap(bytes[i], bytes[i + 1]);
    std::ofstream(be, std::ios::binary) << bytes;
    check_by_offset(be, "be", 2, "voxels");
    check_by_offset(be, "be", 3, "visible");
}

// NaN voxels of a float file read by offset become the whole volume's smallest value (not the
// brick's), as in one process.
TEST(MpiRender, NanVoxelsReadByOffsetAreTheWholeVolumesMinimum) {
    const fs::path f = dir() / "nan_45x38x52_float32.raw";
    ASSERT_EQ(run_cli("generate sphere-shells --dims 45x38x52 --type float32 --out " + f.string() +
                          " --quiet",
                      dir())
                  .code,
              0);
    std::string bytes = slurp_file(f);
    const float nan = NAN;
    for (size_t i = 0; i + 4 <= bytes.size(); i += 4 * 5) std::memcpy(&bytes[i], &nan, 4);
    std::ofstream(f, std::ios::binary | std::ios::trunc) << bytes;
    check_by_offset(f, "nan", 4, "voxels");
    check_by_offset(f, "nan", 3, "visible");
}

// A truncated file read by offset fails from its header on every rank alike: one line from rank
// 0, exit 2, no abort, no image.
TEST(MpiRender, TruncatedOffsetFilesAreOneLineFromRankZero) {
    for (const char* name : {"tr.nrrd", "tr.mha", "tr.nii", "tr_45x38x52_float32.raw"}) {
        const fs::path p = dir() / name;
        ASSERT_EQ(run_cli("generate sphere-shells --dims 45x38x52 --type float32 --out " +
                              p.string() + " --quiet",
                          dir())
                      .code,
                  0);
        fs::resize_file(p, fs::file_size(p) - 1000);
        const fs::path png = dir() / "truncated.png";
        const CliResult m =
            run_mpi(3, "render " + p.string() + " " + kFrame + " --out " + png.string());
        EXPECT_EQ(m.code, 2) << name << ": " << m.err;
        size_t lines = 0;
        for (size_t q = m.err.find("lacuna:"); q != std::string::npos;
             q = m.err.find("lacuna:", q + 1))
            ++lines;
        EXPECT_EQ(lines, 1u) << name << ": " << m.err;
        EXPECT_NE(m.err.find(p.filename().string()), std::string::npos) << name << ": " << m.err;
        EXPECT_EQ(m.err.find("MPI_ABORT"), std::string::npos) << m.err;
        EXPECT_FALSE(fs::exists(png)) << name;
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
    for (const char* flags : {"--shading phong --shadows", "--blend mip",
                              "--tf-animate mr-default mr-skin", "--renderer slice"}) {
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

// `lacuna bench mpi` runs (tiny sizes): its report has the scaling rows and the compositing
// counts of composite.cpp equal the model's (composite_model.h). Times are not checked.
TEST(MpiRender, BenchMpiRunsAndItsCountsAreTheModels) {
    const fs::path out = dir() / "bench";
    const CliResult r = run_cli(
        "bench mpi --quick --mpirun '" + mpirun_launcher() + "' --out-dir " + out.string(), dir());
    ASSERT_EQ(r.code, 0) << r.err << r.out;
    const std::string md = slurp_file(out / "mpi.md");
    for (const char* want :
         {"## Strong scaling", "## Weak scaling", "| 1 | tree_40x40x40_uint8.raw |",
          "| 2 | tree_40x40x40_uint8.raw |", "| 2 | tree_48x24x24_uint8.raw |",
          "every count equals the model's", "| radix-k | 3 | 64² |", "| 1024 |"})
        EXPECT_NE(md.find(want), std::string::npos) << want << "\n" << md;
}

}  // namespace
}  // namespace lacuna::test
