// Session files (session/session_file.h, docs/cli.md): a frame rendered from flags, saved with
// --save-session and rendered again with --session gives the same bytes; the parser's round trip
// is exact; malformed files are one line naming the JSON field, exit 2, nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/cli_run.h"
#include "lacuna/error.h"
#include "session/session_file.h"

namespace fs = std::filesystem;

namespace {

using lacuna::test::CliResult;
using lacuna::test::expect_one_line_error;
using lacuna::test::slurp_file;

fs::path temp_dir() {
    static const fs::path dir = lacuna::test::cli_temp_dir("session");
    return dir;
}

CliResult run(const std::string& args) {
    return lacuna::test::run_cli(args, temp_dir());
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

void write(const fs::path& p, const std::string& text) {
    std::ofstream f(p, std::ios::binary);
    f << text;
}

// Flags that touch most of a FrameSpec: camera, size, structure, sampling, shading, clip, crop,
// background, range; each frame from flags equals its frame from the saved session.
TEST(CliSession, SavedSessionRendersTheSameBytes) {
    const std::string cases[] = {
        " --tf mr-default --size 40 --azimuth 75 --elevation -10 --zoom 1.3 --accel bitfield",
        " --tf mr-gap --width 37 --height 29 --ortho --step 0.7 --ert 1 --interpolation nearest "
        "--background 0.1,0.2,0.3 --accel minmax --leaf 4",
        " --tf ct-bone --size 32 --shading phong --clip 1,0,0,0 --jitter --range 10:200 --fov 40",
        " --tf mr-default --size 32 --renderer slice --accel none",
        // A piecewise gradient opacity, and a TF whose rendering set the features (Slicer's
        // MR-Default: Phong 0.2,1,0,1): the file holds the resolved features and the TF.
        " --tf mr-default --size 32 --gradient-opacity 0:0,4:0,4:0.5,30:1 --shading phong",
        " --tf MR-Default --size 32 --accel bitfield",
    };
    int i = 0;
    for (const std::string& flags : cases) {
        const std::string n = std::to_string(i++);
        const fs::path a = temp_dir() / ("flags" + n + ".png"),
                       b = temp_dir() / ("file" + n + ".png"),
                       json = temp_dir() / ("s" + n + ".json");
        const CliResult r1 = run("render " + volume().string() + flags + " --out " + a.string() +
                                 " --save-session " + json.string());
        ASSERT_EQ(r1.code, 0) << flags << "\n" << r1.err;
        ASSERT_TRUE(fs::exists(json)) << flags;
        const CliResult r2 = run("render --session " + json.string() + " --out " + b.string());
        ASSERT_EQ(r2.code, 0) << flags << "\n" << r2.err;
        EXPECT_EQ(slurp_file(a), slurp_file(b)) << flags;
        // The file round-trips exactly: parse, write, parse gives the same text.
        const lacuna::SessionFile s = lacuna::load_session_file(json.string());
        EXPECT_EQ(lacuna::to_json(s), slurp_file(json)) << flags;
    }
    // A session's frame differs from the default one (the test would pass on a no-op otherwise).
    EXPECT_NE(slurp_file(temp_dir() / "flags0.png"), slurp_file(temp_dir() / "flags1.png"));
}

// An orbit from a session: frame 0 is the session's frame.
TEST(CliSession, OrbitFromASessionStartsAtItsFrame) {
    const fs::path a = temp_dir() / "o.png", json = temp_dir() / "o.json",
                   seq = temp_dir() / "oseq.png";
    ASSERT_EQ(run("render " + volume().string() + " --tf mr-default --size 32 --azimuth 10 --out " +
                  a.string() + " --save-session " + json.string())
                  .code,
              0);
    const CliResult r =
        run("render --session " + json.string() + " --orbit 2 --out " + seq.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(slurp_file(a), slurp_file(temp_dir() / "oseq_0000.png"));
}

// A relative volume path is read relative to the session file's folder.
TEST(CliSession, RelativeVolumePathIsBesideTheFile) {
    const fs::path a = temp_dir() / "rel.png", json = temp_dir() / "rel.json",
                   b = temp_dir() / "rel2.png";
    ASSERT_EQ(run("render " + volume().string() + " --tf mr-default --size 24 --out " + a.string() +
                  " --save-session " + json.string())
                  .code,
              0);
    nlohmann::json j = nlohmann::json::parse(slurp_file(json));
    j["volume"]["path"] = volume().filename().string();
    const fs::path sub = temp_dir() / "sub";
    fs::create_directories(sub);
    fs::copy_file(volume(), sub / volume().filename(), fs::copy_options::overwrite_existing);
    write(sub / "rel.json", j.dump());
    const CliResult r =
        run("render --session " + (sub / "rel.json").string() + " --out " + b.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(slurp_file(a), slurp_file(b));
}

TEST(CliSession, MalformedFilesNameTheFieldAndWriteNothing) {
    const fs::path good = temp_dir() / "good.json", out = temp_dir() / "never.png";
    ASSERT_EQ(run("render " + volume().string() + " --tf mr-default --size 24 --out " +
                  (temp_dir() / "g.png").string() + " --save-session " + good.string())
                  .code,
              0);
    const nlohmann::json base = nlohmann::json::parse(slurp_file(good));
    struct Case {
        const char* what;
        std::function<void(nlohmann::json&)> mutate;
        const char* needle;
    };
    const Case cases[] = {
        {"step as text", [](auto& j) { j["frame"]["sampling"]["step"] = "fast"; },
         "frame.sampling.step: expected a number"},
        {"step out of range", [](auto& j) { j["frame"]["sampling"]["step"] = -1; },
         "frame.sampling.step"},
        {"misspelt key", [](auto& j) { j["frame"]["camera"]["azimut_deg"] = 3; },
         "frame.camera.azimut_deg: unknown key"},
        {"unknown structure", [](auto& j) { j["frame"]["structure"]["name"] = "quadtree"; },
         "frame.structure.name"},
        {"bad bits",
         [](auto& j) {
             j["frame"]["structure"] = {{"name", "bitfield"}, {"bits", 7}};
         },
         "frame.structure.bits"},
        {"bad projection", [](auto& j) { j["frame"]["camera"]["projection"] = "fisheye"; },
         "frame.camera.projection: expected one of perspective, orthographic"},
        {"width not integer", [](auto& j) { j["frame"]["width"] = 1.5; }, "frame.width"},
        {"no volume", [](auto& j) { j.erase("volume"); }, "volume: missing"},
        {"volume path number", [](auto& j) { j["volume"]["path"] = 3; },
         "volume.path: expected a string"},
        {"bad tf", [](auto& j) { j["tf"]["opacity"] = "x"; }, ": tf: "},
        {"version", [](auto& j) { j["lacuna_session"] = 2; }, "lacuna_session: expected 1"},
        {"two_tfs without back", [](auto& j) { j["frame"]["two_tfs"] = true; }, "tf_back: missing"},
        // A segments frame in mask mode names its label volume (the viewer's segments toggle).
        {"segments without labels",
         [](auto& j) {
             j["frame"]["renderer"] = "segments";
             j["frame"]["structure"] = {{"name", "label-octree"}};
         },
         "labels: missing (frame.renderer is segments in mask mode"},
        {"background short",
         [](auto& j) {
             j["frame"]["background"] = {0, 0};
         },
         "frame.background: expected an array of three numbers"},
        {"gradient points not pairs",
         [](auto& j) {
             j["frame"]["features"]["gradient_opacity"]["points"] = {{0, 0, 1}};
         },
         "frame.features.gradient_opacity.points[0]: expected [x, a]"},
        {"gradient points unsorted",
         [](auto& j) {
             j["frame"]["features"]["gradient_opacity"] = {
                 {"enabled", true}, {"lo", 0}, {"hi", 1}, {"points", {{5, 0}, {1, 1}}}};
         },
         "features.gradient_opacity.points: expected points sorted by x"},
        {"gradient points empty",
         [](auto& j) {
             j["frame"]["features"]["gradient_opacity"]["points"] = nlohmann::json::array();
         },
         "frame.features.gradient_opacity.points: expected a non-empty array"},
    };
    int i = 0;
    for (const Case& c : cases) {
        nlohmann::json j = base;
        c.mutate(j);
        const fs::path f = temp_dir() / ("bad" + std::to_string(i++) + ".json");
        write(f, j.dump(1));
        const std::string before = slurp_file(f);
        const CliResult r = run("render --session " + f.string() + " --out " + out.string());
        SCOPED_TRACE(c.what);
        expect_one_line_error(r, c.needle);
        EXPECT_NE(r.err.find(f.string()), std::string::npos) << "names the file: " << r.err;
        EXPECT_FALSE(fs::exists(out));
        EXPECT_EQ(slurp_file(f), before) << "input untouched";
    }
    // Not JSON at all, and a missing file.
    write(temp_dir() / "text.json", "{\"lacuna_session\": 1,");
    expect_one_line_error(
        run("render --session " + (temp_dir() / "text.json").string() + " --out " + out.string()),
        "json: not valid JSON");
    expect_one_line_error(
        run("render --session " + (temp_dir() / "none.json").string() + " --out " + out.string()),
        "none.json: session: not a readable file");
    // A flag that would change the frame is refused, not ignored.
    expect_one_line_error(
        run("render --session " + good.string() + " --size 64 --out " + out.string()),
        "--session: flags: the session file sets the frame; drop --size");
    EXPECT_FALSE(fs::exists(out));
    // --save-session of what a file cannot hold (segments) fails before rendering.
    const fs::path seg_json = temp_dir() / "seg.json";
    expect_one_line_error(
        run("render " + volume().string() + " --segments labels --size 16 --out " + out.string() +
            " --save-session " + seg_json.string()),
        "--save-session: frame.renderer");
    EXPECT_FALSE(fs::exists(seg_json));
    EXPECT_FALSE(fs::exists(out));
}

// The parser on its own: every field read back as written (floats exactly).
// fuzz_session_file's finding: a number past double (8888E8888) made nlohmann throw out_of_range,
// which the reader did not catch (the process aborted); now one error naming "json".
TEST(SessionFile, NumberPastDoubleIsAnErrorNotAnAbort) {
    std::string msg;
    try {
        lacuna::parse_session_file(R"({"lacuna_session": 1, "qva": [8888E8888]})", "x.json");
    } catch (const lacuna::Error& e) {
        msg = e.what();
    }
    EXPECT_NE(msg.find("x.json: json: not valid JSON"), std::string::npos) << msg;
}

TEST(SessionFile, RoundTripIsExact) {
    lacuna::SessionFile s;
    s.volume.path = "/data/head.nii.gz";
    s.volume.frame = 3;
    s.volume.range = lacuna::ValueRange{-1000.25f, 3071.f};
    s.tf = lacuna::preset("ct-bone");
    s.tf_back = lacuna::preset("ct-skin");
    s.frame.two_tfs = true;
    s.frame.features.clip_planes.push_back({{0.6f, 0.8f, 0.f}, 1.f / 3.f});
    s.frame.camera.orbit.azimuth_deg = 0.1f;
    s.frame.camera.orbit.has_target = true;
    s.frame.camera.orbit.target = {1e-7f, -3.4e38f, 12.5f};
    s.frame.sampling.early_termination = std::nullopt;
    s.frame.structure = lacuna::structure::KdTree{5, 2, 0.3f, 0.07f, 6};
    s.frame.features.gradient_opacity.enabled = true;
    s.frame.features.gradient_opacity.points = {
        {0.f, 0.f}, {2.5f, 0.f}, {2.5f, 1.f / 3.f}, {1e4f, 1.f}};
    const std::string text = lacuna::to_json(s);
    const lacuna::SessionFile t = lacuna::parse_session_file(text, "x.json");
    EXPECT_EQ(lacuna::to_json(t), text);
    EXPECT_EQ(t.frame.camera.orbit.target.y, -3.4e38f);
    EXPECT_EQ(t.frame.features.clip_planes.at(0).d, 1.f / 3.f);
    EXPECT_EQ(t.frame.structure, s.frame.structure);
    EXPECT_EQ(t.frame.features.gradient_opacity.points, s.frame.features.gradient_opacity.points);
    // Without points the gradient opacity is written as it always was: no "points" key.
    lacuna::SessionFile ramp = s;
    ramp.frame.features.gradient_opacity.points.clear();
    EXPECT_EQ(lacuna::to_json(ramp).find("points"), std::string::npos);
    EXPECT_FALSE(t.frame.sampling.early_termination.has_value());
    EXPECT_EQ(t.tf, s.tf);
    EXPECT_EQ(*t.tf_back, *s.tf_back);
    EXPECT_EQ(t.volume.range->min, s.volume.range->min);
    EXPECT_EQ(t.volume.range->max, s.volume.range->max);
}

}  // namespace
