// Saving work in the viewer (issue 18 item 2): the screenshot, session, tf_export and tf_import
// messages. Parsing rejects what it must with one line naming the field; the Slicer .vp.json
// writer reads back through the library's Slicer reader to the same TF points; over a real
// WebSocket a screenshot is the PNG `lacuna render --session` writes for the session the server
// saves of the same view, byte for byte; and no bad message closes the connection.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "lacuna/error.h"
#include "lacuna/image.h"
#include "lacuna/io.h"
#include "serve/protocol.h"
#include "serve/server_test_util.h"
#include "serve/tf_files.h"
#include "transfer/slicer_presets.h"

using namespace lacuna::serve::test;
namespace fs = std::filesystem;

namespace {

const std::string kData = std::string(LACUNA_SOURCE_DIR) + "/tests/data/";

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const lacuna::Error& e) {
        return e.what();
    }
    return "no error";
}

fs::path temp_dir() {
    static fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("lacuna-saving-" + std::to_string(::getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

std::string read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}
void write_all(const fs::path& p, const std::string& s) {
    std::ofstream out(p, std::ios::binary);
    out << s;
}

json view_json(const char* type, uint64_t id) {
    json j = render_request(id, json::parse(to_json(preset("mr-default"))));
    j["type"] = type;
    j.erase("preview");
    return j;
}

// A value-domain TF that uses every part of the format the Slicer writer handles.
TransferFunction value_tf() {
    TransferFunction tf;
    tf.name = "bone-ish";
    tf.domain = TfDomain::Value;
    tf.color = {{-1000, 0.1f, 0.2f, 0.3f}, {150.5, 0.9f, 0.6f, 0.25f}, {2000, 1, 1, 0.95f}};
    tf.opacity = {{-1000, 0}, {120, 0}, {400, 0.55f}, {2000, 0.8f}};
    tf.range = ValueRange{-1024, 3071};
    tf.rendering.shading = TfShading{0.15f, 0.8f, 0.3f, 20.f};
    tf.rendering.gradient_opacity = {{0, 0.f}, {45.5, 1.f}, {900, 1.f}};
    return tf;
}

TransferFunction read_back(const std::string& vp_json) {
    const std::vector<SlicerVolumeProperty> all = parse_slicer_vp_json(vp_json, "export.vp.json");
    EXPECT_EQ(all.size(), 1u);
    return to_transfer_function(all.at(0));
}

}  // namespace

// ---- parsing ----------------------------------------------------------------------------------

TEST(SavingProtocol, ScreenshotAndSessionCarryTheRenderViewState) {
    for (const char* type : {"screenshot", "session"}) {
        const json j = view_json(type, 9);
        const MessageKind kind =
            std::string(type) == "screenshot" ? MessageKind::Screenshot : MessageKind::Session;
        EXPECT_EQ(message_kind(j.dump()), kind);
        const ViewRequest r = parse_view_request(j.dump(), kind);
        json as_render = j;
        as_render["type"] = "render";
        as_render["preview"] = false;
        const ViewRequest want = parse_request(as_render.dump());
        EXPECT_EQ(r.id, 9u);
        EXPECT_EQ(r.width, want.width);
        EXPECT_EQ(r.height, want.height);
        EXPECT_FALSE(r.preview);
        EXPECT_EQ(r.camera, want.camera);
        EXPECT_EQ(r.accel, want.accel);
        EXPECT_EQ(r.tf, want.tf);
    }
    EXPECT_EQ(message_kind(R"({"type":"tf_export"})"), MessageKind::TfExport);
    EXPECT_EQ(message_kind(R"({"type":"tf_import"})"), MessageKind::TfImport);
}

TEST(SavingProtocol, ErrorsNameTheField) {
    struct Case {
        const char* type;
        const char* field;
        json value;  // null: remove the field
    };
    const Case cases[] = {
        {"screenshot", "preview", true},  // a screenshot is never a preview
        {"screenshot", "width", 0},
        {"screenshot", "width", 5000},
        {"screenshot", "height", nullptr},
        {"screenshot", "tf", "mr-default"},
        {"screenshot", "camera", nullptr},
        {"screenshot", "accel", "octree"},
        {"screenshot", "id", -3},
        {"screenshot", "path", "/tmp/x.png"},
        {"session", "step", 0},
        {"session", "renderer", "raycast"},
        {"session", "volume", "/etc/passwd"},
    };
    for (const Case& c : cases) {
        json j = view_json(c.type, 1);
        if (c.value.is_null())
            j.erase(c.field);
        else
            j[c.field] = c.value;
        const MessageKind kind = message_kind(j.dump());
        const std::string e = error_of([&] { parse_view_request(j.dump(), kind); });
        EXPECT_NE(e.find(std::string(c.field) + ":"), std::string::npos)
            << c.type << " " << c.field << " = " << c.value << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    const json tf = json::parse(to_json(preset("mr-default")));
    const std::pair<json, const char*> files[] = {
        {{{"type", "tf_export"}, {"id", 1}, {"format", "vtk"}, {"tf", tf}}, "format:"},
        {{{"type", "tf_export"}, {"id", 1}, {"tf", tf}}, "format: missing"},
        {{{"type", "tf_export"}, {"id", 1}, {"format", "slicer"}}, "tf: missing"},
        {{{"type", "tf_export"}, {"id", 1}, {"format", "slicer"}, {"tf", {{"color", 1}}}}, "tf:"},
        {{{"type", "tf_import"}, {"id", 1}, {"name", "a.json"}}, "text: missing"},
        {{{"type", "tf_import"}, {"id", 1}, {"name", 3}, {"text", "{}"}}, "name:"},
        {{{"type", "tf_import"}, {"id", 1}, {"name", std::string(300, 'a')}, {"text", "{}"}},
         "name:"},
        {{{"type", "tf_import"}, {"id", 1}, {"name", "a\nb"}, {"text", "{}"}}, "name:"},
        {{{"type", "tf_import"}, {"id", 1}, {"name", "a"}, {"text", "{}"}, {"path", "/"}}, "path:"},
        {{{"type", "tf_import"},
          {"id", 1},
          {"name", "a.json"},
          {"text", std::string(40, '[') + std::string(40, ']')}},
         "nesting:"},
    };
    for (const auto& file : files) {  // (not a structured binding: clang's C++20 lambdas)
        const json& j = file.first;
        const std::string e = error_of([&] {
            if (j["type"] == "tf_export")
                parse_tf_export_request(j.dump());
            else
                parse_tf_import_request(j.dump());
        });
        EXPECT_NE(e.find(file.second), std::string::npos) << j.dump() << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    // An unknown type names every type the server answers.
    const std::string t = error_of([] { message_kind(R"({"type":"snapshot"})"); });
    for (const std::string& name : message_names()) EXPECT_NE(t.find(name), std::string::npos) << t;
}

// ---- the Slicer writer and the upload reader ----------------------------------------------------

TEST(TfFiles, SlicerExportReadsBackToTheSameTf) {
    // Value domain: the exact TF, range, shading terms and gradient opacity.
    const TransferFunction tf = value_tf();
    const TransferFunction back = read_back(to_slicer_vp_json(tf, {0, 255}, 0.8));
    EXPECT_EQ(back, tf);
    // Through the CLI's own path too (a file read by --tf FILE.vp.json's loader).
    const fs::path file = temp_dir() / "bone.vp.json";
    write_all(file, to_slicer_vp_json(tf, {0, 255}, 0.8));
    EXPECT_EQ(resolve_transfer_function(file.string()), tf);
    // The unit distance is the smallest spacing (lacuna's opacity is per smallest voxel).
    const json doc = json::parse(to_slicer_vp_json(tf, {0, 255}, 0.8));
    EXPECT_EQ(doc["volumeProperties"][0]["components"][0]["scalarOpacityUnitDistance"], 0.8);
}

TEST(TfFiles, SlicerExportOfANormalizedTfIsItsValueDomainTf) {
    // Every built-in preset over a volume's range: x becomes (1 - x) lo + x hi, opacity and
    // colours unchanged; a step's second point moves to the next double above it.
    const ValueRange vis{-200.f, 1800.5f};
    for (const std::string& name : preset_names()) {
        const TransferFunction tf = preset(name);
        const TransferFunction back = read_back(to_slicer_vp_json(tf, vis, 1.0));
        const ValueRange r = tf.range.value_or(vis);
        auto value_x = [&](double x) {
            return tf.domain == TfDomain::Value ? x : (1.0 - x) * double(r.min) + x * double(r.max);
        };
        EXPECT_EQ(back.domain, TfDomain::Value) << name;
        EXPECT_EQ(back.range.has_value(), tf.range.has_value()) << name;
        if (back.range && tf.range) {
            EXPECT_EQ(back.range->min, tf.range->min) << name;
            EXPECT_EQ(back.range->max, tf.range->max) << name;
        }
        EXPECT_EQ(back.name, tf.name) << name;
        EXPECT_EQ(back.rendering.shading, tf.rendering.shading) << name;
        EXPECT_EQ(back.rendering.gradient_opacity, tf.rendering.gradient_opacity) << name;
        ASSERT_EQ(back.opacity.size(), tf.opacity.size()) << name;
        ASSERT_EQ(back.color.size(), tf.color.size()) << name;
        for (size_t i = 0; i < tf.opacity.size(); ++i) {
            double want = value_x(tf.opacity[i].x);
            if (i > 0 && tf.opacity[i].x == tf.opacity[i - 1].x)
                want =
                    std::nextafter(back.opacity[i - 1].x, std::numeric_limits<double>::infinity());
            EXPECT_EQ(back.opacity[i].x, want) << name << " opacity " << i;
            EXPECT_EQ(back.opacity[i].a, tf.opacity[i].a) << name << " opacity " << i;
        }
        for (size_t i = 0; i < tf.color.size(); ++i) {
            double want = value_x(tf.color[i].x);
            if (i > 0 && tf.color[i].x == tf.color[i - 1].x)
                want = std::nextafter(back.color[i - 1].x, std::numeric_limits<double>::infinity());
            EXPECT_EQ(back.color[i].x, want) << name << " colour " << i;
            EXPECT_EQ(back.color[i].r, tf.color[i].r) << name;
            EXPECT_EQ(back.color[i].g, tf.color[i].g) << name;
            EXPECT_EQ(back.color[i].b, tf.color[i].b) << name;
        }
        // The LUT over the volume's range is the TF's own, up to the affine map's rounding.
        const TransferLut a = discretise(tf, vis, 256), b = discretise(back, vis, 256);
        for (size_t e = 0; e < a.entries.size(); ++e) {
            EXPECT_NEAR(a.entries[e].a, b.entries[e].a, 1e-5) << name << " entry " << e;
            EXPECT_NEAR(a.entries[e].r, b.entries[e].r, 1e-5) << name << " entry " << e;
        }
    }
}

TEST(TfFiles, AStepIsKeptApartAndNoGradientOpacityIsDisabled) {
    TransferFunction tf;
    tf.name = "step";
    tf.domain = TfDomain::Normalized;
    tf.color = {{0, 1, 1, 1}};
    tf.opacity = {{0, 0}, {0.5, 0}, {0.5, 0.7f}, {1, 0.7f}};
    const std::string text = to_slicer_vp_json(tf, {0, 100}, 1.0);
    const json doc = json::parse(text);
    const json& c = doc["volumeProperties"][0]["components"][0];
    EXPECT_EQ(c["disableGradientOpacity"], true);
    EXPECT_EQ(c["shade"], false);
    EXPECT_FALSE(doc["volumeProperties"][0].contains("effectiveRange"));
    const TransferFunction back = read_back(text);
    ASSERT_EQ(back.opacity.size(), 4u);  // VTK would have merged an exact step into one point
    EXPECT_EQ(back.opacity[1].x, 50.0);
    EXPECT_EQ(back.opacity[2].x, std::nextafter(50.0, 100.0));
    EXPECT_EQ(back.opacity[2].a, 0.7f);
    EXPECT_TRUE(back.rendering.gradient_opacity.empty());
    EXPECT_FALSE(back.rendering.shading);
}

TEST(TfFiles, UploadsAreReadByTheLibrarysReaders) {
    // lacuna JSON, Slicer .vp.json (by name, or by its content under another name), Slicer .vp.
    const TransferFunction bone = preset("ct-bone");
    EXPECT_EQ(read_tf_file("bone.json", to_json(bone)), bone);
    const std::string vp_json = read_all(kData + "lacuna-ct.vp.json");
    const TransferFunction from_slicer = resolve_transfer_function(kData + "lacuna-ct.vp.json");
    EXPECT_EQ(read_tf_file("lacuna-ct.vp.json", vp_json), from_slicer);
    EXPECT_EQ(read_tf_file("renamed.json", vp_json), from_slicer);
    EXPECT_EQ(read_tf_file("lacuna-mr.vp", read_all(kData + "lacuna-mr.vp")),
              resolve_transfer_function(kData + "lacuna-mr.vp"));
    // Errors: one line naming the file and the field.
    const std::pair<std::pair<const char*, std::string>, const char*> bad[] = {
        {{"a.json", "{\"color\": 3}"}, "a.json: "},
        {{"a.json", "not json"}, "a.json: "},
        {{"b.vp.json", "{\"volumeProperties\": []}"}, "b.vp.json: volumeProperties"},
        {{"c.vp", "1\n2\n"}, "c.vp: lines"},
    };
    for (const auto& b : bad) {
        const auto& file = b.first;
        const std::string e = error_of([&] { read_tf_file(file.first, file.second); });
        EXPECT_NE(e.find(b.second), std::string::npos) << file.first << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    // Two properties: which one is not guessed.
    json two = json::parse(vp_json);
    two["volumeProperties"].push_back(two["volumeProperties"][0]);
    const std::string e = error_of([&] { read_tf_file("two.vp.json", two.dump()); });
    EXPECT_NE(e.find("expected one volume property"), std::string::npos) << e;
}

// ---- over a real WebSocket
// ------------------------------------------------------------------------

namespace {

// A server over a volume file (so it can write session files), on its own thread.
class FileServer {
  public:
    FileServer() {
        SyntheticOptions so;
        so.dims = {30, 27, 24};
        volume_path = temp_dir() / "shells.nrrd";
        write_volume(volume_path.string(), generate(SyntheticKind::SphereShells, so));
        m_renderer = std::make_unique<FrameRenderer>(read_volume(volume_path.string()));
        options.port = 0;
        SessionVolume sv;
        sv.path = volume_path.string();
        options.session_volume = sv;
        m_server = std::make_unique<Server>(*m_renderer, options);
        port = m_server->start();
        m_thread = std::thread([this] { m_server->run(); });
    }
    ~FileServer() {
        m_server->stop();
        m_thread.join();
    }
    fs::path volume_path;
    ServerOptions options;
    uint16_t port = 0;

  private:
    std::unique_ptr<FrameRenderer> m_renderer;
    std::unique_ptr<Server> m_server;
    std::thread m_thread;
};

}  // namespace

TEST(SavingServer, TheScreenshotIsTheCliRenderOfTheSavedSessionByteForByte) {
    FileServer server;
    Client c(server.port);
    const json hello = c.read_text();
    EXPECT_EQ(hello["session"], true);
    // A view with every toggle the session holds: shading, the clip toggle and a world plane,
    // a pan, an edited TF, no early termination, a size unlike the render's.
    json view = view_json("session", 21);
    view["width"] = 77;
    view["height"] = 51;
    view["camera"] = {
        {"azimuth", 123.25}, {"elevation", -31.5}, {"zoom", 1.7}, {"pan", {0.05, -0.1}}};
    view["ert"] = false;
    view["step"] = 0.75;
    view["shading"] = true;
    view["clip"] = true;
    view["clip_planes"] = {{0, 0.6, 0.8, -3.5}};
    view["tf"]["opacity"][1] = {0.3, 0.42};
    view["tf"]["name"] = "edited";
    c.send(view.dump());
    const json session = c.read_text();
    ASSERT_EQ(session["type"], "session") << session.dump();
    EXPECT_EQ(session["id"], 21);
    const fs::path session_file = temp_dir() / "viewer-session.json";
    write_all(session_file, session["text"].get<std::string>());

    view["type"] = "screenshot";
    view["id"] = 22;
    c.send(view.dump());
    bool binary = false;
    const WireFrame shot = split_frame(c.read(binary));
    ASSERT_TRUE(binary);
    EXPECT_EQ(shot.header["type"], "screenshot");
    EXPECT_EQ(shot.header["id"], 22);
    EXPECT_EQ(shot.header["width"], 77);
    EXPECT_EQ(shot.header["height"], 51);
    ASSERT_GT(shot.jpeg.size(), 8u);
    EXPECT_EQ(shot.jpeg.substr(1, 3), "PNG");

    const fs::path out = temp_dir() / "from-session.png";
    const std::string cmd = std::string(LACUNA_CLI_PATH) + " render --session " +
                            session_file.string() + " --out " + out.string() + " >/dev/null";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
    EXPECT_EQ(read_all(out), shot.jpeg) << "the CLI's PNG of the session is the screenshot";
    // And the screenshot is the view: not a blank or a preview.
    const fs::path shot_png = temp_dir() / "shot.png";
    write_all(shot_png, shot.jpeg);
    const Image img = read_png(shot_png.string());
    EXPECT_EQ(img.width, 77);
    EXPECT_EQ(img.height, 51);
    EXPECT_TRUE(
        std::any_of(img.rgba.begin(), img.rgba.end(), [](uint8_t b) { return b > 40 && b < 255; }));
}

TEST(SavingServer, AScreenshotIsNotDroppedForANewerRenderAndBadMessagesGetOneErrorEach) {
    FileServer server;
    Client c(server.port);
    c.read_text();  // hello
    // A screenshot and, right behind it, a render: both are answered.
    c.send(view_json("screenshot", 5).dump());
    c.send(render_request(6, json::parse(to_json(preset("mr-default")))).dump());
    bool got_shot = false, got_frame = false;
    for (int i = 0; i < 2; ++i) {
        bool binary = false;
        const WireFrame f = split_frame(c.read(binary));
        ASSERT_TRUE(binary);
        got_shot = got_shot || (f.header["type"] == "screenshot" && f.header["id"] == 5);
        got_frame = got_frame || (f.header["type"] == "frame" && f.header["id"] == 6);
    }
    EXPECT_TRUE(got_shot);
    EXPECT_TRUE(got_frame);
    // Bad messages of every new kind: one error each, naming the field, the socket stays open.
    json bad_shot = view_json("screenshot", 30);
    bad_shot["width"] = 0;
    json bad_session = view_json("session", 31);
    bad_session["preview"] = false;
    json segments_session = view_json("session", 32);
    segments_session["segments"] = true;  // without a label volume: ignored, as in render
    struct Bad {
        std::string text;
        const char* needle;
        int id;
    };
    const Bad bad[] = {
        {bad_shot.dump(), "width", 30},
        {bad_session.dump(), "preview: unknown key", 31},
        {R"({"type":"tf_export","id":33,"format":"vtk","tf":{}})", "format", 33},
        {R"({"type":"tf_import","id":34,"name":"x.json","text":"{\"opacity\":1}"})", "x.json", 34},
        {R"({"type":"tf_import","id":35,"name":"y.vp.json","text":"[]"})", "y.vp.json", 35},
        {R"({"type":"tf_import","id":36})", "name", 36},
    };
    for (const Bad& b : bad) {
        c.send(b.text);
        const json e = c.read_text();
        EXPECT_EQ(e["type"], "error") << b.text;
        EXPECT_NE(e["message"].get<std::string>().find(b.needle), std::string::npos) << e.dump();
        EXPECT_EQ(e["id"], b.id) << e.dump();
    }
    c.send(segments_session.dump());
    EXPECT_EQ(c.read_text()["type"], "session");
    // Still serving.
    c.send(render_request(40, json::parse(to_json(preset("mr-default")))).dump());
    bool binary = false;
    EXPECT_EQ(split_frame(c.read(binary)).header["id"], 40);
}

TEST(SavingServer, TfFilesRoundTripThroughTheServer) {
    FileServer server;
    Client c(server.port);
    c.read_text();
    const TransferFunction tf = value_tf();
    // lacuna JSON: what --tf reads, the TF exactly.
    c.send(json{
        {"type", "tf_export"}, {"id", 1}, {"format", "lacuna"}, {"tf", json::parse(to_json(tf))}}
               .dump());
    const json lacuna = c.read_text();
    ASSERT_EQ(lacuna["type"], "tf_export") << lacuna.dump();
    EXPECT_EQ(lacuna["format"], "lacuna");
    EXPECT_EQ(parse_transfer_function(lacuna["text"].get<std::string>(), "t.json"), tf);
    // Slicer: the writer over the server's volume, read back by the Slicer reader.
    c.send(json{
        {"type", "tf_export"}, {"id", 2}, {"format", "slicer"}, {"tf", json::parse(to_json(tf))}}
               .dump());
    const json slicer = c.read_text();
    ASSERT_EQ(slicer["type"], "tf_export") << slicer.dump();
    EXPECT_EQ(read_back(slicer["text"].get<std::string>()), tf);
    // Upload of both files: the TF again, as lacuna TF JSON for the editor.
    for (const auto& [name, text] : {std::pair<std::string, std::string>{"t.json", lacuna["text"]},
                                     {"t.vp.json", slicer["text"]}}) {
        c.send(json{{"type", "tf_import"}, {"id", 3}, {"name", name}, {"text", text}}.dump());
        const json up = c.read_text();
        ASSERT_EQ(up["type"], "tf_import") << up.dump();
        EXPECT_EQ(parse_transfer_function(up["tf"].dump(), name), tf) << name;
    }
}

TEST(SavingServer, ASessionNeedsTheVolumesFile) {
    Running server;  // a volume made in memory
    Client c(server.port);
    EXPECT_EQ(c.read_text()["session"], false);
    c.send(view_json("session", 4).dump());
    const json e = c.read_text();
    EXPECT_EQ(e["type"], "error");
    EXPECT_EQ(e["id"], 4);
    EXPECT_NE(e["message"].get<std::string>().find("session: volume"), std::string::npos)
        << e.dump();
    // A screenshot needs no file.
    c.send(view_json("screenshot", 5).dump());
    bool binary = false;
    EXPECT_EQ(split_frame(c.read(binary)).header["type"], "screenshot");
}

TEST(SavingServer, ASavedSessionOpensToTheSameViewAndForeignOnesNameWhatDiffers) {
    FileServer server;
    Client c(server.port);
    c.read_text();
    json view = view_json("session", 1);
    view["camera"] = {{"azimuth", -47.5}, {"elevation", 12.25}, {"zoom", 0.9}, {"pan", {0.2, 0.1}}};
    view["shading"] = true;
    view["clip"] = true;
    view["clip_planes"] = {{1, 0, 0, -2.5}};
    view["ert"] = false;
    c.send(view.dump());
    const std::string saved = c.read_text()["text"];
    // Open it: the view state the server answers saves to the same file.
    c.send(json{{"type", "session_import"}, {"id", 2}, {"name", "s.json"}, {"text", saved}}.dump());
    const json opened = c.read_text();
    ASSERT_EQ(opened["type"], "session_import") << opened.dump();
    const json& v = opened["view"];
    EXPECT_EQ(v["camera"]["azimuth"], -47.5);
    EXPECT_EQ(v["clip"], true);
    EXPECT_EQ(v["clip_planes"].size(), 1u);  // the toggle's plane is the toggle again
    json again = v;
    again["type"] = "session";
    again["id"] = 3;
    c.send(again.dump());
    EXPECT_EQ(c.read_text()["text"], saved);
    // A named view comes back by name (superior is 90 degrees: beyond free angles).
    json superior = view_json("session", 4);
    superior["camera"] = {{"view", "superior"}, {"zoom", 1}, {"pan", {0, 0}}};
    c.send(superior.dump());
    const std::string sup = c.read_text()["text"];
    c.send(json{{"type", "session_import"}, {"id", 5}, {"name", "sup.json"}, {"text", sup}}.dump());
    EXPECT_EQ(c.read_text()["view"]["camera"]["view"], "superior");

    // Sessions the viewer cannot reproduce: one error each, naming the field.
    json doc = json::parse(saved);
    auto refused = [&](const json& d, const std::string& needle) {
        c.send(json{{"type", "session_import"}, {"id", 9}, {"name", "x.json"}, {"text", d.dump()}}
                   .dump());
        const json e = c.read_text();
        EXPECT_EQ(e["type"], "error") << d.dump();
        EXPECT_EQ(e["id"], 9);
        EXPECT_NE(e["message"].get<std::string>().find(needle), std::string::npos) << e.dump();
    };
    json other = doc;
    other["volume"]["path"] = "/elsewhere/other.nrrd";
    refused(other, "x.json: volume.path");
    json pbr = doc;
    pbr["frame"]["features"]["shading"] = "pbr";
    refused(pbr, "x.json: frame.features.shading");
    json fov = doc;
    fov["frame"]["camera"]["fov_y_deg"] = 45.0;
    refused(fov, "x.json: frame.camera");
    json range = doc;
    range["volume"]["range"] = {0, 100};
    refused(range, "x.json: volume.range");
    refused(json::parse("{\"lacuna_session\": 1, \"frame\": 3}"), "x.json: ");
    // A relative path naming the server's file is its volume.
    json relative = doc;
    relative["volume"]["path"] = server.volume_path.filename().string();
    c.send(
        json{{"type", "session_import"}, {"id", 10}, {"name", "r.json"}, {"text", relative.dump()}}
            .dump());
    EXPECT_EQ(c.read_text()["type"], "session_import");
}
