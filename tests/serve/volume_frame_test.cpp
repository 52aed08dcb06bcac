// The viewer's frame selector (volume_frame, docs/viewer.md): the server swaps in volume K of a
// 4D file, answers every tab with its info, renders every later request from it, names it in the
// session files it writes; switching back gives the first frame's bytes again; out-of-range and
// single-volume servers answer one error naming the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "serve/server_test_util.h"
#include "session/session_file.h"

namespace lacuna::serve::test {
namespace {

// Volume k of a pretend 4D file: 0 is the test server's sphere (server_test_util.h), the others
// blobs of another seed per volume (same grid).
Volume series_volume(int64_t k) {
    SyntheticOptions so;
    so.dims = {20, 18, 16};
    if (k == 0) return generate(SyntheticKind::Sphere, so);
    so.seed = uint32_t(3 + 5 * k);
    return generate(SyntheticKind::NoiseBlobs, so);
}

void as_series(ServerOptions& o) {
    o.frames = 3;
    o.frame = 0;
    o.load_frame = series_volume;
    SessionVolume sv;
    sv.path = "/data/series.nii.gz";
    sv.frame = 0;
    o.session_volume = sv;
}

json frame_request(uint64_t id, int64_t k) {
    return json{{"type", "volume_frame"}, {"id", id}, {"frame", k}};
}

std::string frame_jpeg(Client& c, uint64_t id) {
    c.send(render_request(id, json::parse(to_json(preset("mr-default")))).dump());
    bool binary = false;
    const WireFrame f = split_frame(c.read(binary));
    EXPECT_TRUE(binary);
    EXPECT_EQ(f.header["id"], id);
    return f.jpeg;
}

TEST(VolumeFrameProtocol, ParsesTheFrameAndNamesBadFields) {
    EXPECT_EQ(message_kind(frame_request(1, 2).dump()), MessageKind::VolumeFrame);
    const VolumeFrameRequest r = parse_volume_frame_request(frame_request(7, 2).dump());
    EXPECT_EQ(r.id, 7u);
    EXPECT_EQ(r.frame, 2);
    for (const json& bad : {json{{"type", "volume_frame"}, {"id", 1}, {"frame", -1}},
                            json{{"type", "volume_frame"}, {"id", 1}, {"frame", "2"}},
                            json{{"type", "volume_frame"}, {"id", 1}},
                            json{{"type", "volume_frame"}, {"id", 1}, {"frame", 1}, {"x", 0}}}) {
        try {
            (void)parse_volume_frame_request(bad.dump());
            ADD_FAILURE() << bad.dump();
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_TRUE(m.find("frame") != std::string::npos || m.find("x") != std::string::npos)
                << m;
        }
    }
}

TEST(VolumeFrameServer, SwitchingFramesRendersTheChosenVolumeAndTellsEveryTab) {
    Running server(32, as_series);
    Client a(server.port), b(server.port);
    const json hello = a.read_text();
    (void)b.read_text();
    EXPECT_EQ(hello["frames"], 3);
    EXPECT_EQ(hello["frame"], 0);
    const auto& names = hello["messages"];
    EXPECT_NE(std::find(names.begin(), names.end(), "volume_frame"), names.end());
    const std::string first = frame_jpeg(a, 1);

    a.send(frame_request(2, 2).dump());
    for (Client* c : {&a, &b}) {  // every tab shows the server's one volume
        const json m = c->read_text();
        ASSERT_EQ(m["type"], "volume_frame") << m.dump();
        EXPECT_EQ(m["id"], 2);
        EXPECT_EQ(m["frame"], 2);
        EXPECT_EQ(m["frames"], 3);
        EXPECT_EQ(m["histogram"].size(), size_t(FrameRenderer::kHistogramBins));
        const Volume v = series_volume(2);
        EXPECT_EQ(m["volume"]["data_range"][1].get<double>(), double(v.data_range().max));
    }
    const std::string second = frame_jpeg(a, 3);
    EXPECT_NE(second, first);
    // The session file names the frame; a tab connecting now is told frame 2.
    json session = render_request(4, json::parse(to_json(preset("mr-default"))));
    session["type"] = "session";
    session.erase("preview");
    a.send(session.dump());
    const json s = a.read_text();
    ASSERT_EQ(s["type"], "session") << s.dump();
    EXPECT_EQ(parse_session_file(s["text"].get<std::string>(), "s").volume.frame, 2);
    Client late(server.port);
    EXPECT_EQ(late.read_text()["frame"], 2);
    // Back to volume 0: the first frame's bytes again (the switch leaves nothing behind).
    a.send(frame_request(5, 0).dump());
    EXPECT_EQ(a.read_text()["frame"], 0);
    EXPECT_EQ(b.read_text()["frame"], 0);
    EXPECT_EQ(frame_jpeg(a, 6), first);
    // Out of range: one error naming the field and the range; the volume stays.
    a.send(frame_request(7, 3).dump());
    const json e = a.read_text();
    EXPECT_EQ(e["type"], "error");
    EXPECT_EQ(e["id"], 7);
    EXPECT_NE(e["message"].get<std::string>().find("volume_frame: frame: expected 0..2, got 3"),
              std::string::npos)
        << e.dump();
    EXPECT_EQ(frame_jpeg(a, 8), first);
}

TEST(VolumeFrameServer, AOneVolumeServerRefusesFrames) {
    Running server;
    Client c(server.port);
    EXPECT_EQ(c.read_text()["frames"], 1);
    c.send(frame_request(3, 1).dump());
    const json e = c.read_text();
    EXPECT_EQ(e["type"], "error");
    EXPECT_NE(e["message"].get<std::string>().find("one frame"), std::string::npos) << e.dump();
}

}  // namespace
}  // namespace lacuna::serve::test
