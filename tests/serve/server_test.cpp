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

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;
using namespace lacuna;
using namespace lacuna::serve;

namespace {

// A server on 127.0.0.1:<ephemeral> serving a small sphere, run on its own thread.
class Running {
  public:
    explicit Running(int max_sessions = 32) {
        SyntheticOptions so;
        so.dims = {20, 18, 16};
        m_renderer = std::make_unique<FrameRenderer>(generate(SyntheticKind::Sphere, so));
        ServerOptions o;
        o.port = 0;
        o.volume_name = "sphere";
        o.max_sessions = max_sessions;
        m_server = std::make_unique<Server>(*m_renderer, o);
        port = m_server->start();
        m_thread = std::thread([this] { m_server->run(); });
    }
    ~Running() { stop(); }
    void stop() {
        if (!m_thread.joinable()) return;
        m_server->stop();
        m_thread.join();
    }
    uint16_t port = 0;

  private:
    std::unique_ptr<FrameRenderer> m_renderer;
    std::unique_ptr<Server> m_server;
    std::thread m_thread;
};

struct Client {
    net::io_context ioc;
    websocket::stream<tcp::socket> ws{ioc};
    explicit Client(uint16_t port, const std::string& origin = "") {
        tcp::resolver resolver(ioc);
        net::connect(ws.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
        const std::string host = "127.0.0.1:" + std::to_string(port);
        ws.set_option(websocket::stream_base::decorator([origin](websocket::request_type& req) {
            if (!origin.empty()) req.set(http::field::origin, origin);
        }));
        ws.handshake(host, "/ws");
    }
    // The next message: text as is, binary with binary = true.
    std::string read(bool& binary) {
        beast::flat_buffer b;
        ws.read(b);
        binary = ws.got_binary();
        return beast::buffers_to_string(b.data());
    }
    json read_text() {
        bool binary = true;
        const std::string s = read(binary);
        EXPECT_FALSE(binary);
        return json::parse(s);
    }
    void send(const std::string& s) {
        ws.text(true);
        ws.write(net::buffer(s));
    }
};

json render_request(uint64_t id, const json& tf) {
    return json{{"type", "render"},
                {"id", id},
                {"width", 64},
                {"height", 48},
                {"preview", false},
                {"camera", {{"azimuth", 30}, {"elevation", 10}, {"zoom", 1}, {"pan", {0, 0}}}},
                {"renderer", "march"},
                {"accel", "bitfield"},
                {"ert", true},
                {"step", 0.5},
                {"tf", tf}};
}

struct WireFrame {
    json header;
    std::string jpeg;
};
WireFrame split_frame(const std::string& msg) {
    EXPECT_GE(msg.size(), 4u);
    const uint32_t n = uint32_t(uint8_t(msg[0])) | uint32_t(uint8_t(msg[1])) << 8 |
                       uint32_t(uint8_t(msg[2])) << 16 | uint32_t(uint8_t(msg[3])) << 24;
    return {json::parse(msg.substr(4, n)), msg.substr(4 + n)};
}

// One HTTP/1.1 request; returns the response.
http::response<http::string_body> http_get(uint16_t port, const std::string& target,
                                           const std::string& host = "") {
    net::io_context ioc;
    tcp::socket s(ioc);
    tcp::resolver resolver(ioc);
    net::connect(s, resolver.resolve("127.0.0.1", std::to_string(port)));
    http::request<http::empty_body> req{http::verb::get, target, 11};
    req.set(http::field::host, host.empty() ? "127.0.0.1:" + std::to_string(port) : host);
    http::write(s, req);
    beast::flat_buffer b;
    http::response<http::string_body> res;
    http::read(s, b, res);
    return res;
}

}  // namespace

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
