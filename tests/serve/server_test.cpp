// The server on an ephemeral port, driven by real Beast clients: the page and nothing else over
// HTTP, hello / render / error over the WebSocket, several tabs at once, clean stop.
#include "serve/server.h"

#include <gtest/gtest.h>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "lacuna/error.h"
#include "lacuna/synthetic.h"
#include "serve/server_test_util.h"

using namespace lacuna::serve::test;

TEST(Server, HelloRenderAndErrorOverAWebSocket) {
    Running server;
    Client c(server.port);
    const json hello = c.read_text();
    ASSERT_EQ(hello["type"], "hello");
    EXPECT_EQ(hello["volume"]["dims"], json::array({20, 18, 16}));
    EXPECT_EQ(hello["accels"].size(), accel_names().size());
    EXPECT_EQ(hello["renderers"], json::array({"march", "slice"}));
    EXPECT_EQ(hello["histogram"].size(), size_t(FrameRenderer::kHistogramBins));

    // Malformed: answered with an error, the connection stays usable.
    c.send("{\"type\": \"render\", \"id\": 3, ");
    json err = c.read_text();
    EXPECT_EQ(err["type"], "error");
    EXPECT_NE(err["message"].get<std::string>().find("JSON"), std::string::npos);
    json bad = render_request(4, hello["tf"]);
    bad["width"] = 100000;
    c.send(bad.dump());
    err = c.read_text();
    EXPECT_EQ(err["type"], "error");
    EXPECT_EQ(err["id"], 4);
    EXPECT_NE(err["message"].get<std::string>().find("width"), std::string::npos);
    c.send(std::string(200 * 1024, ' '));  // over the protocol's limit, under the socket's
    err = c.read_text();
    EXPECT_NE(err["message"].get<std::string>().find("size"), std::string::npos);

    c.send(render_request(5, hello["tf"]).dump());
    bool binary = false;
    const WireFrame f = split_frame(c.read(binary));
    EXPECT_TRUE(binary);
    EXPECT_EQ(f.header["type"], "frame");
    EXPECT_EQ(f.header["id"], 5);
    EXPECT_EQ(f.header["width"], 64);
    EXPECT_EQ(f.header["height"], 48);
    EXPECT_EQ(f.header["accel"], "bitfield");
    EXPECT_TRUE(f.header["tf_changed"].get<bool>());
    EXPECT_GT(f.header["samples_per_ray"].get<double>(), 0.0);
    ASSERT_GT(f.jpeg.size(), 2u);
    EXPECT_EQ(uint8_t(f.jpeg[0]), 0xFF);
    EXPECT_EQ(uint8_t(f.jpeg[1]), 0xD8);

    // A preview is rendered at reduced resolution.
    json preview = render_request(6, hello["tf"]);
    preview["preview"] = true;
    c.send(preview.dump());
    const WireFrame p = split_frame(c.read(binary));
    EXPECT_EQ(p.header["id"], 6);
    EXPECT_TRUE(p.header["preview"].get<bool>());
    EXPECT_LT(p.header["width"].get<int>(), 64);
    EXPECT_FALSE(p.header["tf_changed"].get<bool>());
}

TEST(Server, LatestRequestWinsAndSeveralTabsAreServed) {
    Running server;
    Client a(server.port), b(server.port);
    const json tf = a.read_text()["tf"];
    b.read_text();
    // A burst: the server may drop any but the last, and must answer the last.
    for (uint64_t id = 1; id <= 20; ++id) a.send(render_request(id, tf).dump());
    b.send(render_request(100, tf).dump());
    bool binary = false;
    uint64_t last = 0;
    int frames = 0;
    while (last != 20) {
        const WireFrame f = split_frame(a.read(binary));
        ASSERT_TRUE(binary);
        EXPECT_GT(f.header["id"].get<uint64_t>(), last);  // in order, never an older one
        last = f.header["id"].get<uint64_t>();
        ++frames;
    }
    EXPECT_LE(frames, 20);
    EXPECT_EQ(split_frame(b.read(binary)).header["id"], 100);
}

TEST(Server, ServesOnlyTheEmbeddedPage) {
    Running server;
    auto res = http_get(server.port, "/");
    EXPECT_EQ(res.result(), http::status::ok);
    EXPECT_NE(res.body().find("<html"), std::string::npos);
    EXPECT_EQ(res[http::field::content_type], "text/html; charset=utf-8");
    EXPECT_EQ(http_get(server.port, "/viewer.js").result(), http::status::ok);
    EXPECT_EQ(http_get(server.port, "/viewer.css").result(), http::status::ok);
    for (const char* t : {"/../../etc/passwd", "/etc/passwd", "/web/index.html", "//index.html",
                          "/%2e%2e/etc/passwd", "/CMakeLists.txt"})
        EXPECT_EQ(http_get(server.port, t).result(), http::status::not_found) << t;
    // DNS rebinding: a loopback server answers only loopback host names.
    EXPECT_EQ(http_get(server.port, "/", "evil.example:80").result(), http::status::forbidden);
    EXPECT_EQ(http_get(server.port, "/", "localhost:1234").result(), http::status::ok);
}

TEST(Server, RefusesWebSocketsFromOtherOrigins) {
    Running server;
    EXPECT_THROW(Client(server.port, "http://evil.example"), beast::system_error);
    Client ok(server.port, "http://127.0.0.1:" + std::to_string(server.port));
    EXPECT_EQ(ok.read_text()["type"], "hello");
}

TEST(Server, RefusesTabsBeyondTheLimitAndStopsCleanly) {
    Running server(2);
    Client a(server.port), b(server.port);
    a.read_text();
    b.read_text();
    EXPECT_THROW(Client(server.port), beast::system_error);
    server.stop();
    // Both open connections are closed by the stop.
    bool binary;
    EXPECT_THROW(a.read(binary), beast::system_error);
    EXPECT_THROW(b.read(binary), beast::system_error);
}

TEST(Server, ReportsAnAddressInUse) {
    Running first;
    SyntheticOptions so;
    so.dims = {4, 4, 4};
    FrameRenderer r(generate(SyntheticKind::Sphere, so));
    ServerOptions o;
    o.port = first.port;
    Server second(r, o);
    EXPECT_THROW(second.start(), lacuna::Error);
    o.host = "not-an-address";
    Server third(r, o);
    EXPECT_THROW(third.start(), lacuna::Error);
}
