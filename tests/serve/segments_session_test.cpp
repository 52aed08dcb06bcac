// The segments toggle in session files (issue 18): a view with segments on and labels hidden is
// saved by the server with the label volume's path and the frame's label table, and `lacuna
// render --session` of that file writes the server's screenshot of the view byte for byte.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "lacuna/io.h"
#include "serve/server_test_util.h"
#include "session/session_file.h"

namespace lacuna::serve::test {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
    static fs::path dir = [] {
        fs::path d =
            fs::temp_directory_path() / ("lacuna-segsession-" + std::to_string(::getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}
std::string read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(SegmentsSession, TheSavedSessionRendersTheScreenshotWithSegmentsAndHiddenLabels) {
    SyntheticOptions so;
    so.dims = {30, 27, 24};
    const Volume shells = generate(SyntheticKind::SphereShells, so);
    // Labels 1..3 by value band of the shells (same grid), 0 elsewhere.
    Volume labels(shells.dims(), VoxelType::UInt8);
    const ValueRange r = shells.data_range();
    for (int k = 0; k < so.dims.z; ++k)
        for (int j = 0; j < so.dims.y; ++j)
            for (int i = 0; i < so.dims.x; ++i) {
                const float u = (shells.value(i, j, k) - r.min) / (r.max - r.min);
                labels.set_value(i, j, k, u > 0.75f ? 3.f : u > 0.5f ? 2.f : u > 0.25f ? 1.f : 0.f);
            }
    labels.compute_range();
    const fs::path volume_path = temp_dir() / "shells.nrrd",
                   labels_path = temp_dir() / "labels.nrrd";
    write_volume(volume_path.string(), shells);
    write_volume(labels_path.string(), labels);

    FrameRenderer renderer(read_volume(volume_path.string()));
    renderer.set_labels(read_volume(labels_path.string()));
    ServerOptions o;
    o.port = 0;
    SessionVolume sv;
    sv.path = volume_path.string();
    o.session_volume = sv;
    o.labels_path = labels_path.string();
    Server server(renderer, o);
    const uint16_t port = server.start();
    std::thread t([&] { server.run(); });

    Client c(port);
    (void)c.read_text();
    json view = render_request(5, json::parse(to_json(preset("mr-default"))));
    view.erase("preview");
    view["type"] = "session";
    view["segments"] = true;
    view["hide"] = "2";
    view["width"] = 61;
    view["height"] = 47;
    c.send(view.dump());
    const json answer = c.read_text();
    ASSERT_EQ(answer["type"], "session") << answer.dump();
    const std::string text = answer["text"].get<std::string>();
    const SessionFile f = parse_session_file(text, "s.json");
    EXPECT_EQ(f.frame.renderer, Renderer::Segments);
    ASSERT_TRUE(f.labels);
    EXPECT_EQ(*f.labels, labels_path.string());
    ASSERT_TRUE(f.frame.segments.labels);
    ASSERT_EQ(f.frame.segments.labels->size(), 4);
    EXPECT_TRUE(f.frame.segments.labels->styles[1].visible);
    EXPECT_FALSE(f.frame.segments.labels->styles[2].visible);  // hidden by "hide"
    const fs::path session_file = temp_dir() / "segments-session.json";
    std::ofstream(session_file, std::ios::binary) << text;

    view["type"] = "screenshot";
    view["id"] = 6;
    c.send(view.dump());
    bool binary = false;
    const WireFrame shot = split_frame(c.read(binary));
    ASSERT_TRUE(binary);
    ASSERT_EQ(shot.header["type"], "screenshot");
    // With segments off the picture differs (the toggle is what the file holds).
    view["segments"] = false;
    view["id"] = 7;
    c.send(view.dump());
    const WireFrame plain = split_frame(c.read(binary));
    EXPECT_NE(plain.jpeg, shot.jpeg);

    const fs::path out = temp_dir() / "from-session.png";
    const std::string cmd = std::string(LACUNA_CLI_PATH) + " render --session " +
                            session_file.string() + " --out " + out.string() + " >/dev/null";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
    EXPECT_EQ(read_all(out), shot.jpeg)
        << "the CLI's PNG of the segments session is the screenshot";
    server.stop();
    t.join();
}

// The parser alone: a segments frame and its label path read back as written; what does not
// belong together is one error naming the field.
TEST(SegmentsSession, TheFileRoundTripsAndNamesWhatIsMissing) {
    SessionFile s;
    s.volume.path = "v.nrrd";
    s.tf = preset("mr-default");
    s.frame.renderer = Renderer::Segments;
    s.frame.structure = structure::LabelOctree{};
    s.frame.segments.mode = SegmentMode::Masked;
    s.frame.segments.tint = 0.3f;
    LabelTable t;
    t.styles = {{"background", 0.f, 0.f, 0.f, 1.f, false},
                {"a", 0.1f, 0.7f, 1.f / 3.f, 0.5f, true},
                {"b \"quoted\"", 1.f, 0.f, 0.2f, 2.f, false}};
    s.frame.segments.labels = t;
    s.labels = "labels/seg.nii.gz";
    const std::string text = to_json(s, "s.json");
    const SessionFile back = parse_session_file(text, "s.json");
    EXPECT_EQ(to_json(back, "s.json"), text);
    ASSERT_TRUE(back.frame.segments.labels);
    for (int l = 0; l < 3; ++l) {
        const LabelStyle &a = t.styles[size_t(l)],
                         &b = back.frame.segments.labels->styles[size_t(l)];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.r, b.r);
        EXPECT_EQ(a.g, b.g);
        EXPECT_EQ(a.b, b.b);
        EXPECT_EQ(a.opacity, b.opacity);
        EXPECT_EQ(a.visible, b.visible);
    }
    EXPECT_EQ(back.frame.segments.tint, 0.3f);
    EXPECT_EQ(back.labels, s.labels);

    auto error_of = [](const std::function<void()>& f) {
        try {
            f();
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    SessionFile no_labels = s;
    no_labels.labels.reset();
    EXPECT_NE(error_of([&] { to_json(no_labels, "s.json"); }).find("s.json: labels: missing"),
              std::string::npos);
    json j = json::parse(text);
    j.erase("labels");
    EXPECT_NE(
        error_of([&] { parse_session_file(j.dump(), "s.json"); }).find("s.json: labels: missing"),
        std::string::npos);
    j = json::parse(text);
    j["frame"]["renderer"] = "raymarcher";
    j["frame"]["structure"] = {{"name", "grid"}};
    EXPECT_NE(
        error_of([&] { parse_session_file(j.dump(), "s.json"); }).find("frame.segments: given"),
        std::string::npos);
    j["frame"].erase("segments");
    EXPECT_NE(error_of([&] { parse_session_file(j.dump(), "s.json"); }).find("labels: given"),
              std::string::npos);
    j = json::parse(text);
    j["frame"]["segments"]["table"][1]["opacity"] = -1;
    EXPECT_NE(error_of([&] {
                  parse_session_file(j.dump(), "s.json");
              }).find("frame.segments.table[1].opacity: expected a number >= 0"),
              std::string::npos);
    // Labels mode needs no label volume (the volume is the label map).
    SessionFile labels_mode = s;
    labels_mode.frame.segments.mode = SegmentMode::Labels;
    labels_mode.labels.reset();
    EXPECT_EQ(parse_session_file(to_json(labels_mode, "s.json"), "s.json").frame.segments.mode,
              SegmentMode::Labels);
}

}  // namespace
}  // namespace lacuna::serve::test
