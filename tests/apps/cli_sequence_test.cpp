// Progress, --quiet, --orbit and --movie end to end (docs/cli.md): the summary line on a pipe and
// the in-place line with its ETA on a terminal; orbit frames equal to single frames at the same
// azimuth byte for byte; an H.264 MP4 checked by ffprobe; and every failure of the movie path
// (ffmpeg missing, ffmpeg failing) one line, exit 2, nothing written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "apps/cli_run.h"

namespace fs = std::filesystem;

namespace {

using lacuna::test::CliResult;
using lacuna::test::expect_one_line_error;
using lacuna::test::slurp_file;

fs::path temp_dir() {
    static const fs::path dir = lacuna::test::cli_temp_dir("sequence");
    return dir;
}

CliResult run(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
}

// The CLI with `env` (e.g. "PATH=/x") in front of it.
CliResult run_env(const std::string& env, const std::string& args) {
    const fs::path out = temp_dir() / "env-out.txt", err = temp_dir() / "env-err.txt";
    const std::string cmd = "env " + env + " " + LACUNA_CLI_PATH + " " + args + " >" +
                            out.string() + " 2>" + err.string() + " </dev/null";
    const int status = std::system(cmd.c_str());
    CliResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp_file(out);
    r.err = slurp_file(err);
    return r;
}

// The output of a shell command (its exit code in `code`).
std::string shell(const std::string& cmd, int& code) {
    const fs::path out = temp_dir() / "shell-out.txt";
    const int status = std::system((cmd + " >" + out.string() + " 2>&1 </dev/null").c_str());
    code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return slurp_file(out);
}

const fs::path& volume() {
    static const fs::path p = [] {
        const fs::path v = temp_dir() / "shells.nrrd";
        const CliResult r = run("generate sphere-shells --dims 31x28x25 --out " + v.string());
        EXPECT_EQ(r.code, 0) << r.err;
        return v;
    }();
    return p;
}

std::string render_args() {
    return "render " + volume().string() + " --tf mr-default --size 40";
}

size_t lines(const std::string& s) {
    return size_t(std::count(s.begin(), s.end(), '\n'));
}

// Files in the test folder whose name starts with `prefix` (leftovers, temporaries).
int count_files(const std::string& prefix) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(temp_dir()))
        n += e.path().filename().string().rfind(prefix, 0) == 0;
    return n;
}

TEST(CliProgress, OnAPipeOneSummaryLineAndNothingUnderQuiet) {
    const fs::path png = temp_dir() / "sum.png";
    const CliResult orbit = run(render_args() + " --orbit 3 --out " + png.string());
    ASSERT_EQ(orbit.code, 0) << orbit.err;
    EXPECT_EQ(orbit.err.rfind("render: 3 frames in ", 0), 0u) << orbit.err;
    EXPECT_NE(orbit.err.find(" ms/frame)\n"), std::string::npos) << orbit.err;
    EXPECT_EQ(lines(orbit.err), 1u) << orbit.err;
    EXPECT_EQ(orbit.err.find('\r'), std::string::npos) << "a terminal line on a pipe";

    const CliResult one = run(render_args() + " --out " + png.string());
    ASSERT_EQ(one.code, 0) << one.err;
    EXPECT_EQ(one.err.rfind("render: 1 frame in ", 0), 0u) << one.err;
    EXPECT_EQ(lines(one.err), 1u) << one.err;

    const CliResult gen =
        run("generate sphere-shells --dims 9x9x9 --out " + (temp_dir() / "g.nrrd").string());
    ASSERT_EQ(gen.code, 0) << gen.err;
    EXPECT_EQ(gen.err.rfind("generate: done in ", 0), 0u) << gen.err;

    // --quiet after the subcommand and before it: no progress, no summary; stdout unchanged.
    const CliResult q1 = run(render_args() + " --orbit 3 --quiet --out " + png.string());
    ASSERT_EQ(q1.code, 0) << q1.err;
    EXPECT_EQ(q1.err, "");
    EXPECT_NE(q1.out.find("orbit of 3 frames"), std::string::npos) << q1.out;
    const CliResult q2 = run("--quiet " + render_args() + " --orbit 3 --out " + png.string());
    ASSERT_EQ(q2.code, 0) << q2.err;
    EXPECT_EQ(q2.err, "");
    const CliResult q3 =
        run("generate -q sphere-shells --dims 9x9x9 --out " + (temp_dir() / "g.nrrd").string());
    ASSERT_EQ(q3.code, 0) << q3.err;
    EXPECT_EQ(q3.err, "");
    // --quiet never silences an error.
    expect_one_line_error(run("--quiet " + render_args() + " --orbit -2 --out " + png.string()),
                          "--orbit");
}

// On a terminal (script(1) gives the command a pty): the line is redrawn with '\r', shows
// frames done of the total and the ETA, and ends with the summary.
TEST(CliProgress, OnATerminalFramesDoneOfTotalWithEta) {
    const fs::path png = temp_dir() / "tty.png";
    int code = -1;
    const std::string cmd =
        std::string(LACUNA_CLI_PATH) + " " + render_args() + " --orbit 5 --out " + png.string();
    const std::string out = shell("script -qec '" + cmd + " >/dev/null' /dev/null", code);
    ASSERT_EQ(code, 0) << out;
    EXPECT_NE(out.find("\rrender: 1/5 frames, "), std::string::npos) << out;
    EXPECT_NE(out.find(", ETA "), std::string::npos) << out;
    EXPECT_NE(out.find("\rrender: 5 frames in "), std::string::npos) << out;
    // Under --quiet the terminal sees nothing either.
    const std::string quiet = shell("script -qec '" + cmd + " --quiet >/dev/null' /dev/null", code);
    ASSERT_EQ(code, 0) << quiet;
    EXPECT_EQ(quiet.find("render:"), std::string::npos) << quiet;
}

// Orbit frame i is the single frame at azimuth start + 360 i / N, byte for byte, named
// NAME_000i.png; and a TF animation uses the same numbering.
TEST(CliOrbit, FramesEqualSingleFramesAtTheSameAzimuth) {
    const fs::path seq = temp_dir() / "orb.png";
    const std::string view = " --azimuth 30 --elevation 20 --accel bitfield";
    const CliResult r = run(render_args() + view + " --orbit 4 --out " + seq.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("orbit of 4 frames"), std::string::npos) << r.out;
    for (int i = 0; i < 4; ++i)
        ASSERT_TRUE(fs::exists(temp_dir() / ("orb_000" + std::to_string(i) + ".png"))) << i;
    EXPECT_FALSE(fs::exists(temp_dir() / "orb_0004.png"));
    EXPECT_FALSE(fs::exists(seq));
    const int azimuths[] = {30, 120, 210, 300};
    for (int i = 0; i < 4; ++i) {
        const fs::path one = temp_dir() / ("one" + std::to_string(i) + ".png");
        const CliResult s = run(render_args() + " --azimuth " + std::to_string(azimuths[i]) +
                                " --elevation 20 --accel none --out " + one.string());
        ASSERT_EQ(s.code, 0) << s.err;
        EXPECT_EQ(slurp_file(one),
                  slurp_file(temp_dir() / ("orb_000" + std::to_string(i) + ".png")))
            << "frame " << i;
    }
    // Not all the same picture (the camera moves).
    EXPECT_NE(slurp_file(temp_dir() / "orb_0000.png"), slurp_file(temp_dir() / "orb_0001.png"));
}

TEST(CliOrbit, BadCombinationsAreOneLineAndWriteNothing) {
    const fs::path png = temp_dir() / "bad.png";
    expect_one_line_error(run(render_args() + " --orbit -1 --out " + png.string()), "--orbit");
    expect_one_line_error(run(render_args() + " --orbit 3 --repeat 2 --out " + png.string()),
                          "--repeat");
    expect_one_line_error(
        run(render_args() + " --orbit 3 --tf-animate mr-default mr-gap --out " + png.string()),
        "--orbit");
    expect_one_line_error(run(render_args() + " --movie m.mp4 --out " + png.string()), "--movie");
    expect_one_line_error(
        run(render_args() + " --orbit 2 --movie " + (temp_dir() / "m.avi").string()), ".mp4");
    expect_one_line_error(
        run(render_args() + " --orbit 2 --fps 0 --movie " + (temp_dir() / "m.mp4").string()),
        "--fps");
    EXPECT_EQ(count_files("bad"), 0);
    EXPECT_EQ(count_files("m."), 0);
}

// ffprobe's value of `entry` for the first video stream ("" if none).
std::string probe(const fs::path& mp4, const std::string& entry) {
    int code = -1;
    std::string v =
        shell("ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=" + entry +
                  " -of default=noprint_wrappers=1:nokey=1 " + mp4.string(),
              code);
    EXPECT_EQ(code, 0) << v;
    while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
    return v;
}

// ffmpeg is in scripts/install-deps' default set: a machine without it fails here (no skip).
TEST(CliMovie, WritesAnH264Mp4WithEveryFrame) {
    ASSERT_EQ(std::system("command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null"), 0)
        << "ffmpeg/ffprobe missing: run scripts/install-deps";
    const fs::path mp4 = temp_dir() / "orbit.mp4";
    const CliResult r = run(render_args() + " --orbit 6 --fps 12 --movie " + mp4.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("(6 frames at 12 fps)"), std::string::npos) << r.out;
    EXPECT_EQ(probe(mp4, "codec_name"), "h264");
    EXPECT_EQ(probe(mp4, "width"), "40");
    EXPECT_EQ(probe(mp4, "height"), "40");
    EXPECT_EQ(probe(mp4, "nb_read_frames"), "6");
    EXPECT_EQ(probe(mp4, "r_frame_rate"), "12/1");
    EXPECT_EQ(count_files("orbit_"), 0) << "--movie without --out writes no PNGs";
    EXPECT_EQ(count_files(".tmp-"), 0);

    // An odd edge is padded to even; a TF animation makes a movie too, beside its PNGs.
    const fs::path anim = temp_dir() / "anim.mp4", png = temp_dir() / "animf.png";
    const CliResult a = run("render " + volume().string() +
                            " --tf-animate mr-default mr-gap --frames 3 --accel minmax --width 41 "
                            "--height 30 --movie " +
                            anim.string() + " --out " + png.string());
    ASSERT_EQ(a.code, 0) << a.err;
    EXPECT_EQ(probe(anim, "codec_name"), "h264");
    EXPECT_EQ(probe(anim, "width"), "42");
    EXPECT_EQ(probe(anim, "height"), "30");
    EXPECT_EQ(probe(anim, "nb_read_frames"), "3");
    EXPECT_TRUE(fs::exists(temp_dir() / "animf_0002.png"));
}

TEST(CliMovie, NoFfmpegOrAFailingOneLeavesNothing) {
    const fs::path mp4 = temp_dir() / "fail.mp4", png = temp_dir() / "failf.png";
    // No ffmpeg on PATH: refused before any work (no frame written).
    expect_one_line_error(run_env("PATH=/nonexistent", render_args() + " --orbit 3 --movie " +
                                                           mp4.string() + " --out " + png.string()),
                          "--movie: ffmpeg: no ffmpeg program on PATH");
    EXPECT_FALSE(fs::exists(mp4));
    EXPECT_EQ(count_files("failf"), 0);

    // An ffmpeg that refuses: its message in the one line, exit 2, no movie, no temporary.
    const fs::path bin = temp_dir() / "fakebin";
    fs::create_directories(bin);
    {
        std::ofstream f(bin / "ffmpeg");
        f << "#!/bin/sh\necho 'first line' >&2\necho 'Unknown encoder libx264' >&2\nexit 1\n";
    }
    fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
    {
        std::ofstream f(mp4);
        f << "old movie";
    }
    const CliResult r = run_env("PATH=" + bin.string() + ":/usr/bin:/bin",
                                render_args() + " --orbit 3 --movie " + mp4.string());
    expect_one_line_error(r, "ffmpeg says: Unknown encoder libx264");
    EXPECT_NE(r.err.find(mp4.string() + ": movie: "), std::string::npos) << r.err;
    EXPECT_EQ(slurp_file(mp4), "old movie") << "the target is untouched";
    EXPECT_EQ(count_files(".tmp-"), 0);
    // An ffmpeg that reads everything and then fails.
    {
        std::ofstream f(bin / "ffmpeg");
        f << "#!/bin/sh\ncat >/dev/null\necho 'disk full' >&2\nexit 3\n";
    }
    const CliResult late = run_env("PATH=" + bin.string() + ":/usr/bin:/bin",
                                   render_args() + " --orbit 3 --movie " + mp4.string());
    expect_one_line_error(late, "ffmpeg failed (exit 3): ffmpeg says: disk full");
    EXPECT_EQ(slurp_file(mp4), "old movie");
    EXPECT_EQ(count_files(".tmp-"), 0);
}

}  // namespace
