// `lacuna serve`: an HTTP + WebSocket server (Boost.Beast) for the browser viewer
// (docs/viewer.md).
//
// Threads: one network thread runs every socket (Beast's asynchronous operations on one
// io_context, so sessions need no locks of their own), and one render thread owns the
// FrameRenderer (which renders with all cores through core/parallel.h). They meet in a
// "latest wins" slot per browser tab: a new request overwrites the tab's unrendered one, so
// stale requests are dropped instead of queued, and a finished frame that has not started
// going out is replaced by a newer one.
//
// Robustness (issue 15; every limit below is a ServerOptions field):
//   - accept errors (out of file descriptors: the connection stays in the backlog, so accepting
//     again at once fails again) back off, doubling from 10 ms to 1 s, instead of spinning;
//   - a WebSocket that sends nothing for idle_timeout is closed, and a full server (max_sessions
//     open) makes room for a new tab by closing the one idle longest, if it has been idle for
//     evict_idle_after: idle sockets cannot lock tabs out;
//   - render budget: a request whose estimated time (the last frame of the same renderer,
//     structure and features, per pixel and per sample step) exceeds render_budget_ms is rendered
//     at 1/2 .. 1/8 of its size per side (the frame header says "reduced"), so one 4096² request
//     holds the render thread for about the budget, not 24 s, while other tabs wait. A closed
//     tab's queued request is dropped and a newer request replaces a queued one (latest wins);
//     a newer request of the tab, or its closing, also cancels its frame in progress between
//     two tiles (core/cancel.h; a structure's first build runs to its end);
//   - a malformed or unrenderable message is answered with an "error" message naming the field;
//     the connection and the server stay up;
//   - a frame switch (volume_frame) reads the new volume on the network thread (other tabs wait
//     for that read), cancels the frame in progress and swaps the renderer's volume while the
//     render thread is locked out (renderer_mutex), so slices and frames never see half a switch;
//   - a screenshot is rendered at its full size (no preview, no budget: the user asked for it),
//     one per tab at a time, before the tab's pending render; a newer render does not cancel it,
//     closing the tab does.
//
// Security: binds 127.0.0.1 unless told otherwise; serves only the page embedded in the binary
// (no path from the browser is ever opened); on a loopback address it accepts only Host
// headers naming loopback (DNS rebinding); the WebSocket upgrade is refused when the browser's
// Origin is not the page's own; message size, image size and TF size are bounded.
#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "serve/frame_renderer.h"
#include "serve/protocol.h"
#include "session/session_file.h"

namespace lacuna::serve {

struct ServerOptions {
    std::string host = "127.0.0.1";
    uint16_t port = 8080;  // 0: an ephemeral port (tests)
    Limits limits;
    size_t max_frame_bytes = 1 << 20;  // WebSocket messages above this close the connection
    int max_sessions = 32;             // open WebSockets; more are refused (but see eviction)
    // A WebSocket with no message from the page for this long is closed (0: never).
    std::chrono::milliseconds idle_timeout = std::chrono::minutes(30);
    // When max_sessions are open, a new tab closes the longest-idle one if it has been idle at
    // least this long (else the new tab is refused with 503).
    std::chrono::milliseconds evict_idle_after = std::chrono::seconds(30);
    // Estimated render time above which a frame is rendered reduced (0: no budget).
    double render_budget_ms = 2000;
    std::string volume_name;  // shown by the page
    // The volume's file and read options, for the page's "session" messages (the session file
    // `lacuna render --session` reads); nullopt (a volume made in memory): they are refused.
    std::optional<SessionVolume> session_volume;
    // The label volume's file (`lacuna serve --labels`), named by session files of the segments
    // toggle; nullopt with a label volume: such sessions are refused.
    std::optional<std::string> labels_path;
    // A 4D file's volumes (the page's frame selector, "volume_frame" messages): how many, the one
    // the renderer starts with, and how to read volume K (called on the network thread; its
    // lacuna::Error is the page's error message). frames 1 or no load_frame: no selector.
    int64_t frames = 1, frame = 0;
    std::function<Volume(int64_t)> load_frame;
    TransferFunction initial_tf = preset("mr-default");
    int jpeg_quality = 88;
    int preview_quality = 75;
    bool handle_signals = false;  // SIGINT/SIGTERM stop the server (the CLI; not tests)
    bool log = false;             // one line per connection on stdout
};

class Server {
  public:
    // The renderer must outlive the server.
    Server(FrameRenderer& renderer, ServerOptions options);
    ~Server();  // stops and joins the render thread; run() must have returned
    Server(const Server&) = delete;
    Server& operator=(const Server&) = delete;

    // Binds and listens. Throws lacuna::Error("serve", "host"/"port", ...) if that fails.
    // Returns the port (the chosen one when options.port is 0).
    uint16_t start();
    // Serves until stop() (or a signal with handle_signals). Call after start().
    void run();
    // Thread-safe, idempotent: closes the listener and every connection; run() returns.
    void stop();
    std::string url() const;

    // Counters since start (thread-safe): what the robustness limits did.
    struct Stats {
        uint64_t accept_errors = 0;   // failed accepts (each followed by a back-off)
        uint64_t idle_closed = 0;     // WebSockets closed by idle_timeout
        uint64_t evicted = 0;         // idle WebSockets closed to admit a new tab
        uint64_t budget_reduced = 0;  // frames rendered reduced by the render budget
        uint64_t dropped = 0;         // queued requests of closed tabs, not rendered
        uint64_t started = 0;         // frames the render thread began
        uint64_t cancelled = 0;  // frames cancelled while rendering (newer request, closed tab)
    };
    Stats stats() const;

    struct Impl;  // opaque: Beast stays out of this header

  private:
    std::unique_ptr<Impl> m;  // owned alone: see server.cpp
};

}  // namespace lacuna::serve
