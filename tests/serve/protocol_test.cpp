// The viewer protocol: a well-formed request parses into typed values; every malformed,
// oversized or out-of-range message is rejected with a lacuna::Error naming the field.
#include "serve/protocol.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "lacuna/error.h"
#include "lacuna/synthetic.h"
#include "lacuna/views.h"

using nlohmann::json;
using namespace lacuna;
using namespace lacuna::serve;

namespace {

json good_request() {
    return json::parse(R"({
        "type": "render", "id": 7, "width": 320, "height": 240, "preview": true,
        "camera": {"azimuth": 40, "elevation": -10.5, "zoom": 1.5, "pan": [0.1, -0.2]},
        "renderer": "march", "accel": "bitfield", "ert": false, "step": 0.75,
        "tf": {"name": "t", "domain": "normalized",
               "color": [[0, 1, 0, 0], [1, 0, 0, 1]],
               "opacity": [[0, 0], [0.5, 0.25], [1, 1]]}})");
}

// The error message of parse_request, or "" if it parsed.
std::string rejection(const std::string& text) {
    try {
        parse_request(text);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

void expect_rejected(const json& j, const std::string& needle) {
    const std::string msg = rejection(j.dump());
    EXPECT_NE(msg.find(needle), std::string::npos) << "message: '" << msg << "' for " << j.dump();
}

}  // namespace

TEST(Protocol, ParsesAWellFormedRequest) {
    const ViewRequest r = parse_request(good_request().dump());
    EXPECT_EQ(r.id, 7u);
    EXPECT_EQ(r.width, 320);
    EXPECT_EQ(r.height, 240);
    EXPECT_TRUE(r.preview);
    EXPECT_EQ(r.camera.azimuth, 40.f);
    EXPECT_EQ(r.camera.elevation, -10.5f);
    EXPECT_EQ(r.camera.zoom, 1.5f);
    EXPECT_EQ(r.camera.pan_x, 0.1f);
    EXPECT_EQ(r.camera.pan_y, -0.2f);
    EXPECT_EQ(r.renderer, RendererKind::March);
    EXPECT_EQ(r.accel, AccelKind::Bitfield);
    EXPECT_FALSE(r.ert);
    EXPECT_EQ(r.step, 0.75f);
    ASSERT_EQ(r.tf.opacity.size(), 3u);
    EXPECT_EQ(r.tf.opacity[1].x, 0.5);
    EXPECT_EQ(r.tf.opacity[1].a, 0.25f);
    EXPECT_EQ(r.tf.color[1].b, 1.f);
    EXPECT_FALSE(r.shading) << "optional toggles are off when absent";
    EXPECT_FALSE(r.clip);
}

TEST(Protocol, TheSliceRendererTakesNoneOrKdtreeAndNoFeatures) {
    json j = good_request();
    j["renderer"] = "slice";
    j["accel"] = "kdtree";
    EXPECT_EQ(parse_request(j.dump()).renderer, RendererKind::Slice);
    j["accel"] = "bitfield";
    expect_rejected(j, "accel");
    j["accel"] = "none";
    j["shading"] = true;
    expect_rejected(j, "renderer");
}

TEST(Protocol, ParsesTheSegmentsToggleAndItsHiddenLabels) {
    json j = good_request();
    j["segments"] = true;
    j["hide"] = "1-28,40";
    const ViewRequest r = parse_request(j.dump());
    EXPECT_TRUE(r.segments);
    EXPECT_EQ(r.hide, "1-28,40");
    j["hide"] = "1-x";
    expect_rejected(j, "hide");
    j["hide"] = 3;
    expect_rejected(j, "hide");
    j = good_request();
    j["segments"] = true;
    j["shading"] = true;
    expect_rejected(j, "segments");
}

TEST(Protocol, ParsesTheOptionalShadingAndClipToggles) {
    json j = good_request();
    j["shading"] = true;
    j["clip"] = true;
    const ViewRequest r = parse_request(j.dump());
    EXPECT_TRUE(r.shading);
    EXPECT_TRUE(r.clip);
    j["shading"] = "phong";
    expect_rejected(j, "shading");
    j = good_request();
    j["clip"] = 1;
    expect_rejected(j, "clip");
}

// A named view is the CLI's --view: the same angles from one table (superior and inferior are
// exactly +-90, beyond the +-89.9 free angles may reach); angles beside it are refused.
TEST(Protocol, NamedViewsAreTheCliViews) {
    for (const char* name : {"anterior", "posterior", "left", "right", "superior", "inferior"}) {
        json j = good_request();
        j["camera"] = {{"view", name}, {"zoom", 2}, {"pan", {0, 0}}};
        const ViewRequest r = parse_request(j.dump());
        float az = -1, el = -1;
        ASSERT_TRUE(named_view(name, az, el));
        EXPECT_EQ(r.camera.azimuth, az) << name;
        EXPECT_EQ(r.camera.elevation, el) << name;
        EXPECT_EQ(r.camera.zoom, 2.f);
    }
    json j = good_request();
    j["camera"]["view"] = "superior";
    j["camera"]["elevation"] = 90;
    expect_rejected(j, "camera.view: sets azimuth and elevation");
    j["camera"].erase("azimuth");
    j["camera"].erase("elevation");
    EXPECT_EQ(parse_request(j.dump()).camera.elevation, 90.f);
    j["camera"]["view"] = "front";
    expect_rejected(j, "camera.view: unknown 'front'; expected anterior, posterior");
    j["camera"]["view"] = 3;
    expect_rejected(j, "camera.view: expected a string");
}

// "clip_planes" are --clip planes, world RAS mm, each [nx, ny, nz, d]; nothing else parses.
TEST(Protocol, ClipPlanesAreWorldPlanesLikeTheCliFlag) {
    json j = good_request();
    j["clip_planes"] = {{-1, 0, 0, 26}, {0, 0.5, 0.5, -3.25}};
    const ViewRequest r = parse_request(j.dump());
    ASSERT_EQ(r.clip_planes.size(), 2u);
    EXPECT_EQ(r.clip_planes[0].normal, (Vec3f{-1, 0, 0}));
    EXPECT_EQ(r.clip_planes[0].d, 26.f);
    EXPECT_EQ(r.clip_planes[1].normal, (Vec3f{0, 0.5f, 0.5f}));
    EXPECT_EQ(r.clip_planes[1].d, -3.25f);
    EXPECT_TRUE(parse_request(good_request().dump()).clip_planes.empty());
    for (const json& bad :
         {json(1), json({{1, 0, 0}}), json({{0, 0, 0, 1}}), json({{1, 0, "0", 1}}),
          json({{1, 0, 0, 1e300}}), json(std::vector<json>(7, {1, 0, 0, 0}))}) {
        j["clip_planes"] = bad;
        expect_rejected(j, "clip_planes: expected");
    }
    j["clip_planes"] = {{1, 0, 0, 0}};
    j["renderer"] = "slice";
    j["accel"] = "kdtree";
    expect_rejected(j, "the slice renderer has no shading or clipping");
}

TEST(Protocol, EveryPresetRoundTripsThroughARequest) {
    for (const std::string& name : preset_names()) {
        json j = good_request();
        j["tf"] = json::parse(to_json(preset(name)));
        EXPECT_EQ(parse_request(j.dump()).tf, preset(name)) << name;
    }
}

TEST(Protocol, RejectsTextThatIsNotAJsonObject) {
    EXPECT_NE(rejection("").find("not valid JSON"), std::string::npos);
    EXPECT_NE(rejection("{\"type\":").find("not valid JSON"), std::string::npos);
    EXPECT_NE(rejection("\xff\xfe garbage").find("not valid JSON"), std::string::npos);
    EXPECT_NE(rejection("[1,2,3]").find("expected an object"), std::string::npos);
    EXPECT_NE(rejection("42").find("expected an object"), std::string::npos);
}

TEST(Protocol, RejectsOversizedAndDeeplyNestedMessages) {
    json j = good_request();
    j["tf"]["name"] = std::string(70 * 1024, 'x');
    expect_rejected(j, "size");
    Limits small;
    small.max_message_bytes = 100;
    EXPECT_THROW(parse_request(good_request().dump(), small), Error);
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    EXPECT_NE(rejection(deep).find("size"), std::string::npos);
    const std::string nested =
        "{\"type\":\"render\",\"x\":" + std::string(40, '[') + std::string(40, ']') + "}";
    EXPECT_NE(rejection(nested).find("nesting"), std::string::npos);
    // Brackets inside strings are not nesting.
    json named = good_request();
    named["tf"]["name"] = std::string(100, '[');
    EXPECT_EQ(rejection(named.dump()), "");
}

TEST(Protocol, RejectsUnknownTypesAndKeys) {
    json j = good_request();
    j["type"] = "delete-everything";
    expect_rejected(j, "unknown message type");
    j = good_request();
    j.erase("type");
    expect_rejected(j, "type: missing");
    j = good_request();
    j["path"] = "/etc/passwd";
    expect_rejected(j, "path: unknown key");
    j = good_request();
    j["camera"]["roll"] = 3;
    expect_rejected(j, "camera.roll: unknown key");
}

TEST(Protocol, RejectsMissingFieldsAndWrongTypes) {
    for (const char* key :
         {"id", "width", "height", "preview", "camera", "renderer", "accel", "ert", "step", "tf"}) {
        json j = good_request();
        j.erase(key);
        expect_rejected(j, std::string(key) + ": missing");
    }
    json j = good_request();
    j["width"] = "320";
    expect_rejected(j, "width");
    j = good_request();
    j["width"] = 320.5;
    expect_rejected(j, "width");
    j = good_request();
    j["preview"] = 1;
    expect_rejected(j, "preview");
    j = good_request();
    j["camera"] = "front";
    expect_rejected(j, "camera");
    j = good_request();
    j["camera"]["pan"] = json::array({1});
    expect_rejected(j, "camera.pan");
    j = good_request();
    j["tf"] = "mr-brain";
    expect_rejected(j, "tf");
    j = good_request();
    j["id"] = -1;
    expect_rejected(j, "id");
}

TEST(Protocol, RejectsOutOfRangeValues) {
    const std::pair<const char*, json> cases[] = {
        {"width", 0}, {"width", 4097}, {"height", -5}, {"step", 0.0}, {"step", 100}};
    for (const auto& [key, value] : cases) {
        json j = good_request();
        j[key] = value;
        expect_rejected(j, key);
    }
    json j = good_request();
    j["camera"]["zoom"] = 0;
    expect_rejected(j, "camera.zoom");
    j = good_request();
    j["camera"]["elevation"] = 90;
    expect_rejected(j, "camera.elevation");
    j = good_request();
    j["camera"]["pan"] = json::array({1e9, 0});
    expect_rejected(j, "camera.pan");
    j = good_request();
    j["accel"] = "octree9";
    expect_rejected(j, "accel");
    j = good_request();
    j["renderer"] = "slicer9";
    expect_rejected(j, "renderer");
}

TEST(Protocol, RejectsInvalidTransferFunctions) {
    json j = good_request();
    j["tf"]["opacity"][1][1] = 1.5;  // opacity outside [0,1]
    expect_rejected(j, "tf");
    j = good_request();
    j["tf"]["opacity"] = json::array({json::array({0.8, 0}), json::array({0.2, 1})});  // unsorted
    expect_rejected(j, "tf");
    j = good_request();
    j["tf"]["opacity"] = json::array();
    for (int i = 0; i < 600; ++i) j["tf"]["opacity"].push_back(json::array({i / 600.0, 0.5}));
    expect_rejected(j, "points");
}

TEST(Protocol, RequestIdIsRecoveredForErrorsWhenPresent) {
    json j = good_request();
    j["width"] = 0;
    EXPECT_EQ(request_id(j.dump()), std::optional<uint64_t>(7));
    EXPECT_EQ(request_id("{"), std::nullopt);
    EXPECT_EQ(request_id("{\"id\":\"x\"}"), std::nullopt);
}

// The hello's capabilities are what parse_request accepts: for every renderer (and the segments
// toggle) and every accel, a request is accepted exactly when the table lists the accel, and the
// shading and clip toggles exactly when it lists the feature.
TEST(Protocol, HelloCapabilitiesAreWhatRequestsMayCombine) {
    SyntheticOptions so;
    so.dims = {9, 8, 7};
    Volume v = generate(SyntheticKind::Sphere, so);
    HelloInfo h;
    h.volume = &v;
    h.initial_tf = preset("mr-brain");
    h.accels = accel_names();
    h.renderers = renderer_names();
    const json caps = json::parse(hello_message(h))["capabilities"];
    EXPECT_EQ(caps["slice"]["accels"], json::array({"none", "kdtree"}));
    EXPECT_EQ(caps["march"]["accels"].size(), accel_names().size());
    EXPECT_EQ(caps["segments"]["renderer"], "march");
    auto has = [](const json& list, const std::string& x) {
        return std::find(list.begin(), list.end(), json(x)) != list.end();
    };
    EXPECT_TRUE(has(caps["march"]["features"], "shading"));
    EXPECT_FALSE(has(caps["slice"]["features"], "clip_planes"));
    EXPECT_FALSE(has(caps["segments"]["features"], "shading"));
    auto accepted = [](const json& j) {
        try {
            parse_request(j.dump());
            return true;
        } catch (const lacuna::Error&) {
            return false;
        }
    };
    for (const char* row : {"march", "slice", "segments"}) {
        const json& c = caps[row];
        json base = good_request();
        base["renderer"] = std::string(row) == "segments" ? c["renderer"] : json(row);
        if (std::string(row) == "segments") base["segments"] = true;
        for (const std::string& accel : accel_names()) {
            json j = base;
            j["accel"] = accel;
            EXPECT_EQ(accepted(j), has(c["accels"], accel)) << row << " " << accel;
        }
        base["accel"] = c["accels"][0];
        ASSERT_TRUE(accepted(base)) << row;
        json j = base;
        j["shading"] = true;
        EXPECT_EQ(accepted(j), has(c["features"], "shading")) << row;
        for (const char* key : {"clip", "clip_planes"}) {
            j = base;
            j[key] =
                std::string(key) == "clip" ? json(true) : json::array({json::array({1, 0, 0, 0})});
            EXPECT_EQ(accepted(j), has(c["features"], "clip_planes")) << row << " " << key;
        }
    }
    // Segments are never drawn by the slicer.
    json j = good_request();
    j["renderer"] = "slice";
    j["accel"] = "none";
    j["segments"] = true;
    expect_rejected(j, "segments");
}

TEST(Protocol, ServerMessagesAreWellFormed) {
    SyntheticOptions so;
    so.dims = {9, 8, 7};
    Volume v = generate(SyntheticKind::Sphere, so);
    HelloInfo h;
    h.volume_name = "sphere.nrrd";
    h.volume = &v;
    h.histogram = {1, 2, 3};
    h.initial_tf = preset("mr-brain");
    h.accels = accel_names();
    h.renderers = renderer_names();
    const json hello = json::parse(hello_message(h));
    EXPECT_EQ(hello["type"], "hello");
    EXPECT_EQ(hello["volume"]["dims"], json::array({9, 8, 7}));
    EXPECT_EQ(hello["accels"].size(), accel_names().size());
    EXPECT_EQ(hello["renderers"], json::array({"march", "slice"}));
    EXPECT_EQ(hello["presets"].size(), preset_names().size());
    EXPECT_EQ(parse_transfer_function(hello["tf"].dump(), "hello"), preset("mr-brain"));

    const json err = json::parse(error_message("message: width: bad\n\"quoted\"", 12));
    EXPECT_EQ(err["type"], "error");
    EXPECT_EQ(err["id"], 12);
    EXPECT_TRUE(json::parse(error_message("x", std::nullopt))["id"].is_null());

    FrameInfo f;
    f.id = 5;
    f.width = 3;
    f.tf_changed = true;
    f.tf_update_ms = 1.25;
    const std::string msg = frame_message(f, std::string("\xff\xd8jpeg", 6));
    const uint32_t n = uint32_t(uint8_t(msg[0])) | uint32_t(uint8_t(msg[1])) << 8 |
                       uint32_t(uint8_t(msg[2])) << 16 | uint32_t(uint8_t(msg[3])) << 24;
    ASSERT_EQ(msg.size(), 4 + n + 6);
    const json header = json::parse(msg.substr(4, n));
    EXPECT_EQ(header["type"], "frame");
    EXPECT_EQ(header["id"], 5);
    EXPECT_EQ(header["tf_update_ms"], 1.25);
    EXPECT_EQ(msg.substr(4 + n), std::string("\xff\xd8jpeg", 6));
}
