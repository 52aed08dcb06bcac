// `lacuna serve VOLUME`: the browser viewer (docs/viewer.md). Loads the volume, prints the URL,
// serves until Ctrl-C.
#include <cstdio>
#include <filesystem>

#include "cli_common.h"
#include "lacuna/error.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume_frames.h"
#include "serve/frame_renderer.h"
#include "serve/server.h"

namespace lacuna::cli {

namespace {

struct ServeArgs {
    VolumeArgs volume;
    std::string host = "127.0.0.1";
    int port = 8080;
    std::string tf;
    int threads = 0;
    int leaf = 8, bits = 64;
    std::string labels;  // label volume for the segments toggle
};

void run(const ServeArgs& a) {
    if (a.port < 0 || a.port > 65535) throw Error("--port", "port", "expected 0..65535");
    serve::ServerOptions so;
    so.host = a.host;
    so.port = uint16_t(a.port);
    so.handle_signals = true;
    so.log = true;
    // A 4D file: the page's frame selector picks among its volumes (volume 0 unless --frame).
    VolumeArgs first = a.volume;
    if (const int64_t frames = count_volume_frames(a.volume.path); frames > 1) {
        if (!first.frame) first.frame = 0;
        so.frames = frames;
        so.frame = *first.frame;
        so.load_frame = [args = a.volume](int64_t k) {
            VolumeArgs b = args;
            b.frame = k;
            return load_volume(b);
        };
    }
    Volume vol = load_volume(first);
    // CT (int16, Hounsfield units) starts with bone, everything else with the MRI default.
    so.initial_tf = resolve_transfer_function(
        !a.tf.empty() ? a.tf : (vol.type() == VoxelType::Int16 ? "ct-bone" : "mr-default"));
    so.volume_name = std::filesystem::path(a.volume.path).filename().string();
    // What the page's session files name (read as `lacuna render --save-session` writes it).
    SessionVolume sv;
    sv.path = std::filesystem::absolute(a.volume.path).lexically_normal().string();
    sv.frame = first.frame;
    sv.raw = raw_spec_of(a.volume);
    if (!a.volume.range.empty()) sv.range = parse_range(a.volume.range);
    so.session_volume = sv;
    AccelOptions ao;
    ao.leaf_cells = a.leaf;
    ao.bitfield_bits = a.bits;
    serve::FrameRenderer renderer(std::move(vol), ao, a.threads);
    if (!a.labels.empty()) {
        VolumeArgs la;
        la.path = a.labels;
        renderer.set_labels(load_volume(la));
        so.labels_path = std::filesystem::absolute(a.labels).lexically_normal().string();
    }
    serve::Server server(renderer, so);
    server.start();
    if (a.host != "127.0.0.1" && a.host != "::1")
        std::printf(
            "warning: listening on %s: anyone who can reach this address can use the viewer\n",
            a.host.c_str());
    std::printf("lacuna viewer: %s (Ctrl-C stops)\n", server.url().c_str());
    std::fflush(stdout);
    server.run();
    std::printf("lacuna viewer: stopped\n");
}

}  // namespace

void register_serve(CLI::App& app) {
    auto a = std::make_shared<ServeArgs>();
    auto* cmd = app.add_subcommand("serve", "Interactive viewer in the browser (docs/viewer.md)");
    add_volume_args(*cmd, a->volume);
    cmd->add_option("--labels", a->labels,
                    "Label volume (same dims) for the page's segments toggle (docs/segments.md)");
    cmd->add_option(
           "--host", a->host,
           "Address to listen on (default loopback only; another address exposes the viewer)")
        ->capture_default_str();
    cmd->add_option("--port", a->port, "TCP port (0: any free port)")->capture_default_str();
    cmd->add_option("--tf", a->tf, "Initial transfer function: a preset name or a .json file");
    cmd->add_option("--threads", a->threads, "Render threads (0 = all)")->capture_default_str();
    cmd->add_option("--leaf", a->leaf, "Octree leaf edge in cells (2..64, power of two)")
        ->capture_default_str();
    cmd->add_option("--bits", a->bits, "Bitfield width (8, 16, 32, 64, 128)")
        ->capture_default_str();
    cmd->callback([a] { run(*a); });
}

}  // namespace lacuna::cli
