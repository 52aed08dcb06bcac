// The viewer's slice and probe messages: parse errors name their field; over a real WebSocket a
// slice is the library's slice (lacuna/mpr.h) through the same JPEG encoder, byte for byte, its
// header maps pixels to the world, and a probe is lacuna::probe; bad messages never close the
// connection.
#include <gtest/gtest.h>

#include <cmath>

#include "lacuna/error.h"
#include "lacuna/mpr.h"
#include "render/orientation_test_util.h"
#include "serve/jpeg.h"
#include "serve/protocol.h"
#include "serve/server_test_util.h"

using namespace lacuna::serve::test;

namespace {

json slice_json(uint64_t id) {
    return json{{"type", "slice"},
                {"id", id},
                {"plane", "coronal"},
                {"point", {1.5, -2.0, 3.25}},
                {"window", 180},
                {"level", 90},
                {"interpolation", "trilinear"}};
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const lacuna::Error& e) {
        return e.what();
    }
    return "no error";
}

// The phantom of the orientation tests stored LPS (a reordered copy), with a label map of it.
Volume lps_phantom() {
    using namespace lacuna::test::orientation;
    return reorder(phantom(), {0, 1, 2}, {true, true, false});
}
Volume labels_of(const Volume& v) {
    Volume l(v.dims(), VoxelType::UInt8);
    l.spacing = v.spacing;
    l.origin = v.origin;
    std::copy(std::begin(v.direction), std::end(v.direction), std::begin(l.direction));
    for (int k = 0; k < v.dims().z; ++k)
        for (int j = 0; j < v.dims().y; ++j)
            for (int i = 0; i < v.dims().x; ++i) {
                const float x = v.value(i, j, k);
                l.set_value(i, j, k, x > 200 ? 3.f : x > 140 ? 2.f : x > 80 ? 1.f : 0.f);
            }
    l.compute_range();
    return l;
}

// A server over the LPS phantom and its labels, on its own thread.
class PhantomServer {
  public:
    PhantomServer() {
        m_renderer = std::make_unique<FrameRenderer>(lps_phantom());
        m_renderer->set_labels(labels_of(lps_phantom()));
        options.port = 0;
        m_server = std::make_unique<Server>(*m_renderer, options);
        port = m_server->start();
        m_thread = std::thread([this] { m_server->run(); });
    }
    ~PhantomServer() {
        m_server->stop();
        m_thread.join();
    }
    ServerOptions options;
    uint16_t port = 0;

  private:
    std::unique_ptr<FrameRenderer> m_renderer;
    std::unique_ptr<Server> m_server;
    std::thread m_thread;
};

}  // namespace

TEST(SliceProtocol, ParsesAValidSliceAndProbe) {
    json j = slice_json(7);
    j["overlay_opacity"] = 0.25;
    j["max_size"] = 300;
    const SliceRequest r = parse_slice_request(j.dump());
    EXPECT_EQ(r.id, 7u);
    EXPECT_EQ(r.plane, SlicePlane::Coronal);
    EXPECT_EQ(r.point, (Vec3d{1.5, -2.0, 3.25}));
    EXPECT_EQ(r.window, 180);
    EXPECT_EQ(r.level, 90);
    EXPECT_EQ(r.interpolation, Interpolation::Trilinear);
    EXPECT_FLOAT_EQ(r.overlay_opacity, 0.25f);
    EXPECT_EQ(r.max_size, 300);
    EXPECT_EQ(message_kind(j.dump()), MessageKind::Slice);
    const ProbeRequest p = parse_probe_request(R"({"type":"probe","id":3,"point":[1,2,3]})");
    EXPECT_EQ(p.id, 3u);
    EXPECT_EQ(p.point, (Vec3d{1, 2, 3}));
    EXPECT_EQ(message_kind(R"({"type":"probe"})"), MessageKind::Probe);
    EXPECT_EQ(message_kind(R"({"type":"render"})"), MessageKind::Render);
}

TEST(SliceProtocol, ErrorsNameTheField) {
    struct Case {
        const char* field;
        json value;  // null: remove the field
    };
    const Case cases[] = {
        {"plane", "oblique"},
        {"plane", 3},
        {"plane", nullptr},
        {"point", {1, 2}},
        {"point", {1, "a", 2}},
        {"point", nullptr},
        {"point", {1, 2, 1e300}},
        {"window", 0},
        {"window", -4},
        {"window", "wide"},
        {"window", nullptr},
        {"level", "x"},
        {"level", nullptr},
        {"interpolation", "cubic"},
        {"interpolation", nullptr},
        {"overlay_opacity", 1.5},
        {"overlay_opacity", -0.1},
        {"max_size", 0},
        {"max_size", 100000},
        {"max_size", 2.5},
        {"id", -1},
        {"id", nullptr},
        {"colour", 1},
    };
    for (const Case& c : cases) {
        json j = slice_json(1);
        if (c.value.is_null())
            j.erase(c.field);
        else
            j[c.field] = c.value;
        const std::string e = error_of([&] { parse_slice_request(j.dump()); });
        EXPECT_NE(e.find(c.field), std::string::npos) << c.field << " = " << c.value << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
    const std::string p1 = error_of([] { parse_probe_request(R"({"type":"probe","id":1})"); });
    EXPECT_NE(p1.find("point"), std::string::npos) << p1;
    const std::string p2 =
        error_of([] { parse_probe_request(R"({"type":"probe","id":1,"point":[0,0,0],"x":1})"); });
    EXPECT_NE(p2.find("x"), std::string::npos) << p2;
    const std::string t = error_of([] { message_kind(R"({"type":"slices"})"); });
    EXPECT_NE(t.find("type"), std::string::npos) << t;
    EXPECT_NE(t.find("slice"), std::string::npos) << t;
}

TEST(SliceServer, HelloListsTheNewMessages) {
    PhantomServer server;
    Client c(server.port);
    const json hello = c.read_text();
    EXPECT_EQ(hello["messages"],
              json::array({"render", "slice", "probe", "screenshot", "session", "tf_export",
                           "tf_import", "session_import", "volume_frame"}));
    EXPECT_EQ(hello["slice_views"]["planes"], json::array({"axial", "coronal", "sagittal"}));
    EXPECT_EQ(hello["slice_views"]["interpolations"], json::array({"trilinear", "nearest"}));
    // The world box the page centres its crosshair in: the phantom's, centred on 0 whatever
    // the voxel order (stored LPS here).
    const Box3f b = world_bounds(lps_phantom());
    for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(hello["volume"]["world_bounds"]["lo"][a].get<double>(), double(b.lo[a]));
        EXPECT_EQ(hello["volume"]["world_bounds"]["hi"][a].get<double>(), double(b.hi[a]));
        EXPECT_NEAR(double(b.lo[a] + b.hi[a]), 0.0, 1e-4);
    }
    EXPECT_EQ(hello["volume"]["orientation"], "LPS");
}

TEST(SliceServer, SliceOverTheWebSocketIsTheLibrarysSliceByteForByte) {
    PhantomServer server;
    Client c(server.port);
    c.read_text();  // hello
    const Volume v = lps_phantom();
    const Volume labels = labels_of(v);
    const LabelTable table = default_label_table(labels);
    uint64_t id = 10;
    for (const char* plane : {"axial", "coronal", "sagittal"})
        for (const char* interp : {"trilinear", "nearest"})
            for (double opacity : {0.0, 0.5}) {
                json j = slice_json(++id);
                j["plane"] = plane;
                j["interpolation"] = interp;
                if (opacity > 0) j["overlay_opacity"] = opacity;
                c.send(j.dump());
                bool binary = false;
                const WireFrame f = split_frame(c.read(binary));
                ASSERT_TRUE(binary);
                EXPECT_EQ(f.header["type"], "slice");
                EXPECT_EQ(f.header["id"], id);
                EXPECT_EQ(f.header["plane"], plane);
                // The library's call with the same settings, through the same encoder.
                SliceOptions o;
                o.interpolation = parse_interpolation(interp);
                o.max_size = server.options.limits.max_side;
                const Slice s = sample_slice(v, parse_slice_plane(plane), {1.5, -2.0, 3.25}, o);
                Image img = window_level(s, 180, 90);
                if (opacity > 0)
                    overlay_labels(img, sample_labels(labels, s.geometry), table, float(opacity));
                ASSERT_EQ(f.header["width"], s.geometry.width);
                ASSERT_EQ(f.header["height"], s.geometry.height);
                EXPECT_EQ(f.jpeg, encode_jpeg(img, server.options.jpeg_quality))
                    << plane << " " << interp << " " << opacity;
                // The header's pixel -> world map is the slice's.
                const Vec3d o0{f.header["origin"][0], f.header["origin"][1], f.header["origin"][2]};
                const Vec3d u{f.header["u"][0], f.header["u"][1], f.header["u"][2]};
                const Vec3d vv{f.header["v"][0], f.header["v"][1], f.header["v"][2]};
                const Vec3d corner =
                    o0 + u * double(s.geometry.width - 1) + vv * double(s.geometry.height - 1);
                const Vec3d want =
                    s.geometry.pixel_world(s.geometry.width - 1, s.geometry.height - 1);
                for (int a = 0; a < 3; ++a) EXPECT_NEAR(corner[a], want[a], 1e-9);
            }
}

TEST(SliceServer, ProbeOverTheWebSocketIsTheLibrarysProbe) {
    PhantomServer server;
    Client c(server.port);
    c.read_text();
    const Volume v = lps_phantom();
    const Volume labels = labels_of(v);
    const LabelTable table = default_label_table(labels);
    const Vec3d points[] = {{11, -2, 0}, {0.3, 17.2, -4.1}, {-3, -4, 16}, {500, 0, 0}};
    uint64_t id = 0;
    for (Vec3d p : points) {
        c.send(json{{"type", "probe"}, {"id", ++id}, {"point", {p.x, p.y, p.z}}}.dump());
        const json r = c.read_text();
        ASSERT_EQ(r["type"], "probe") << r.dump();
        EXPECT_EQ(r["id"], id);
        const ProbeResult want = probe(v, p, Interpolation::Trilinear, &labels, &table);
        EXPECT_EQ(r["inside"], want.inside);
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(r["index"][a].get<double>(), want.index[a], 1e-9);
        if (want.inside) {
            EXPECT_EQ(r["voxel"], json::array({want.voxel.x, want.voxel.y, want.voxel.z}));
            EXPECT_FLOAT_EQ(r["value"].get<float>(), want.value);
            EXPECT_FLOAT_EQ(r["voxel_value"].get<float>(), want.voxel_value);
            ASSERT_TRUE(want.label.has_value());
            EXPECT_EQ(r["label"], *want.label);
            EXPECT_EQ(r["label_name"], want.label_name);
        } else {
            EXPECT_TRUE(r["value"].is_null());
            EXPECT_TRUE(r["voxel"].is_null());
        }
    }
    EXPECT_TRUE(probe(v, points[0]).inside);
}

TEST(SliceServer, MalformedSlicesAreErrorsAndTheConnectionStays) {
    Running server;  // the sphere, no labels
    Client c(server.port);
    c.read_text();
    json bad = slice_json(5);
    bad["plane"] = "oblique";
    c.send(bad.dump());
    json err = c.read_text();
    EXPECT_EQ(err["type"], "error");
    EXPECT_EQ(err["id"], 5);
    EXPECT_NE(err["message"].get<std::string>().find("plane"), std::string::npos) << err.dump();
    // An overlay without a label volume names the field.
    json overlay = slice_json(6);
    overlay["overlay_opacity"] = 0.5;
    c.send(overlay.dump());
    err = c.read_text();
    EXPECT_EQ(err["id"], 6);
    EXPECT_NE(err["message"].get<std::string>().find("overlay_opacity"), std::string::npos)
        << err.dump();
    c.send(R"({"type":"probe","id":8,"point":[1,2]})");
    err = c.read_text();
    EXPECT_EQ(err["id"], 8);
    EXPECT_NE(err["message"].get<std::string>().find("point"), std::string::npos) << err.dump();
    // Still served.
    c.send(slice_json(9).dump());
    bool binary = false;
    const WireFrame f = split_frame(c.read(binary));
    EXPECT_TRUE(binary);
    EXPECT_EQ(f.header["id"], 9);
    c.send(R"({"type":"probe","id":10,"point":[9,9,9]})");
    const json p = c.read_text();
    EXPECT_EQ(p["type"], "probe");
    EXPECT_EQ(p["label"], nullptr);
}
