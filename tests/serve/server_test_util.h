// The server test harness shared by tests/serve/: a server on an ephemeral port on its own
// thread, a blocking Beast WebSocket client (a browser tab), HTTP GET, frame parsing.
#pragma once
#include <gtest/gtest.h>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "lacuna/synthetic.h"
#include "serve/server.h"

namespace lacuna::serve::test {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;
using namespace lacuna;
using namespace lacuna::serve;

// A server on 127.0.0.1:<ephemeral> serving a small sphere, run on its own thread.
class Running {
  public:
    explicit Running(int max_sessions = 32,
                     const std::function<void(ServerOptions&)>& configure = {}) {
        SyntheticOptions so;
        so.dims = {20, 18, 16};
        m_renderer = std::make_unique<FrameRenderer>(generate(SyntheticKind::Sphere, so));
        ServerOptions o;
        o.port = 0;
        o.volume_name = "sphere";
        o.max_sessions = max_sessions;
        if (configure) configure(o);
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
    Server::Stats stats() const { return m_server->stats(); }

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

inline json render_request(uint64_t id, const json& tf) {
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
inline WireFrame split_frame(const std::string& msg) {
    EXPECT_GE(msg.size(), 4u);
    const uint32_t n = uint32_t(uint8_t(msg[0])) | uint32_t(uint8_t(msg[1])) << 8 |
                       uint32_t(uint8_t(msg[2])) << 16 | uint32_t(uint8_t(msg[3])) << 24;
    return {json::parse(msg.substr(4, n)), msg.substr(4 + n)};
}

// One HTTP/1.1 request; returns the response.
inline http::response<http::string_body> http_get(uint16_t port, const std::string& target,
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

}  // namespace lacuna::serve::test
