// The server's threads and protocol plumbing (see server.h). The network side follows Beast's
// "advanced server" example shape: an HTTP session per connection that either answers from the
// embedded asset table or upgrades to a WebSocket session.
//
// This file is glue, not an algorithm: it owns the two threads the server needs (network and
// render) directly; the rendering itself is parallelised only through core/parallel.h.
#include "serve/server.h"

#include <algorithm>
#include <atomic>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "core/cancel.h"
#include "lacuna/error.h"
#include "lacuna/image.h"
#include "serve/assets.h"
#include "serve/jpeg.h"
#include "serve/tf_files.h"

namespace lacuna::serve {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

namespace {

double ms_between(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

// "host:port" -> "host" ("[::1]:80" -> "::1").
std::string host_name(std::string_view host_header) {
    std::string h(host_header);
    if (!h.empty() && h.front() == '[') {
        const size_t close = h.find(']');
        return close == std::string::npos ? h : h.substr(1, close - 1);
    }
    const size_t colon = h.find(':');
    return colon == std::string::npos ? h : h.substr(0, colon);
}

// What the time per pixel of a frame depends on most (the render budget's estimate is kept
// per key).
std::string cost_key(const ViewRequest& r) {
    return to_string(r.renderer) + "/" + to_string(r.accel) + (r.shading ? "/shading" : "") +
           (r.clip ? "/clip" : "") + (r.segments ? "/segments" : "");
}

// The first field where two session documents differ ("frame.camera.fov_y_deg"), "" if none.
std::string first_difference(const nlohmann::json& a, const nlohmann::json& b,
                             const std::string& path) {
    if (a.is_object() && b.is_object()) {
        for (const auto* side : {&a, &b})
            for (auto it = side->begin(); it != side->end(); ++it) {
                const std::string child = path.empty() ? it.key() : path + "." + it.key();
                if (!a.contains(it.key()) || !b.contains(it.key())) return child;
                const std::string d = first_difference(a.at(it.key()), b.at(it.key()), child);
                if (!d.empty()) return d;
            }
        return "";
    }
    return a == b ? "" : path;
}

// A session's volume path names the server's file: the same path, or (relative: the page does not
// know the session file's folder) the server's path ends with it, component by component.
bool same_volume_path(const std::string& session_path, const std::string& server_path) {
    namespace fs = std::filesystem;
    const fs::path a = fs::path(session_path).lexically_normal(),
                   b = fs::path(server_path).lexically_normal();
    if (a.is_absolute()) return a == b;
    std::vector<fs::path> ca(a.begin(), a.end()), cb(b.begin(), b.end());
    if (ca.empty() || ca.size() > cb.size()) return false;
    return std::equal(ca.rbegin(), ca.rend(), cb.rbegin());
}

bool is_loopback_name(const std::string& h) {
    if (h == "localhost") return true;
    boost::system::error_code ec;
    const auto a = net::ip::make_address(h, ec);
    return !ec && a.is_loopback();
}

}  // namespace

class WsSession;

// Lifetime: the Server owns the Impl alone. Sessions and handlers point to it without owning
// it (a handler that owned it would be stored in the io_context the Impl owns: a cycle that
// kept every server, its sessions and their buffers alive forever). ~Server joins both threads,
// then ~Impl destroys the io_context last, which destroys the handlers still queued and with
// them the sessions they hold (Asio's documented shutdown order).
struct Server::Impl {
    Impl(FrameRenderer& r, ServerOptions o) : renderer(r), options(std::move(o)) {}

    FrameRenderer& renderer;
    ServerOptions options;
    net::io_context ioc{1};
    tcp::acceptor acceptor{ioc};
    std::optional<net::signal_set> signals;
    std::string hello;
    bool loopback = true;
    uint16_t port = 0;

    // Network thread only.
    std::set<std::shared_ptr<WsSession>> sessions;
    bool stopping = false;
    net::steady_timer accept_timer{ioc};
    std::chrono::milliseconds accept_backoff{0};

    std::atomic<uint64_t> accept_errors{0}, idle_closed{0}, evicted{0}, budget_reduced{0},
        dropped{0}, started{0}, cancelled{0};

    // The render thread and its latest-wins slots (guarded by slot_mutex).
    std::mutex slot_mutex;
    std::condition_variable slot_cv;
    std::deque<std::weak_ptr<WsSession>> ready;  // sessions with a pending request, FIFO
    bool render_stop = false;
    std::thread render_thread;
    double last_full_ms = 0;  // render thread only: drives the preview's reduction
    // The frame in progress: whose it is (guarded by slot_mutex) and its cancellation flag,
    // which a newer request of that tab or the tab's closing sets (core/cancel.h: the renderers
    // stop between two tiles).
    const WsSession* rendering = nullptr;
    bool rendering_screenshot = false;  // a newer render of the tab does not cancel a screenshot
    std::atomic<bool> cancel_frame{false};
    // Render thread only: milliseconds per pixel-sample-step unit (w * h / step) of the last
    // frame of each cost_key, the render budget's estimate.
    std::map<std::string, double> ms_per_unit;

    std::once_flag stop_once;
    // Held by the render thread while it uses the renderer, and by the network thread while it
    // swaps the renderer's volume (switch_frame); slices read the renderer on the network thread,
    // the swap's own thread, so they need no lock.
    std::mutex renderer_mutex;

    HelloInfo hello_info() const;
    void switch_frame(const std::string& text);

    void accept();
    void on_accept(beast::error_code ec, tcp::socket socket);
    bool evict_idlest();
    void submit(const std::shared_ptr<WsSession>& s);
    void render_loop();
    std::string render_screenshot(const ViewRequest& req);
    void close_all();
};

// One browser tab's WebSocket. Every member except the slot is touched only on the network
// thread.
class WsSession : public std::enable_shared_from_this<WsSession> {
  public:
    WsSession(tcp::socket&& socket, Server::Impl* server)
        : m_ws(std::move(socket)), m_server(server) {}

    template <class Body, class Allocator>
    void run(http::request<Body, http::basic_fields<Allocator>> req) {
        // Beast closes the stream when nothing arrives for idle_timeout; no keep-alive pings, so
        // only the page's own messages count as activity.
        auto timeout = websocket::stream_base::timeout::suggested(beast::role_type::server);
        const auto idle = m_server->options.idle_timeout;
        timeout.idle_timeout =
            idle.count() > 0 ? Clock::duration(idle) : websocket::stream_base::none();
        timeout.keep_alive_pings = false;
        m_ws.set_option(timeout);
        m_ws.read_message_max(m_server->options.max_frame_bytes);
        m_ws.async_accept(req,
                          beast::bind_front_handler(&WsSession::on_accept, shared_from_this()));
    }

    // Queues a text message (hello, errors): these are never dropped.
    void send_text(std::string text) {
        m_texts.push_back(std::move(text));
        pump();
    }
    // Queues a frame, replacing one that has not started going out (it is stale).
    void send_frame(std::string frame) {
        m_frame = std::move(frame);
        pump();
    }
    void close() {
        beast::error_code ec;
        beast::get_lowest_layer(m_ws).socket().shutdown(tcp::socket::shutdown_both, ec);
        beast::get_lowest_layer(m_ws).socket().close(ec);
    }
    // Closed to make room for a new tab: leaves the session set now.
    void evict() {
        close();
        finish();
    }
    Clock::time_point last_active() const { return m_last_active; }

    // The latest-wins slot, shared with the render thread (Impl::slot_mutex).
    std::optional<ViewRequest> pending;
    // A screenshot waiting for the render thread (never dropped for a newer render; one a tab).
    std::optional<ViewRequest> screenshot;
    bool screenshot_busy = false;  // queued or rendering: a second one is refused
    Clock::time_point pending_received;
    bool in_ready = false;

  private:
    void on_accept(beast::error_code ec) {
        if (ec) return;
        if (m_server->stopping) return close();
        m_server->sessions.insert(shared_from_this());
        if (m_server->options.log)
            std::printf("viewer: tab connected (%zu open)\n", m_server->sessions.size());
        send_text(m_server->hello);
        read();
    }

    void read() {
        m_ws.async_read(m_buffer,
                        beast::bind_front_handler(&WsSession::on_read, shared_from_this()));
    }

    void on_read(beast::error_code ec, size_t) {
        if (ec == beast::error::timeout) ++m_server->idle_closed;
        if (ec) return finish();
        m_last_active = Clock::now();
        const std::string text = beast::buffers_to_string(m_buffer.data());
        m_buffer.consume(m_buffer.size());
        if (!m_ws.got_text()) {
            send_text(error_message("message: binary: expected a JSON text message", std::nullopt));
        } else {
            try {
                const MessageKind kind = message_kind(text, m_server->options.limits);
                if (kind == MessageKind::Slice || kind == MessageKind::Probe) {
                    answer_slice_or_probe(kind, text);
                } else if (kind == MessageKind::Screenshot) {
                    queue_screenshot(text);
                } else if (kind == MessageKind::VolumeFrame) {
                    m_server->switch_frame(text);
                } else if (kind != MessageKind::Render) {
                    answer_file_message(kind, text);
                } else {
                    ViewRequest req = parse_request(text, m_server->options.limits);
                    {
                        std::lock_guard<std::mutex> lock(m_server->slot_mutex);
                        pending = std::move(req);  // latest wins: an unrendered request is dropped
                        pending_received = Clock::now();
                        // ... and so is the frame of this tab being rendered (not a screenshot).
                        if (m_server->rendering == this && !m_server->rendering_screenshot)
                            m_server->cancel_frame = true;
                    }
                    m_server->submit(shared_from_this());
                }
            } catch (const Error& e) {
                send_text(error_message(e.what(), request_id(text, m_server->options.limits)));
            }
        }
        read();
    }

    // Slices and probes are answered here, on the network thread, in order: a slice takes
    // milliseconds (lacuna/mpr.h) and reads only what the render thread never changes
    // (FrameRenderer::slice). A failure is an error message naming the field; the socket stays.
    void answer_slice_or_probe(MessageKind kind, const std::string& text) {
        const Limits& limits = m_server->options.limits;
        if (kind == MessageKind::Probe) {
            const ProbeRequest req = parse_probe_request(text, limits);
            send_text(probe_message(req.id, m_server->renderer.probe(req)));
            return;
        }
        const SliceRequest req = parse_slice_request(text, limits);
        try {
            const FrameRenderer::SliceImage s = m_server->renderer.slice(req, limits.max_side);
            SliceInfo info;
            info.id = req.id;
            info.geometry = s.geometry;
            info.interpolation = req.interpolation;
            info.overlay = s.overlay;
            info.slice_ms = s.seconds * 1e3;
            const Clock::time_point e0 = Clock::now();
            const std::string jpeg = encode_jpeg(s.image, m_server->options.jpeg_quality);
            info.encode_ms = std::chrono::duration<double, std::milli>(Clock::now() - e0).count();
            m_binaries.push_back(slice_message(info, jpeg));
            pump();
        } catch (const Error& e) {
            send_text(error_message(e.what(), req.id));
        } catch (const std::exception& e) {  // out of memory: report, keep serving
            send_text(error_message(std::string("slice: ") + e.what(), req.id));
        }
    }

    // A screenshot goes to the render thread (it owns the renderer); one per tab at a time.
    void queue_screenshot(const std::string& text) {
        ViewRequest req =
            parse_view_request(text, MessageKind::Screenshot, m_server->options.limits);
        {
            std::lock_guard<std::mutex> lock(m_server->slot_mutex);
            if (screenshot_busy)
                throw Error(
                    "screenshot", "id",
                    "this tab's previous screenshot is still rendering; ask for one at a time");
            screenshot_busy = true;
            screenshot = std::move(req);
        }
        m_server->submit(shared_from_this());
    }

  public:
    // The render thread's screenshot went out (or failed): the tab may ask for the next one.
    void screenshot_done(std::string message, bool binary) {
        {
            std::lock_guard<std::mutex> lock(m_server->slot_mutex);
            screenshot_busy = false;
        }
        if (binary) {
            m_binaries.push_back(std::move(message));
            pump();
        } else {
            send_text(std::move(message));
        }
    }

  private:
    // Session files and TF files, on the network thread: they read only what never changes once
    // the server runs (the volume's geometry and ranges, the options), no rendering.
    void answer_file_message(MessageKind kind, const std::string& text) {
        const Limits& limits = m_server->options.limits;
        const FrameRenderer& renderer = m_server->renderer;
        if (kind == MessageKind::Session) {
            const ViewRequest req = parse_view_request(text, MessageKind::Session, limits);
            const auto& volume = m_server->options.session_volume;
            if (!volume)
                throw Error("session", "volume",
                            "this server's volume has no file to name (it was made in memory)");
            SessionFile f;
            f.volume = *volume;
            f.tf = req.tf;
            f.frame = renderer.frame_spec(req, req.width, req.height);
            if (f.frame.renderer == Renderer::Segments) {
                if (!m_server->options.labels_path)
                    throw Error("session", "segments",
                                "the server's label volume has no file to name (it was made in "
                                "memory); switch segments off to save the session");
                f.labels = m_server->options.labels_path;
            }
            send_text(session_message(req.id, to_json(f, "session")));
            return;
        }
        if (kind == MessageKind::TfExport) {
            const TfExportRequest req = parse_tf_export_request(text, limits);
            const Volume& v = renderer.volume();
            const double smallest = std::min({v.spacing.x, v.spacing.y, v.spacing.z});
            send_text(tf_export_message(req.id, req.format,
                                        req.format == TfFileFormat::Slicer
                                            ? to_slicer_vp_json(req.tf, v.vis_range(), smallest)
                                            : to_json(req.tf)));
            return;
        }
        if (kind == MessageKind::SessionImport) return open_session(text);
        const TfImportRequest req = parse_tf_import_request(text, limits);
        const TransferFunction tf = read_tf_file(req.name, req.text);
        const size_t points =
            tf.color.size() + tf.opacity.size() + tf.rendering.gradient_opacity.size();
        if (points > size_t(limits.max_tf_points))
            throw Error(req.name, "points",
                        std::to_string(points) + "; the viewer takes at most " +
                            std::to_string(limits.max_tf_points));
        send_text(tf_import_message(req.id, tf));
    }

    // A session file opened in the page: the view state whose frame is the session's exactly, or
    // an error naming the first field the page cannot reproduce.
    void open_session(const std::string& text) {
        using nlohmann::json;
        const Limits& limits = m_server->options.limits;
        const FrameRenderer& renderer = m_server->renderer;
        const TfImportRequest req = parse_session_import_request(text, limits);
        const std::string where = req.name.empty() ? "session" : req.name;
        const SessionFile f = parse_session_file(req.text, where);
        const auto& volume = m_server->options.session_volume;
        if (!volume || !same_volume_path(f.volume.path, volume->path))
            throw Error(where, "volume.path",
                        "'" + f.volume.path + "' is not this server's volume" +
                            (volume ? " (" + volume->path + ")" : ""));
        json mine = json::parse(
            to_json(SessionFile{*volume, f.tf, std::nullopt, f.frame, f.labels}, where));
        json theirs = json::parse(to_json(f, where));
        mine["volume"].erase("path");
        theirs["volume"].erase("path");
        if (const std::string d = first_difference(theirs["volume"], mine["volume"], "volume");
            !d.empty())
            throw Error(where, d,
                        "differs from the server's volume (lacuna serve's --frame, --range, "
                        "--dims/--type)");
        if (f.tf_back) throw Error(where, "tf_back", "the viewer has no back TF (--tf-back)");
        const ViewRequest view = renderer.view_request(f.frame, f.tf);
        // Exact: the view's frame is the session's, field by field.
        const json want = theirs["frame"];
        const json got = json::parse(
            to_json(SessionFile{*volume, f.tf, std::nullopt,
                                renderer.frame_spec(view, view.width, view.height), f.labels},
                    where))["frame"];
        if (const std::string d = first_difference(want, got, "frame"); !d.empty())
            throw Error(where, d,
                        "the viewer has no control for this value (its frame would differ)");
        // And the page may send it: the answer's view parses as a render message.
        const std::string answer = session_import_message(req.id, view);
        json as_render = json::parse(answer)["view"];
        as_render["type"] = "render";
        as_render["id"] = req.id;
        as_render["preview"] = false;
        try {
            (void)parse_request(as_render.dump(), limits);
        } catch (const Error& e) {
            throw Error(where, "frame", std::string("the viewer cannot send it: ") + e.what());
        }
        send_text(answer);
    }

    void finish() {
        {
            // A closed tab's queued request is not rendered.
            std::lock_guard<std::mutex> lock(m_server->slot_mutex);
            if (pending) ++m_server->dropped;
            if (screenshot) ++m_server->dropped;
            pending.reset();
            screenshot.reset();
            if (m_server->rendering == this) m_server->cancel_frame = true;
        }
        if (m_server->sessions.erase(shared_from_this()) && m_server->options.log)
            std::printf("viewer: tab closed (%zu open)\n", m_server->sessions.size());
    }

    void pump() {
        if (m_writing) return;
        if (!m_texts.empty()) {
            m_out = std::move(m_texts.front());
            m_texts.pop_front();
            m_ws.text(true);
        } else if (!m_binaries.empty()) {
            m_out = std::move(m_binaries.front());
            m_binaries.pop_front();
            m_ws.binary(true);
        } else if (m_frame) {
            m_out = std::move(*m_frame);
            m_frame.reset();
            m_ws.binary(true);
        } else {
            return;
        }
        m_writing = true;
        m_ws.async_write(net::buffer(m_out),
                         beast::bind_front_handler(&WsSession::on_write, shared_from_this()));
    }

    void on_write(beast::error_code ec, size_t) {
        m_writing = false;
        if (ec) return finish();
        pump();
    }

    websocket::stream<beast::tcp_stream> m_ws;
    Server::Impl* m_server;  // outlives the session (see Server::Impl)
    beast::flat_buffer m_buffer;
    std::deque<std::string> m_texts;
    std::optional<std::string> m_frame;
    std::deque<std::string> m_binaries;  // slices: answered in order, never dropped
    std::string m_out;                   // the message being written (alive until on_write)
    bool m_writing = false;
    Clock::time_point m_last_active = Clock::now();  // connect, then the last message read
};

// A full server admits a new tab by closing the one idle longest, if it has been idle for
// evict_idle_after. True if a slot was freed.
bool Server::Impl::evict_idlest() {
    if (sessions.empty()) return false;
    const auto idlest = std::min_element(
        sessions.begin(), sessions.end(),
        [](const auto& a, const auto& b) { return a->last_active() < b->last_active(); });
    if (Clock::now() - (*idlest)->last_active() < options.evict_idle_after) return false;
    const std::shared_ptr<WsSession> s = *idlest;
    s->evict();
    ++evicted;
    if (options.log) std::printf("viewer: closed the longest-idle tab for a new one\n");
    return true;
}

// One HTTP connection: GET/HEAD of an embedded asset, or the upgrade to /ws.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
  public:
    HttpSession(tcp::socket&& socket, Server::Impl* server)
        : m_stream(std::move(socket)), m_server(server) {}

    void run() { read(); }

  private:
    void read() {
        m_parser.emplace();
        m_parser->header_limit(8 * 1024);
        m_parser->body_limit(4 * 1024);  // the page never sends a body
        m_stream.expires_after(std::chrono::seconds(30));
        http::async_read(m_stream, m_buffer, *m_parser,
                         beast::bind_front_handler(&HttpSession::on_read, shared_from_this()));
    }

    void on_read(beast::error_code ec, size_t) {
        if (ec == http::error::end_of_stream) return shut();
        if (ec) {
            // Oversized or malformed requests get one plain answer, then the connection closes.
            if (ec == http::error::header_limit || ec == http::error::body_limit ||
                ec.category() == make_error_code(http::error::bad_target).category())
                return respond(plain(http::status::bad_request, "bad request\n", 11, false));
            return shut();
        }
        auto req = m_parser->release();
        const std::string host(req[http::field::host]);
        if (m_server->loopback && !is_loopback_name(host_name(host)))
            return respond(
                plain(http::status::forbidden, "forbidden host\n", req.version(), false));
        if (websocket::is_upgrade(req)) {
            if (req.target() != "/ws")
                return respond(plain(http::status::not_found, "not found\n", req.version(), false));
            // A page from another site must not drive this server (cross-site WebSocket
            // hijacking): a browser always sends Origin; it must be this server's own.
            const auto origin = req[http::field::origin];
            if (!origin.empty() && origin != "http://" + host)
                return respond(
                    plain(http::status::forbidden, "forbidden origin\n", req.version(), false));
            if (int(m_server->sessions.size()) >= m_server->options.max_sessions &&
                !m_server->evict_idlest())
                return respond(plain(http::status::service_unavailable, "too many tabs\n",
                                     req.version(), false));
            beast::get_lowest_layer(m_stream).expires_never();
            std::make_shared<WsSession>(m_stream.release_socket(), m_server)->run(std::move(req));
            return;
        }
        if (req.method() != http::verb::get && req.method() != http::verb::head)
            return respond(plain(http::status::method_not_allowed, "method not allowed\n",
                                 req.version(), req.keep_alive()));
        std::string_view target(req.target().data(), req.target().size());
        target = target.substr(0, target.find('?'));
        if (target == "/") target = "/index.html";
        for (const Asset& a : assets()) {
            if (a.path != target) continue;
            http::response<http::string_body> res{http::status::ok, req.version()};
            res.set(http::field::content_type, std::string(a.content_type));
            secure_headers(res);
            res.keep_alive(req.keep_alive());
            if (req.method() == http::verb::get) res.body() = std::string(a.body);
            res.content_length(a.body.size());
            return respond(std::move(res));
        }
        return respond(
            plain(http::status::not_found, "not found\n", req.version(), req.keep_alive()));
    }

    template <class Res>
    static void secure_headers(Res& res) {
        res.set(http::field::server, "lacuna");
        res.set(http::field::cache_control, "no-store");
        res.set("X-Content-Type-Options", "nosniff");
        res.set("X-Frame-Options", "DENY");
        res.set("Content-Security-Policy",
                "default-src 'self'; img-src 'self' blob: data:; connect-src 'self'; "
                "frame-ancestors 'none'");
    }

    static http::response<http::string_body> plain(http::status s, const char* body,
                                                   unsigned version, bool keep_alive) {
        http::response<http::string_body> res{s, version};
        res.set(http::field::content_type, "text/plain; charset=utf-8");
        secure_headers(res);
        res.keep_alive(keep_alive);
        res.body() = body;
        res.prepare_payload();
        return res;
    }

    void respond(http::response<http::string_body>&& res) {
        auto sp = std::make_shared<http::response<http::string_body>>(std::move(res));
        m_res = sp;
        http::async_write(m_stream, *sp,
                          [self = shared_from_this(), sp](beast::error_code ec, size_t) {
                              if (ec || sp->need_eof()) return self->shut();
                              self->read();
                          });
    }

    void shut() {
        beast::error_code ec;
        m_stream.socket().shutdown(tcp::socket::shutdown_send, ec);
    }

    beast::tcp_stream m_stream;
    Server::Impl* m_server;  // outlives the session (see Server::Impl)
    beast::flat_buffer m_buffer;
    std::optional<http::request_parser<http::string_body>> m_parser;
    std::shared_ptr<void> m_res;
};

void Server::Impl::accept() {
    acceptor.async_accept(net::make_strand(ioc), beast::bind_front_handler(&Impl::on_accept, this));
}

void Server::Impl::on_accept(beast::error_code ec, tcp::socket socket) {
    if (stopping || !acceptor.is_open()) return;
    if (ec && ec != net::error::connection_aborted) {
        // Out of file descriptors (EMFILE, ENFILE), buffers or memory: the connection waits in
        // the backlog, so accepting again at once fails again, a busy loop that starves every
        // open socket. Back off, doubling from 10 ms to 1 s, until an accept succeeds.
        ++accept_errors;
        accept_backoff = std::clamp(accept_backoff * 2, std::chrono::milliseconds(10),
                                    std::chrono::milliseconds(1000));
        accept_timer.expires_after(accept_backoff);
        accept_timer.async_wait([this](beast::error_code e) {
            if (!e && !stopping) accept();
        });
        return;
    }
    accept_backoff = 0ms;
    if (!ec) std::make_shared<HttpSession>(std::move(socket), this)->run();
    accept();
}

void Server::Impl::submit(const std::shared_ptr<WsSession>& s) {
    {
        std::lock_guard<std::mutex> lock(slot_mutex);
        if (s->in_ready) return;  // already waiting: its slot now holds the newer request
        s->in_ready = true;
        ready.push_back(s);
    }
    slot_cv.notify_one();
}

// The render thread: takes the tabs with a pending request in turn (round robin, so one busy
// tab cannot starve another), renders each one's latest request, hands the JPEG to the network
// thread.
void Server::Impl::render_loop() {
    for (;;) {
        std::shared_ptr<WsSession> s;
        ViewRequest req;
        std::optional<ViewRequest> shot;
        Clock::time_point received;
        {
            std::unique_lock<std::mutex> lock(slot_mutex);
            slot_cv.wait(lock, [&] { return render_stop || !ready.empty(); });
            if (render_stop) return;
            s = ready.front().lock();
            ready.pop_front();
            if (!s) continue;
            s->in_ready = false;
            if (s->screenshot) {
                // The screenshot first; the tab's pending render (if any) waits its next turn.
                shot = std::move(*s->screenshot);
                s->screenshot.reset();
                if (s->pending) {
                    s->in_ready = true;
                    ready.push_back(s);
                }
            } else {
                if (!s->pending) continue;
                req = std::move(*s->pending);
                s->pending.reset();
                received = s->pending_received;
            }
            rendering = s.get();
            rendering_screenshot = shot.has_value();
            cancel_frame = false;
            ++started;
        }
        if (shot) {
            // Full size, never reduced; cancelled only by the tab's closing. A failure is one
            // error reply; the server goes on.
            std::string reply;
            bool binary = false;
            try {
                const CancelScope cancellable(cancel_frame);
                const std::lock_guard<std::mutex> use(renderer_mutex);
                reply = render_screenshot(*shot);
                binary = true;
            } catch (const Cancelled&) {
                ++cancelled;
            } catch (const std::exception& e) {
                reply = error_message(std::string("screenshot: ") + e.what(), shot->id);
            }
            if (!reply.empty())
                net::post(ioc, [s, m = std::move(reply), binary]() mutable {
                    s->screenshot_done(std::move(m), binary);
                });
            std::lock_guard<std::mutex> lock(slot_mutex);
            rendering = nullptr;
            rendering_screenshot = false;
            continue;
        }
        std::string message;
        try {
            // Previews (the page is dragging) are reduced so they take about a frame at 30 Hz,
            // judged by the last full-resolution frame: 1/2, 1/3 or 1/4 per side.
            int div = 1;
            if (req.preview) div = std::clamp(int(std::ceil(std::sqrt(last_full_ms / 33.0))), 2, 4);
            int w = std::max(1, req.width / div), h = std::max(1, req.height / div);
            // The render budget: the estimate is the last frame of the same key per unit (its
            // own, else the slowest known: a first frame of a new structure is not cheaper), and
            // an estimate over budget divides each side by up to 8.
            const std::string key = cost_key(req);
            int reduced = 1;
            if (options.render_budget_ms > 0 && !ms_per_unit.empty()) {
                double rate = 0;
                if (auto it = ms_per_unit.find(key); it != ms_per_unit.end())
                    rate = it->second;
                else
                    for (const auto& [k, r] : ms_per_unit) rate = std::max(rate, r);
                const double estimate = rate * double(w) * double(h) / double(req.step);
                if (estimate > options.render_budget_ms) {
                    reduced = std::clamp(
                        int(std::ceil(std::sqrt(estimate / options.render_budget_ms))), 2, 8);
                    w = std::max(1, w / reduced);
                    h = std::max(1, h / reduced);
                    ++budget_reduced;
                }
            }
            const Clock::time_point start = Clock::now();
            std::unique_lock<std::mutex> use(renderer_mutex);
            Frame f = [&] {
                const CancelScope cancellable(cancel_frame);  // the frame only, not refine()
                return renderer.render(req, w, h);
            }();
            use.unlock();
            ms_per_unit[key] = f.stats.seconds * 1e3 * double(req.step) / (double(w) * double(h));
            if (!req.preview) last_full_ms = f.stats.seconds * 1e3;
            FrameInfo info;
            info.id = req.id;
            info.width = w;
            info.height = h;
            info.preview = req.preview;
            info.reduced = reduced;
            info.renderer = to_string(req.renderer);
            info.accel = to_string(req.accel);
            info.frame_ms = f.stats.seconds * 1e3;
            info.samples_per_ray = f.stats.samples_per_ray();
            info.skipped = f.skipped;
            info.tf_changed = f.tf_changed;
            info.tf_update_ms = f.tf_update_seconds * 1e3;
            // Received -> ready to render: the wait for the frame in progress, the (possible)
            // structure build and the TF update.
            info.tf_latency_ms = f.tf_changed
                                     ? ms_between(received, start) + f.accel_build_seconds * 1e3 +
                                           f.tf_update_seconds * 1e3
                                     : 0;
            info.accel_build_ms = f.accel_build_seconds * 1e3;
            info.accel_tf_update_ms = f.accel_tf_update_seconds * 1e3;
            const Clock::time_point e0 = Clock::now();
            const std::string jpeg =
                encode_jpeg(f.image, req.preview ? options.preview_quality : options.jpeg_quality);
            info.encode_ms = ms_between(e0, Clock::now());
            message = frame_message(info, jpeg);
            net::post(ioc, [s, m = std::move(message)]() mutable { s->send_frame(std::move(m)); });
            // Idle after a full frame: the structure's finer per-TF level, for the next frames.
            bool idle;
            {
                std::lock_guard<std::mutex> lock(slot_mutex);
                idle = ready.empty();
            }
            if (idle && !req.preview) {
                const std::lock_guard<std::mutex> refining(renderer_mutex);
                renderer.refine();
            }
        } catch (const Cancelled&) {
            // A newer request of this tab (it is queued again and rendered next) or its closing:
            // the frame is not sent.
            ++cancelled;
        } catch (const std::exception& e) {
            // lacuna::Error (e.g. a structure's options) or out of memory: report, keep serving.
            net::post(ioc,
                      [s, m = error_message(std::string("render: ") + e.what(), req.id)]() mutable {
                          s->send_text(std::move(m));
                      });
        }
        std::lock_guard<std::mutex> lock(slot_mutex);
        rendering = nullptr;
    }
}

// A screenshot: the request's frame at its own size, as `lacuna render` writes it (the session's
// frame through the CLI's PNG encoder).
std::string Server::Impl::render_screenshot(const ViewRequest& req) {
    Frame f = renderer.render(req, req.width, req.height);
    ScreenshotInfo info;
    info.id = req.id;
    info.width = req.width;
    info.height = req.height;
    info.frame_ms = f.stats.seconds * 1e3;
    const Clock::time_point e0 = Clock::now();
    const std::string png = png_bytes(f.image);
    info.encode_ms = ms_between(e0, Clock::now());
    return screenshot_message(info, png);
}

void Server::Impl::close_all() {
    stopping = true;
    beast::error_code ec;
    acceptor.close(ec);
    accept_timer.cancel();
    if (signals) signals->cancel(ec);
    for (const auto& s : sessions) s->close();
    sessions.clear();
    ioc.stop();
}

HelloInfo Server::Impl::hello_info() const {
    HelloInfo h;
    h.volume_name = options.volume_name;
    h.volume = &renderer.volume();
    h.histogram = renderer.histogram();
    h.initial_tf = options.initial_tf;
    h.accels = accel_names();
    h.renderers = renderer_names();
    h.labels = renderer.label_count();
    h.session = options.session_volume.has_value();
    h.frames = options.load_frame ? options.frames : 1;
    h.frame = options.frame;
    h.limits = options.limits;
    return h;
}

// Network thread. The new volume is read first (a failure leaves everything as it was), then
// the render thread is locked out for the swap; the frame it was rendering is cancelled so the
// lock comes quickly (a structure's first build still runs to its end).
void Server::Impl::switch_frame(const std::string& text) {
    const VolumeFrameRequest req = parse_volume_frame_request(text, options.limits);
    if (!options.load_frame || options.frames < 2)
        throw Error("volume_frame", "frame", "the server's volume has one frame (not a 4D file)");
    if (req.frame >= options.frames)
        throw Error("volume_frame", "frame",
                    "expected 0.." + std::to_string(options.frames - 1) + ", got " +
                        std::to_string(req.frame));
    if (req.frame != options.frame) {
        Volume v = options.load_frame(req.frame);
        cancel_frame = true;
        {
            const std::lock_guard<std::mutex> swap(renderer_mutex);
            renderer.set_volume(std::move(v));
        }
        options.frame = req.frame;
        if (options.session_volume) options.session_volume->frame = req.frame;
        hello = hello_message(hello_info());  // what tabs that connect later are told
    }
    const std::string answer = volume_frame_message(req.id, hello_info());
    for (const auto& s : sessions) s->send_text(answer);
}

Server::Server(FrameRenderer& renderer, ServerOptions options)
    : m(std::make_unique<Impl>(renderer, std::move(options))) {
    m->hello = hello_message(m->hello_info());
}

Server::~Server() {
    stop();
    if (m->render_thread.joinable()) {
        {
            std::lock_guard<std::mutex> lock(m->slot_mutex);
            m->render_stop = true;
        }
        m->slot_cv.notify_all();
        m->render_thread.join();
    }
}

uint16_t Server::start() {
    boost::system::error_code ec;
    const auto address = net::ip::make_address(m->options.host, ec);
    if (ec) throw Error("serve", "host", "expected an IP address, got '" + m->options.host + "'");
    m->loopback = address.is_loopback();
    const tcp::endpoint ep{address, m->options.port};
    const std::string where = m->options.host + ":" + std::to_string(m->options.port);
    m->acceptor.open(ep.protocol(), ec);
    if (!ec) m->acceptor.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) m->acceptor.bind(ep, ec);
    if (!ec) m->acceptor.listen(net::socket_base::max_listen_connections, ec);
    if (ec) throw Error("serve", "port", where + ": cannot listen: " + ec.message());
    m->port = m->acceptor.local_endpoint().port();
    m->accept();
    if (m->options.handle_signals) {
        m->signals.emplace(m->ioc, SIGINT, SIGTERM);
        m->signals->async_wait([impl = m.get()](const boost::system::error_code& e, int) {
            if (!e) impl->close_all();
        });
    }
    m->render_thread = std::thread([impl = m.get()] { impl->render_loop(); });
    return m->port;
}

void Server::run() {
    m->ioc.run();
    {
        std::lock_guard<std::mutex> lock(m->slot_mutex);
        m->render_stop = true;
    }
    m->slot_cv.notify_all();
    if (m->render_thread.joinable()) m->render_thread.join();
}

void Server::stop() {
    net::post(m->ioc, [impl = m.get()] { impl->close_all(); });
}

Server::Stats Server::stats() const {
    Stats s;
    s.accept_errors = m->accept_errors;
    s.idle_closed = m->idle_closed;
    s.evicted = m->evicted;
    s.budget_reduced = m->budget_reduced;
    s.dropped = m->dropped;
    s.started = m->started;
    s.cancelled = m->cancelled;
    return s;
}

std::string Server::url() const {
    const bool v6 = m->options.host.find(':') != std::string::npos;
    return "http://" + (v6 ? "[" + m->options.host + "]" : m->options.host) + ":" +
           std::to_string(m->port) + "/";
}

}  // namespace lacuna::serve
