// `lacuna serve VOLUME`: the browser viewer (docs/viewer.md). Loads the volume, prints the URL,
// serves until Ctrl-C.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "cli_common.h"
#include "lacuna/error.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume_frames.h"
#include "serve/frame_renderer.h"
#include "serve/server.h"
#include "serve_mpi.h"

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
    MpiCliArgs mpi;      // under mpirun
};

// The volume the viewer starts with: a 4D file's first volume unless --frame (every rank alike).
VolumeArgs first_volume(const VolumeArgs& v, int64_t& frames) {
    VolumeArgs first = v;
    frames = count_volume_frames(v.path);
    if (frames > 1 && !first.frame) first.frame = 0;
    return first;
}

// Ranks 1 .. N-1 of `mpirun -np N lacuna serve`: their bricks of every frame rank 0 asks for.
void follow(const ServeArgs& a) {
    dist::Comm& comm = dist::Comm::world();
    const std::optional<TransferFunction> tf = dist::await_start(comm);
    if (!tf) return;  // rank 0 could not start; it says why
    int64_t frames = 1;
    dist::VolumeSource source;
    try {
        source = volume_source(first_volume(a.volume, frames));
    } catch (const std::exception& e) {
        // This rank alone (rank 0 read the file): rank 0 waits in the session's first message.
        std::fprintf(stderr, "lacuna: rank %d: %s\n", comm.rank(), e.what());
        comm.abort(2);
    }
    dist::DistributedSession session(comm, source, *tf, dist_options(a.mpi), a.threads);
    dist::follow_rank0(session);
}

void run(const ServeArgs& a) {
    if (a.port < 0 || a.port > 65535) throw Error("--port", "port", "expected 0..65535");
    check_mpi_options(a.mpi);
    // Under mpirun every rank renders its brick of each frame; rank 0 also serves the page
    // (docs/distributed.md, "The viewer").
    const bool mpi = mpi_render_active();
    if (mpi) {
        if (!a.labels.empty())
            throw Error("mpirun", "--labels",
                        "the segments toggle is not distributed yet (serve it without mpirun)");
        if (!dist::Comm::world().serialized_threads())
            throw Error("mpirun", "threads",
                        "expected an MPI library with MPI_THREAD_SERIALIZED (rank 0 renders on the "
                        "server's render thread)");
        if (dist::Comm::world().rank() != 0) return follow(a);
    }
    serve::ServerOptions so;
    so.host = a.host;
    so.port = uint16_t(a.port);
    so.handle_signals = true;
    so.log = true;
    // A 4D file: the page's frame selector picks among its volumes (volume 0 unless --frame);
    // under mpirun the bricks are of one volume, so there is no selector.
    int64_t frames = 1;
    const VolumeArgs first = first_volume(a.volume, frames);
    if (frames > 1 && !mpi) {
        so.frames = frames;
        so.frame = *first.frame;
        so.load_frame = [args = a.volume](int64_t k) {
            VolumeArgs b = args;
            b.frame = k;
            return load_volume(b);
        };
    }
    // Rank 0 reads the whole volume for the slice panes, the probe and the histogram, then tells
    // the other ranks to read their bricks (or that it failed, so they end instead of waiting).
    Volume vol;
    try {
        vol = load_volume(first);
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
    } catch (...) {
        if (mpi) dist::announce_failure(dist::Comm::world());
        throw;
    }
    std::unique_ptr<dist::DistributedSession> bricks;
    std::unique_ptr<dist::RankDriver> driver;  // releases the other ranks when it goes
    if (mpi) {
        dist::Comm& comm = dist::Comm::world();
        dist::announce_start(comm, so.initial_tf);
        bricks = std::make_unique<dist::DistributedSession>(
            comm, volume_source(first), so.initial_tf, dist_options(a.mpi), a.threads);
        driver = std::make_unique<dist::RankDriver>(*bricks);
    }
    AccelOptions ao;
    ao.leaf_cells = a.leaf;
    ao.bitfield_bits = a.bits;
    serve::FrameRenderer renderer(std::move(vol), ao, a.threads);
    if (driver) renderer.set_frame_source(std::make_unique<DistributedFrames>(*driver));
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
    if (mpi)
        std::printf("rendering with %d ranks (%s balance, %s compositing): bricks %s\n",
                    bricks->comm().size(), a.mpi.balance.c_str(), a.mpi.composite.c_str(),
                    dist::to_string(bricks->decomposition()).c_str());
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
    add_mpi_options(*cmd, a->mpi, /*rank_times=*/false);
    cmd->callback([a] { run(*a); });
}

}  // namespace lacuna::cli
