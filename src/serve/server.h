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
// Security: binds 127.0.0.1 unless told otherwise; serves only the page embedded in the binary
// (no path from the browser is ever opened); on a loopback address it accepts only Host
// headers naming loopback (DNS rebinding); the WebSocket upgrade is refused when the browser's
// Origin is not the page's own; message size, image size and TF size are bounded.
#pragma once
#include <cstdint>
#include <memory>
#include <string>

#include "serve/frame_renderer.h"
#include "serve/protocol.h"

namespace lacuna::serve {

struct ServerOptions {
    std::string host = "127.0.0.1";
    uint16_t port = 8080;  // 0: an ephemeral port (tests)
    Limits limits;
    size_t max_frame_bytes = 1 << 20;  // WebSocket messages above this close the connection
    int max_sessions = 32;             // open WebSockets; more are refused
    std::string volume_name;           // shown by the page
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
    ~Server();  // stops and joins
    Server(const Server&) = delete;
    Server& operator=(const Server&) = delete;

    // Binds and listens. Throws lacuna::Error("--host"/"--port", ...) if that fails.
    // Returns the port (the chosen one when options.port is 0).
    uint16_t start();
    // Serves until stop() (or a signal with handle_signals). Call after start().
    void run();
    // Thread-safe, idempotent: closes the listener and every connection; run() returns.
    void stop();
    std::string url() const;

    struct Impl;  // opaque: Beast stays out of this header

private:
    std::shared_ptr<Impl> m;
};

}  // namespace lacuna::serve
